//! No input makes the compiler panic, and no program that passes the checks
//! makes it generate WGSL that naga rejects (that would be a compiler bug).
//! Generated well-typed programs (`wellformed.rs`) check and compile with no
//! diagnostic at all. The cargo-fuzz targets in compiler/fuzz run the same
//! properties at scale (docs/fuzzing.md).

use crate::wellformed::{self, SplitMix};
use mrsl::{Mode, Options, Severity};
use proptest::prelude::*;
use std::collections::BTreeSet;

fn options() -> Options {
    // One block size keeps each case fast; the kernels are the same code shape.
    let modes: Vec<Mode> = Mode::ALL.into_iter().filter(|m| *m != Mode::Coarse2x2).collect();
    Options::for_modes(&modes)
}

/// Compiles and fails the test on a panic or on an internal error.
fn no_panic_no_bug(source: &str) {
    if let Err(diagnostics) = mrsl::compile(source, &options()) {
        assert!(
            !diagnostics.iter().any(|d| d.severity == Severity::Bug),
            "internal compiler error on:\n{source}\n{}",
            mrsl::render_all(&diagnostics, "fuzz.mrsl", source)
        );
        // Rendering never fails either, whatever the spans.
        let _ = mrsl::render_all(&diagnostics, "fuzz.mrsl", source);
    }
}

fn seeds() -> Vec<String> {
    let mut out = vec![];
    for dir in ["tests/data/ok", "../examples"] {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
        let mut paths: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        paths.sort();
        for path in paths {
            if path.extension().is_some_and(|e| e == "mrsl") {
                out.push(std::fs::read_to_string(path).unwrap());
            }
        }
    }
    out
}

const TOKENS: &[&str] = &[
    "in",
    "uniform",
    "const",
    "coarse",
    "fine",
    "effect",
    "out",
    "refine",
    "if",
    "else",
    "for",
    "break",
    "continue",
    "return",
    "true",
    "false",
    "(",
    ")",
    "{",
    "}",
    "[",
    "]",
    ";",
    ",",
    ".",
    "?",
    ":",
    "@",
    "=",
    "+=",
    "-=",
    "*=",
    "/=",
    "++",
    "--",
    "+",
    "-",
    "*",
    "/",
    "%",
    "!",
    "~",
    "&",
    "|",
    "^",
    "<<",
    ">>",
    "&&",
    "||",
    "==",
    "!=",
    "<",
    ">",
    "<=",
    ">=",
    "float",
    "float2",
    "float3",
    "float4",
    "int",
    "uint",
    "bool",
    "float4x4",
    "texture2d",
    "sampler",
    "x",
    "y",
    "color",
    "normal",
    "uv",
    "ddx",
    "fwidth",
    "sample",
    "dot",
    "max",
    "saturate",
    "1",
    "2.5",
    "0u",
    "key",
    "nearest",
];

proptest! {
    // MRSL_FUZZ_CASES=20000 for a deeper local run; 256 cases keep CI quick.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("MRSL_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        no_panic_no_bug(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn random_token_streams(tokens in proptest::collection::vec(0..TOKENS.len(), 0..80)) {
        let source: Vec<&str> = tokens.iter().map(|&t| TOKENS[t]).collect();
        no_panic_no_bug(&source.join(" "));
    }

    #[test]
    fn mutated_valid_programs(seed in 0usize..1000, edits in proptest::collection::vec((any::<u16>(), 0u8..4, 0..TOKENS.len()), 1..4)) {
        let seeds = seeds();
        let mut source = seeds[seed % seeds.len()].clone();
        for (position, kind, token) in edits {
            let mut at = position as usize % (source.len() + 1);
            while !source.is_char_boundary(at) {
                at -= 1;
            }
            let end = source[at..].char_indices().nth(1 + position as usize % 6).map(|(i, _)| at + i).unwrap_or(source.len());
            match kind {
                0 => source.replace_range(at..end, ""),
                1 => source.insert_str(at, &format!(" {} ", TOKENS[token])),
                2 => source.replace_range(at..end, TOKENS[token]),
                _ => {
                    // Swap two neighbouring words.
                    let words: Vec<&str> = source.split(' ').collect();
                    if words.len() > 2 {
                        let i = position as usize % (words.len() - 1);
                        let mut w: Vec<String> = words.iter().map(|s| s.to_string()).collect();
                        w.swap(i, i + 1);
                        source = w.join(" ");
                    }
                }
            }
        }
        no_panic_no_bug(&source);
    }
}

/// A generated program passes every check and compiles (the kernels of
/// `options`), with no diagnostic at all; the failure message holds the program.
fn assert_well_formed(source: &str, options: &Options) {
    let allowed_warning = |d: &mrsl::Diagnostic| wellformed::ALLOWED_WARNINGS.contains(&d.code);
    let mut diagnostics = mrsl::check(source);
    diagnostics.retain(|d| !allowed_warning(d));
    assert!(
        diagnostics.is_empty(),
        "a generated program has diagnostics:\n{source}\n{}",
        mrsl::render_all(&diagnostics, "generated.mrsl", source)
    );
    match mrsl::compile(source, options) {
        Ok(program) => {
            assert!(program.warnings.iter().all(allowed_warning), "a generated program warns:\n{source}")
        }
        Err(diagnostics) => panic!(
            "a generated program does not compile:\n{source}\n{}",
            mrsl::render_all(&diagnostics, "generated.mrsl", source)
        ),
    }
}

proptest! {
    // Each case compiles a program (naga included); MRSL_WELLFORMED_CASES=5000 for a deeper run.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("MRSL_WELLFORMED_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(24),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn generated_well_typed_programs_compile(seed in any::<u64>()) {
        // The kernels of one mode per program, as the `wellformed` fuzz
        // target builds them: every kind over the cases, at a fraction of
        // the cost of all of them per case.
        let options = crate::kernels::options((seed % crate::kernels::CHOICES as u64) as usize);
        assert_well_formed(&wellformed::program(&mut SplitMix(seed)).source, &options);
    }
}

/// Every warning the compiler can give (each `Diagnostic::warning("W...")`
/// in its source) is one the generator's programs may draw or one it avoids
/// ([`wellformed::ALLOWED_WARNINGS`], [`wellformed::AVOIDED_WARNINGS`]): a
/// warning added to the compiler fails here until the generator and the
/// `wellformed` fuzz target know it, instead of stopping a campaign.
#[test]
fn the_generator_knows_every_warning() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut codes = BTreeSet::new();
    let mut stack = vec![dir];
    while let Some(path) = stack.pop() {
        if path.is_dir() {
            stack.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            // rustfmt may break the line after the opening parenthesis.
            for (at, _) in text.match_indices("Diagnostic::warning(") {
                let code = text[at + "Diagnostic::warning(".len()..].trim_start();
                if let Some(code) = code.strip_prefix('"') {
                    codes.insert(code[..code.find('"').unwrap()].to_string());
                }
            }
        }
    }
    assert!(codes.contains("W0001"), "the scan found the compiler's warnings: {codes:?}");
    let known: BTreeSet<String> =
        wellformed::ALLOWED_WARNINGS.iter().chain(wellformed::AVOIDED_WARNINGS).map(|c| c.to_string()).collect();
    assert_eq!(codes, known, "the compiler's warnings against those the generator allows or avoids");
}

/// What the generator must keep producing: a change that loses a feature
/// fails here rather than silently narrowing the fuzzing.
const GENERATOR_FEATURES: &[&str] = &[
    "input",
    "@key",
    "@key(threshold)",
    "@surface_key",
    "@background",
    "@foreground",
    "uniform",
    "uniform default",
    "uniform array",
    "uniform array default",
    "texture2d",
    "sampler",
    "const",
    "constant arithmetic",
    "function",
    "texture parameter",
    "parameter assignment",
    "early return",
    "coarse effect",
    "coarse(4) effect",
    "coarse(2) effect",
    "fine effect",
    "fine out",
    "@nearest",
    "@format",
    "expression-form effect",
    "block-form effect",
    "refine",
    "refine on derivative",
    "refine on derivative of own value",
    "refine (unconditional)",
    "local",
    "local without initialiser",
    "component assignment",
    "indexed assignment",
    "column assignment",
    "compound assignment",
    "compound assignment with scalar",
    "++/--",
    "if",
    "else",
    "for",
    "break",
    "continue",
    "block statement",
    "ddx",
    "ddy",
    "fwidth",
    "ddx_surface",
    "ddy_surface",
    "fwidth_surface",
    "sample",
    "sample_level",
    "sample_grad",
    "load",
    "texture_size",
    "effect read",
    "builtin call",
    "user function call",
    "swizzle",
    "vector index",
    "dynamic index",
    "uniform array index",
    "matrix column",
    "matrix",
    "matrix * vector",
    "determinant",
    "vector constructor",
    "splat",
    "abstract int in float constructor",
    "conversion",
    "scalar broadcast",
    "+ -",
    "*",
    "/",
    "%",
    "unary -",
    "~",
    "bitwise",
    "shift",
    "comparison",
    "vector comparison",
    "&& ||",
    "!",
    "any/all",
    "dot",
    "?:",
    // What earlier fuzzing found mishandled (docs/eval/fuzzing-campaigns.md, findings).
    "?: on matrices",
    "@nearest matrix",
    "name WGSL reserves or escapes",
    "local shadowing a constant or function",
    "constant operation",
    "constant index expression",
    "constant shift amount expression",
    "local holding a constant as index",
    "local holding a constant as divisor",
    "local holding a constant as shift amount",
];

#[test]
fn the_generator_covers_the_language() {
    let mut seen = std::collections::BTreeSet::new();
    for seed in 0..1000 {
        seen.extend(wellformed::program(&mut SplitMix(seed)).features);
    }
    let missing: Vec<&&str> = GENERATOR_FEATURES.iter().filter(|f| !seen.contains(**f)).collect();
    assert!(missing.is_empty(), "1,000 generated programs never use {missing:?}");
    if let Ok(dir) = std::env::var("MRSL_WELLFORMED_DUMP") {
        // Writes a few programs to look at: MRSL_WELLFORMED_DUMP=/tmp/gen.
        std::fs::create_dir_all(&dir).unwrap();
        let count = std::env::var("MRSL_WELLFORMED_DUMP_COUNT").ok().and_then(|v| v.parse().ok()).unwrap_or(20);
        for seed in 0..count {
            let g = wellformed::program(&mut SplitMix(seed));
            std::fs::write(format!("{dir}/gen{seed:04}.mrsl"), g.source).unwrap();
        }
    }
}
