//! The formatter (`mrsl::format`, `mrslc fmt`): idempotent, and the
//! formatted program is the same program, kernel for kernel, with every
//! comment kept, on the examples, the corpus and generated programs; the
//! examples and the corpus are committed formatted.

use crate::wellformed::{self, Choices, SplitMix};
use mrsl::internals::Lexer;
use std::path::{Path, PathBuf};

fn programs(dir: &str) -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    paths.sort();
    paths
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "mrsl"))
        .map(|p| {
            let source = std::fs::read_to_string(&p).unwrap();
            (p, source)
        })
        .collect()
}

/// Formats, asserting that formatting again changes nothing and that every
/// comment is kept (as a multiset of texts, trailing whitespace aside).
#[track_caller]
fn format_checked(name: &str, source: &str) -> String {
    let formatted = mrsl::format(source)
        .unwrap_or_else(|d| panic!("{name} does not format:\n{}", mrsl::render_all(&[d], name, source)));
    let again = mrsl::format(&formatted).unwrap_or_else(|d| panic!("{name} formatted does not format: {}", d.message));
    assert_eq!(again, formatted, "{name}: formatting twice changes the result:\n{formatted}");
    assert_eq!(comments(&formatted), comments(source), "{name}: the comments differ once formatted:\n{formatted}");
    formatted
}

/// Every comment of `source`, found between its tokens, sorted.
fn comments(source: &str) -> Vec<String> {
    let mut found = vec![];
    let mut gap_start = 0;
    let tokens: Vec<(usize, usize)> = Lexer::new(source).map_while(Result::ok).map(|(s, _, e)| (s, e)).collect();
    for (start, end) in tokens.into_iter().chain(std::iter::once((source.len(), source.len()))) {
        let mut gap = &source[gap_start..start];
        while let Some(at) = gap.find('/') {
            gap = &gap[at..];
            let len =
                if gap.starts_with("//") { gap.find('\n').unwrap_or(gap.len()) } else { gap.find("*/").unwrap() + 2 };
            found.push(gap[..len].lines().map(str::trim_end).collect::<Vec<_>>().join("\n"));
            gap = &gap[len..];
        }
        gap_start = end;
    }
    found.sort();
    found
}

/// The kernels (kind, block size, WGSL) and the layout JSON of a program
/// compiled with `options`.
fn compiled(name: &str, source: &str, options: &mrsl::Options) -> (Vec<(String, Option<u32>, String)>, String) {
    let program = mrsl::compile(source, options)
        .unwrap_or_else(|d| panic!("{name} does not compile:\n{}", mrsl::render_all(&d, name, source)));
    let kernels = program.kernels.iter().map(|k| (k.kind.name().to_string(), k.block_size, k.wgsl.clone())).collect();
    (kernels, program.layout.to_json())
}

/// The kernels and the layout of `source` and of `formatted` are the same,
/// byte for byte (the kernels' comments name declarations and statements,
/// never source lines, and quote a derivative operand in the canonical
/// layout, `mrsl::format`'s own).
#[track_caller]
fn assert_same_kernels(name: &str, source: &str, formatted: &str, options: &mrsl::Options) {
    let (before, layout_before) = compiled(name, source, options);
    let (after, layout_after) = compiled(name, formatted, options);
    assert_eq!(layout_after, layout_before, "{name}: the layout changes once formatted");
    assert_eq!(after.len(), before.len(), "{name}: the kernels change once formatted");
    for ((kind, block, wgsl), (_, _, formatted_wgsl)) in before.iter().zip(&after) {
        assert!(wgsl == formatted_wgsl, "{name}: the {kind} kernel ({block:?}) changes once formatted");
    }
}

#[test]
fn examples_and_ok_programs_format_to_the_same_kernels_and_layout() {
    for (path, source) in programs("../examples").into_iter().chain(programs("tests/data/ok")) {
        let name = path.display().to_string();
        let formatted = format_checked(&name, &source);
        assert_same_kernels(&name, &source, &formatted, &mrsl::Options::default());
    }
}

/// The examples and the corpus, `ok` and `err` (every program that parses),
/// are committed in the canonical layout: `mrslc fmt examples
/// compiler/tests/data` fixes a failure here.
#[test]
fn examples_and_the_corpus_are_formatted() {
    let mut unformatted = vec![];
    let corpus = programs("tests/data/ok").into_iter().chain(programs("tests/data/err"));
    for (path, source) in programs("../examples").into_iter().chain(corpus) {
        if mrsl::internals::parse(&source).is_err() {
            continue;
        }
        if mrsl::format(&source).ok().as_ref() != Some(&source) {
            unformatted.push(path.display().to_string());
        }
    }
    assert!(unformatted.is_empty(), "not formatted (run `mrslc fmt` on them): {unformatted:#?}");
}

/// Every `err` program that parses formats idempotently, with its comments,
/// to a program with the same diagnostics (codes and messages, in order);
/// one that does not parse is its syntax error.
#[test]
fn err_programs_format_to_the_same_diagnostics() {
    let summary = |diagnostics: Vec<mrsl::Diagnostic>| -> Vec<(String, String)> {
        diagnostics.into_iter().map(|d| (d.code.to_string(), d.message)).collect()
    };
    for (path, source) in programs("tests/data/err") {
        let name = path.display().to_string();
        if let Err(syntax) = mrsl::internals::parse(&source) {
            let error = mrsl::format(&source).expect_err("a program that does not parse does not format");
            assert_eq!((error.code, &error.message), (syntax.code, &syntax.message), "{name}");
            continue;
        }
        let formatted = format_checked(&name, &source);
        assert_eq!(summary(mrsl::check(&formatted)), summary(mrsl::check(&source)), "{name}");
    }
}

/// A generated program with comments between tokens: `/* bN */` or `// cN`
/// (and a line break), at about one gap in five.
fn with_comments(source: &str, rng: &mut SplitMix) -> String {
    let ends: Vec<usize> = Lexer::new(source).map_while(Result::ok).map(|(_, _, e)| e).collect();
    let mut out = String::with_capacity(source.len() * 2);
    let mut from = 0;
    for (n, end) in ends.into_iter().enumerate() {
        out.push_str(&source[from..end]);
        from = end;
        match rng.below(10) {
            0 => out.push_str(&format!(" /* b{n} */ ")),
            1 => out.push_str(&format!(" // c{n}\n")),
            _ => {}
        }
    }
    out.push_str(&source[from..]);
    out
}

/// 10,000 generated programs with comments between their tokens, and one
/// in ten as generated: formatting is idempotent and keeps every comment.
/// (Each format parses twice, the input and, to check it, the result;
/// parsing is most of the cost, about a millisecond a program.)
#[test]
fn generated_programs_format_idempotently_with_their_comments() {
    let cases = std::env::var("MRSL_FORMAT_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(10_000u64);
    for seed in 0..cases {
        let source = wellformed::program(&mut SplitMix(seed)).source;
        if seed % 10 == 0 {
            format_checked(&format!("generated program {seed}"), &source);
        }
        let commented = with_comments(&source, &mut SplitMix(seed ^ 0x5eed));
        format_checked(&format!("generated program {seed} with comments"), &commented);
    }
}

/// Generated programs compile to the same kernels and layout formatted, with
/// comments between their tokens. Fewer cases than above: each compiles
/// twice, naga validation included, and builds the kernels of one mode (as
/// the fuzz smoke does, `kernels::options`) rather than all seventeen.
#[test]
fn generated_programs_format_to_the_same_kernels() {
    for seed in 0..200u64 {
        let source = wellformed::program(&mut SplitMix(seed)).source;
        let commented = with_comments(&source, &mut SplitMix(seed ^ 0x5eed));
        let name = format!("generated program {seed}");
        let formatted = mrsl::format(&commented).unwrap_or_else(|d| panic!("{name}: {}", d.message));
        let options = crate::kernels::options((seed % crate::kernels::CHOICES as u64) as usize);
        assert_same_kernels(&name, &source, &formatted, &options);
    }
}
