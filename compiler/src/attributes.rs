//! The attributes a declaration may carry (`@key(0.4) in float3 normal;`):
//! one table of their names, where each may stand and what it says. The
//! checker takes from it the list an unknown attribute's error offers, and
//! the vocabulary (editors' highlighting and completion) lists it, so a new
//! attribute is added here once. docs/language.md, sections 3.1 and 3.5,
//! has the same in prose.

/// The declaration an attribute may stand on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `in`: a G-buffer channel.
    Input,
    /// `coarse effect`.
    CoarseEffect,
    /// `fine out`: an output.
    Output,
}

/// One attribute: its name (without the `@`), where it may stand, how it is
/// written, and what it means in a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AttributeSpec {
    pub name: &'static str,
    pub target: Target,
    pub syntax: &'static str,
    pub doc: &'static str,
}

const fn spec(name: &'static str, target: Target, syntax: &'static str, doc: &'static str) -> AttributeSpec {
    AttributeSpec { name, target, syntax, doc }
}

/// Every attribute of the language.
pub const ATTRIBUTES: [AttributeSpec; 9] = [
    spec(
        "key",
        Target::Input,
        "@key or @key(threshold)",
        "A discontinuity key: samples whose values differ (by more than the threshold) lie across an edge, where coarse effects that read the channel refine.",
    ),
    spec(
        "surface_key",
        Target::Input,
        "@surface_key(normal, threshold)",
        "A float3 position channel as a surface key: two samples are on different surfaces when the offset between them leaves either one's tangent plane by more than threshold of its length.",
    ),
    spec(
        "background",
        Target::Input,
        "@background(value)",
        "Pixels where this scalar channel equals value are background: coarse effects read zero there and are neither evaluated nor refined.",
    ),
    spec(
        "foreground",
        Target::Input,
        "@foreground(value)",
        "Pixels where this scalar channel does not equal value are background (the pass owns the others).",
    ),
    spec(
        "depth",
        Target::Input,
        "@depth(inverse_view_projection)",
        "The engine binds a depth texture; every kernel rebuilds this float3 channel as the world position through the given uniform float4x4.",
    ),
    spec(
        "encoded",
        Target::Input,
        "@encoded(unorm | octahedral | octahedral_unorm)",
        "The engine stores the channel packed; every kernel decodes it on reading.",
    ),
    spec(
        "packed",
        Target::Input,
        "@packed(bevy_deferred, field)",
        "The channel is a field of Bevy's deferred G-buffer, decoded as Bevy's deferred lighting decodes it.",
    ),
    spec(
        "nearest",
        Target::CoarseEffect,
        "@nearest",
        "Resample this coarse effect from the nearest corner sample instead of bilinearly.",
    ),
    spec("format", Target::Output, "@format(name)", "The storage format of the output texture, e.g. rgba8unorm."),
];

/// The names of the attributes allowed on `target`, as an unknown
/// attribute's error lists them.
pub fn names_on(target: Target) -> Vec<&'static str> {
    ATTRIBUTES.iter().filter(|a| a.target == target).map(|a| a.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checker knows every attribute of the table where the table puts
    /// it (its arguments may still be wrong: E0111, not E0110), and no other.
    #[test]
    fn the_checker_takes_each_attribute_where_the_table_puts_it() {
        let declarations = [
            (Target::Input, "in float3 x;"),
            (Target::CoarseEffect, "coarse effect float e = 1.0;"),
            (Target::Output, "fine out float4 o = float4(1.0);"),
        ];
        let unknown = |source: &str| {
            let program = crate::syntax::parse(source).expect("parses");
            crate::check::check(&program).1.iter().any(|d| d.code == "E0110")
        };
        for attribute in ATTRIBUTES {
            for (target, declaration) in declarations {
                // With an argument and without (`@nearest` takes none, and says so with E0110).
                let name = attribute.name;
                let refused =
                    unknown(&format!("@{name}(1.0) {declaration}")) && unknown(&format!("@{name} {declaration}"));
                assert_eq!(refused, target != attribute.target, "@{name} {declaration}");
            }
        }
        assert!(unknown("@keys in float3 x;"));
    }
}
