//! "Did you mean" suggestions for unknown names and types, and the uniforms
//! an unknown name may have been meant to declare.

pub(super) const TYPE_NAMES: &[&str] = &[
    "bool",
    "int",
    "uint",
    "float",
    "float2",
    "float3",
    "float4",
    "int2",
    "int3",
    "int4",
    "uint2",
    "uint3",
    "uint4",
    "bool2",
    "bool3",
    "bool4",
    "float2x2",
    "float3x3",
    "float4x4",
    "texture2d",
    "sampler",
];

/// Uniforms that the programs in `examples/` declare, each with the one type
/// they all give it, and that at least two of them declare: an unknown name
/// in this table gets the help "declare it: `uniform float3 light_dir;`".
/// A test checks the table against the examples.
const WELL_KNOWN_UNIFORMS: &[(&str, &str)] = &[
    ("albedo_map", "texture2d"),
    ("ambient", "float"),
    ("blocker_edge", "float"),
    ("camera_pos", "float3"),
    ("curvature_threshold", "float"),
    ("diffuse_threshold", "float"),
    ("light_count", "int"),
    ("light_dir", "float3"),
    ("linear", "sampler"),
    ("shadow_map", "texture2d"),
    ("shininess", "float"),
    ("sky_color", "float3"),
];

/// The type the examples give the uniform `name`, if it is well known.
pub(super) fn well_known_uniform(name: &str) -> Option<&'static str> {
    WELL_KNOWN_UNIFORMS.iter().find(|(n, _)| *n == name).map(|(_, ty)| *ty)
}

/// The closest candidate within a small edit distance, for "did you mean".
pub(super) fn suggest<'s>(name: &str, candidates: impl Iterator<Item = &'s str>) -> Option<&'s str> {
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let d = edit_distance(name, c);
        // Ties go to the alphabetically first name, so output is deterministic.
        if d <= (name.len() / 3).max(1) && best.is_none_or(|(bd, bc)| (d, c) < (bd, bc)) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

// Hand-written: a dozen lines of Levenshtein do not justify a dependency.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// Every well-known uniform is declared, with that type and as no array,
    /// by at least two examples, and with no other type by any.
    #[test]
    fn well_known_uniforms_are_those_of_the_examples() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples");
        let mut declared: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for entry in std::fs::read_dir(dir).expect("examples/ exists") {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "mrsl") {
                continue;
            }
            for line in std::fs::read_to_string(&path).unwrap().lines() {
                let words: Vec<&str> = line.split_whitespace().collect();
                if let ["uniform", ty, name, ..] = words.as_slice() {
                    let name = name.trim_end_matches(';');
                    let ty = if name.contains('[') { format!("{ty}[]") } else { ty.to_string() };
                    declared.entry(name.split('[').next().unwrap().to_string()).or_default().push(ty);
                }
            }
        }
        for (name, ty) in WELL_KNOWN_UNIFORMS {
            let types = declared.get(*name).unwrap_or_else(|| panic!("no example declares `{name}`"));
            assert!(types.len() >= 2, "`{name}` is declared by one example only");
            assert!(types.iter().all(|t| t == ty), "`{name}` is declared as {types:?}, not always as `{ty}`");
        }
    }
}
