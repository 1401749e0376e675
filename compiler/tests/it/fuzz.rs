//! No input makes the compiler panic, and no program that passes the checks
//! makes it generate WGSL that naga rejects (that would be a compiler bug).

use mrsl::{Options, Severity};
use proptest::prelude::*;

fn options() -> Options {
    // One block size keeps each case fast; the kernels are the same code shape.
    Options { block_sizes: vec![4], ..Options::default() }
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
