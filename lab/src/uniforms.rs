//! Binding what a scene provides (the light rig's uniforms, `camera_pos`, a
//! scene file's values and images) to a program's uniforms by name AND type.
//!
//! A scene offers values under fixed names, but programs are free to use
//! those names for something else: `examples/textured_materials.mrsl`
//! declares `uniform float3 light_color`, while the rig's `light_color` is a
//! `float4[N]`. Binding by name alone used to write the rig's values into the
//! program's `float3` (resized to three zeros), so the light went black and
//! every mode matched the ambient-only reference exactly. The rule here:
//!
//! - name and type match: the value is set;
//! - the name is not declared: nothing happens (the rig provides more than
//!   most programs read);
//! - the name is declared with another type and the program gives it a
//!   default: the value is NOT set, and a [`Mismatch`] warning names both
//!   types, e.g. "light rig sets `light_color` as float4[32] but the program
//!   declares `uniform float3 light_color`; left at the program's default";
//! - the same, but the program's uniform has no default (textures and
//!   samplers never do): a typed error, [`UniformTypeError`], because the
//!   value would otherwise be missing.
//!
//! Never a silent zero.

use mrsl_abi::{Field, Layout, Scalar, ValueType};
use std::fmt;

/// What a scene offers under a uniform's name.
#[derive(Debug, Clone, PartialEq)]
pub enum Offered {
    /// A value of exactly this type.
    Value(ValueType),
    /// An array of `float4` of any length: the rig's light arrays hold this
    /// many lights, and a program's array takes as many as it has room for.
    Float4Array(usize),
    /// `n` numbers without a type of their own (a scene file's TOML value):
    /// matches any value type of `n` components.
    Numbers(usize),
    /// A texture (the rig's shadow map, a scene file's image).
    Texture,
}

impl Offered {
    /// A `float` (`Scalar(Float)`), `int`, `floatN`, ... value.
    pub fn scalar(s: Scalar) -> Offered {
        Offered::Value(ValueType::Scalar(s))
    }

    /// A `float3`.
    pub fn float3() -> Offered {
        Offered::Value(ValueType::Vector(Scalar::Float, 3))
    }

    /// Whether a uniform declared as `declared` takes this offer.
    pub fn matches(&self, declared: &Declared) -> bool {
        match (self, declared) {
            (Offered::Value(t), Declared::Value(f)) => *t == f.ty,
            (Offered::Float4Array(_), Declared::Value(f)) => {
                matches!(&f.ty, ValueType::Array(e, _) if **e == ValueType::Vector(Scalar::Float, 4))
            }
            (Offered::Numbers(n), Declared::Value(f)) => f.ty.components() as usize == *n,
            (Offered::Texture, Declared::Texture) => true,
            _ => false,
        }
    }
}

impl fmt::Display for Offered {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Offered::Value(t) => write!(f, "{t}"),
            Offered::Float4Array(n) => write!(f, "float4[{n}]"),
            Offered::Numbers(1) => write!(f, "1 number"),
            Offered::Numbers(n) => write!(f, "{n} numbers"),
            Offered::Texture => write!(f, "texture2d"),
        }
    }
}

/// How a program declares a name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Declared<'a> {
    /// A uniform value (`uniform float3 light_color = ...;`).
    Value(&'a Field),
    /// `uniform texture2d NAME;`
    Texture,
    /// `uniform sampler NAME;`
    Sampler,
}

impl Declared<'_> {
    /// The declaration's type as the program spells it.
    pub fn type_name(&self) -> String {
        match self {
            Declared::Value(f) => f.ty.to_string(),
            Declared::Texture => "texture2d".into(),
            Declared::Sampler => "sampler".into(),
        }
    }

    /// Whether the program gives it a value when the scene does not.
    pub fn has_default(&self) -> bool {
        matches!(self, Declared::Value(f) if f.default.is_some())
    }
}

/// How `layout`'s program declares `name`, if it does.
pub fn declared<'a>(layout: &'a Layout, name: &str) -> Option<Declared<'a>> {
    if let Some(f) = layout.uniforms.as_ref().and_then(|u| u.fields.iter().find(|f| f.name == name)) {
        return Some(Declared::Value(f));
    }
    if layout.textures.iter().any(|t| t.name == name) {
        return Some(Declared::Texture);
    }
    layout.samplers.iter().any(|s| s.name == name).then_some(Declared::Sampler)
}

/// A uniform the scene provides under the program's name for it, but with
/// another type.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// Who provides it: "light rig", "scene", "scene file hall.toml".
    pub source: String,
    pub name: String,
    pub offered: Offered,
    /// The program's type for it (`float3`, `texture2d`).
    pub declared: String,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} sets `{}` as {} but the program declares `uniform {} {}`; left at the program's default",
            self.source, self.name, self.offered, self.declared, self.name
        )
    }
}

/// A type mismatch on a uniform without a default: the program would run
/// with the value missing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{} sets `{}` as {} but the program declares `uniform {} {}`, which has no default: give it one, rename it, or provide a {}",
    .0.source, .0.name, .0.offered, .0.declared, .0.name, .0.declared
)]
pub struct UniformTypeError(pub Box<Mismatch>);

/// What to do with one offered uniform.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Name and type match: set it.
    Bind,
    /// The program does not declare the name.
    Absent,
    /// Declared with another type but with a default: leave it, warn.
    Skip(Mismatch),
}

/// Applies the rule of this module to one offer.
pub fn check(layout: &Layout, source: &str, name: &str, offered: &Offered) -> Result<Verdict, UniformTypeError> {
    let Some(declared) = declared(layout, name) else { return Ok(Verdict::Absent) };
    if offered.matches(&declared) {
        return Ok(Verdict::Bind);
    }
    let mismatch =
        Mismatch { source: source.into(), name: name.into(), offered: offered.clone(), declared: declared.type_name() };
    if declared.has_default() { Ok(Verdict::Skip(mismatch)) } else { Err(UniformTypeError(Box::new(mismatch))) }
}

/// What a scene did with a program's uniforms.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Applied {
    /// The names set (or, for textures, to be bound), in order.
    pub set: Vec<String>,
    /// Names declared with another type, left at the program's default.
    pub warnings: Vec<Mismatch>,
    /// Names a scene file sets that the program does not declare: a scene
    /// written for several programs sets more than each reads.
    pub ignored: Vec<Ignored>,
}

/// A uniform a scene file sets and the program does not declare.
#[derive(Debug, Clone, PartialEq)]
pub struct Ignored {
    /// Who sets it: "scene file hall.toml".
    pub source: String,
    pub name: String,
}

impl fmt::Display for Ignored {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} sets `{}`, which the program does not declare; ignored", self.source, self.name)
    }
}

impl Applied {
    /// [`check`]s one offer, records a mismatch, and says whether to set it
    /// (the caller sets it, then [`Applied::record`]s it).
    pub fn admit(
        &mut self,
        layout: &Layout,
        source: &str,
        name: &str,
        offered: &Offered,
    ) -> Result<bool, UniformTypeError> {
        match check(layout, source, name, offered)? {
            Verdict::Bind => Ok(true),
            Verdict::Absent => Ok(false),
            Verdict::Skip(mismatch) => {
                self.warnings.push(mismatch);
                Ok(false)
            }
        }
    }

    /// Notes that `name` was set.
    pub fn record(&mut self, name: &str) {
        self.set.push(name.into());
    }

    /// Appends what another source did.
    pub fn extend(&mut self, other: Applied) {
        self.set.extend(other.set);
        self.warnings.extend(other.warnings);
        self.ignored.extend(other.ignored);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout of a real program: these tests see what `mrslc` sees.
    fn layout(uniforms: &str) -> Layout {
        let source = format!(
            "in float2 uv;\n{uniforms}\nuniform texture2d albedo_map;\nuniform sampler linear;\n\
             fine out float4 color = sample(albedo_map, linear, uv);\n"
        );
        match mrsl::compile(&source, &mrsl::Options::for_modes(&[])) {
            Ok(program) => program.compiled.layout,
            Err(d) => panic!("{}", mrsl::render_all(&d, "test.mrsl", &source)),
        }
    }

    #[test]
    fn name_and_type_must_both_match() {
        let l = layout(
            "uniform float3 light_color = float3(1.0, 0.97, 0.92);\n\
             uniform float4 light_pos[8];\n\
             uniform int light_count = 0;",
        );
        // The textured_materials case: the rig's light_color is a float4 array.
        let v = check(&l, "light rig", "light_color", &Offered::Float4Array(32)).unwrap();
        let Verdict::Skip(m) = v else { panic!("{v:?}") };
        assert_eq!(
            m.to_string(),
            "light rig sets `light_color` as float4[32] but the program declares `uniform float3 light_color`; \
             left at the program's default"
        );
        // A float4 array of another length matches: the program takes what fits.
        assert_eq!(check(&l, "light rig", "light_pos", &Offered::Float4Array(32)), Ok(Verdict::Bind));
        assert_eq!(check(&l, "light rig", "light_color", &Offered::float3()), Ok(Verdict::Bind));
        // int is not uint, nor float.
        assert_eq!(check(&l, "light rig", "light_count", &Offered::scalar(Scalar::Int)), Ok(Verdict::Bind));
        assert!(matches!(check(&l, "rig", "light_count", &Offered::scalar(Scalar::Uint)), Ok(Verdict::Skip(_))));
        assert!(matches!(check(&l, "rig", "light_count", &Offered::scalar(Scalar::Float)), Ok(Verdict::Skip(_))));
        // A float4 is not a float3, and a float3 is not a float4 array.
        let float4 = Offered::Value(ValueType::Vector(Scalar::Float, 4));
        assert!(matches!(check(&l, "rig", "light_color", &float4), Ok(Verdict::Skip(_))));
        // light_pos has no default: a mismatch there is an error (below).
        assert!(check(&l, "rig", "light_pos", &Offered::float3()).is_err());
        // Undeclared names are no business of the program.
        assert_eq!(check(&l, "light rig", "sun_pos", &Offered::float3()), Ok(Verdict::Absent));
    }

    #[test]
    fn a_mismatch_without_a_default_is_an_error() {
        let l = layout("uniform float3 light_color;");
        let e = check(&l, "light rig", "light_color", &Offered::Float4Array(32)).unwrap_err();
        assert_eq!(e.0.declared, "float3");
        assert_eq!(e.0.offered, Offered::Float4Array(32));
        let text = e.to_string();
        assert!(text.contains("float4[32]") && text.contains("`uniform float3 light_color`"), "{text}");
        assert!(text.contains("no default"), "{text}");
        // Textures and samplers have no default: a value for them is an error.
        let e = check(&l, "scene file s.toml", "albedo_map", &Offered::Numbers(3)).unwrap_err();
        assert!(e.to_string().starts_with("scene file s.toml sets `albedo_map` as 3 numbers"), "{e}");
        assert!(e.to_string().contains("`uniform texture2d albedo_map`"), "{e}");
        let e = check(&l, "scene file s.toml", "linear", &Offered::Texture).unwrap_err();
        assert!(e.to_string().contains("`uniform sampler linear`"), "{e}");
    }

    #[test]
    fn scene_file_numbers_match_by_component_count() {
        let l = layout(
            "uniform float3 light_dir = float3(0.0, 1.0, 0.0);\n\
             uniform float4x4 view = float4x4(float4(1.0, 0.0, 0.0, 0.0), float4(0.0, 1.0, 0.0, 0.0), \
             float4(0.0, 0.0, 1.0, 0.0), float4(0.0, 0.0, 0.0, 1.0));\n\
             uniform bool show = false;",
        );
        assert_eq!(check(&l, "scene", "light_dir", &Offered::Numbers(3)), Ok(Verdict::Bind));
        assert_eq!(check(&l, "scene", "view", &Offered::Numbers(16)), Ok(Verdict::Bind));
        assert_eq!(check(&l, "scene", "show", &Offered::Numbers(1)), Ok(Verdict::Bind));
        let Ok(Verdict::Skip(m)) = check(&l, "scene", "light_dir", &Offered::Numbers(4)) else { panic!() };
        assert!(m.to_string().starts_with("scene sets `light_dir` as 4 numbers but"), "{m}");
        // An image for a value uniform, and an image for a texture.
        assert!(matches!(check(&l, "scene", "light_dir", &Offered::Texture), Ok(Verdict::Skip(_))));
        assert_eq!(check(&l, "scene", "albedo_map", &Offered::Texture), Ok(Verdict::Bind));
    }

    #[test]
    fn applied_collects_the_set_names_and_the_warnings() {
        let l = layout("uniform float3 light_color = float3(1.0);\nuniform float3 sun_size;");
        let mut applied = Applied::default();
        assert!(!applied.admit(&l, "light rig", "light_color", &Offered::Float4Array(4)).unwrap());
        assert!(!applied.admit(&l, "light rig", "sun_pos", &Offered::float3()).unwrap());
        assert!(applied.admit(&l, "light rig", "albedo_map", &Offered::Texture).unwrap());
        applied.record("albedo_map");
        assert!(applied.admit(&l, "light rig", "sun_size", &Offered::scalar(Scalar::Float)).is_err());
        assert_eq!(applied.set, ["albedo_map"]);
        assert_eq!(applied.warnings.len(), 1);
        assert_eq!(applied.warnings[0].name, "light_color");
    }
}
