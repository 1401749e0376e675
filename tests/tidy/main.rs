//! Tidy checks that keep the docs and sources honest, run with the tests
//! (after rust-analyzer's `xtask/src/tidy.rs`):
//!
//! - every name a doc puts in backticks that looks like a path of this
//!   repository exists, and every Rust-looking name (`Type`, `Type::item`,
//!   `function()`) still occurs in the code, in ARCHITECTURE.md, README.md,
//!   compiler/tests/README.md and every file under docs/ (CHANGELOG.md is
//!   history and is not checked); in ARCHITECTURE.md and README.md, which
//!   map the code, every `snake_case` name too;
//! - every Rust module opens with a `//!` comment;
//! - no function of the crates' sources runs over 100 lines (`lengths`);
//! - no two modules of a crate import each other, directly or around a
//!   circle (`circles`).
//!
//! Names from outside the repository (wgpu, WebGPU, the papers) are told
//! apart by where they occur: a name counts as known when it occurs in the
//! code of this repository (its `.rs`, `.wgsl`, `.ts` and `.mrsl` files,
//! comments removed), so only what the repository once had and has no more
//! fails.

mod circles;
mod lengths;

use std::collections::{BTreeSet, HashSet};
use std::path::{Path, PathBuf};

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut failures = vec![];
    let known = Known::scan(&root);
    for doc in docs(&root) {
        let text = std::fs::read_to_string(&doc).expect("docs are readable");
        let name = doc.strip_prefix(&root).unwrap_or(&doc).display().to_string();
        // The code maps name private items too; the other docs are held to paths and public names.
        let strict = name == "ARCHITECTURE.md" || name == "README.md";
        for stale in stale_names(&text, &doc, &root, &known, strict) {
            failures.push(format!("{name}: `{stale}` names nothing in the repository"));
        }
    }
    for file in files(&root, &["rs"]) {
        let text = std::fs::read_to_string(&file).unwrap_or_default();
        if !text.starts_with("//!") {
            failures
                .push(format!("{}: does not open with a `//!` comment", file.strip_prefix(&root).unwrap().display()));
        }
    }
    failures.extend(lengths::too_long(&root, |dir| files(dir, &["rs"])));
    failures.extend(circles::circles(&root, |dir| files(dir, &["rs"])));
    failures.extend(circles::ts_circles(&root, |dir| files(dir, &["ts"])));
    self_test();
    lengths::self_test();
    circles::self_test();
    if failures.is_empty() {
        println!("tidy: docs and modules are in order");
        return;
    }
    for f in &failures {
        eprintln!("{f}");
    }
    eprintln!("tidy: {} problem(s); fix the doc (or the code) so each names what exists", failures.len());
    std::process::exit(1);
}

/// The docs checked.
/// Whether an item is test code (`#[test]`, `#[cfg(test)]`), which the
/// module and length checks leave out.
fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("test")
            || (a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test"))
    })
}

fn docs(root: &Path) -> Vec<PathBuf> {
    let mut docs = vec![root.join("ARCHITECTURE.md"), root.join("README.md")];
    let mut under: Vec<PathBuf> =
        files(&root.join("docs"), &["md"]).into_iter().chain(files(&root.join("compiler/tests"), &["md"])).collect();
    under.sort();
    docs.extend(under);
    docs.retain(|d| d.exists());
    docs
}

/// Files under `dir` with one of `extensions`, outside build output, VCS and node_modules.
fn files(dir: &Path, extensions: &[&str]) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            if path.is_dir() {
                if !matches!(name.as_str(), "target" | ".git" | "node_modules" | "fuzz" | "snapshots")
                    && !name.starts_with("target")
                {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| extensions.iter().any(|x| e == *x)) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// Every identifier that occurs in the repository's code.
struct Known {
    words: HashSet<String>,
    /// Every file and directory, relative to the root with a leading `/`.
    paths: Vec<String>,
    /// The root's entries (`abi`, `compiler`, `README.md`, ...).
    top_level: HashSet<String>,
    /// Functions defined (`fn name`), for `name()` in docs.
    functions: HashSet<String>,
}

impl Known {
    fn scan(root: &Path) -> Known {
        let mut words = HashSet::new();
        let mut functions = HashSet::new();
        let mut sources = files(root, &["rs", "wgsl", "ts", "mrsl", "toml", "js", "json"]);
        sources.extend(files(&root.join("compiler/fuzz"), &["rs"]));
        for file in sources {
            let text = std::fs::read_to_string(&file).unwrap_or_default();
            let code = strip_comments(&text);
            let tokens = identifiers(&code);
            for pair in tokens.windows(2) {
                if pair[0] == "fn" || pair[0] == "function" {
                    functions.insert(pair[1].to_string());
                }
            }
            words.extend(tokens.into_iter().map(String::from));
        }
        let mut paths = vec![];
        let mut stack = vec![root.to_path_buf()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
                let path = entry.path();
                let name = entry.file_name().to_string_lossy().into_owned();
                // Build output and what the tools write (`out/`) are not the repository's.
                if name.starts_with("target") || matches!(name.as_str(), ".git" | "node_modules" | "out") {
                    continue;
                }
                paths.push(format!("/{}", path.strip_prefix(root).unwrap().display()));
                if path.is_dir() {
                    stack.push(path);
                }
            }
        }
        let top_level = paths.iter().filter(|p| p[1..].find('/').is_none()).map(|p| p[1..].to_string()).collect();
        Known { words, functions, paths, top_level }
    }
}

/// `text` without `//` line comments (a `//` inside a string is rare enough in this code to ignore).
fn strip_comments(text: &str) -> String {
    text.lines()
        .map(|line| match line.find("//") {
            // Keep URLs and doc-test code: only a `//` at a comment's start counts.
            Some(at) if !line[..at].ends_with(':') => &line[..at],
            _ => line,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn identifiers(text: &str) -> Vec<&str> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect()
}

/// The backticked names in `text` that look like the repository's and name nothing in it.
fn stale_names(text: &str, doc: &Path, root: &Path, known: &Known, strict: bool) -> BTreeSet<String> {
    let mut stale = BTreeSet::new();
    let mut in_fence = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        for span in backticked(line) {
            if !names_something(span, doc, root, known, strict) {
                stale.insert(span.to_string());
            }
        }
    }
    stale
}

/// The inline code spans of a line.
fn backticked(line: &str) -> Vec<&str> {
    line.split('`').skip(1).step_by(2).collect()
}

/// Whether a code span names something that exists, or is not a name this check judges.
fn names_something(span: &str, doc: &Path, root: &Path, known: &Known, strict: bool) -> bool {
    let span = span.trim();
    if let Some(path) = repository_path(span, known) {
        let here = doc.parent().unwrap_or(root);
        return EXTERNAL_PATHS.contains(&path)
            || root.join(path).exists()
            || here.join(path).exists()
            || known.paths.iter().any(|p| p.ends_with(&format!("/{path}")));
    }
    if span.contains(' ') || span.contains('<') || span.contains('=') || span.contains('"') {
        return true;
    }
    // `name()` or `Type::name()`: a function defined in the code.
    if let Some(call) = span.strip_suffix("()") {
        let last = call.rsplit("::").next().unwrap_or(call).rsplit('.').next().unwrap_or(call);
        return !is_identifier(last) || known.functions.contains(last) || known.words.contains(last);
    }
    // A Rust path: every segment occurs in the code.
    if span.contains("::") {
        return span.split("::").filter(|s| is_identifier(s)).all(|s| known.words.contains(s));
    }
    // A type-like name: CamelCase (no underscores) with a lower-case letter.
    let camel = span.len() >= 4
        && span.starts_with(|c: char| c.is_ascii_uppercase())
        && span.chars().all(|c| c.is_ascii_alphanumeric())
        && span.contains(|c: char| c.is_ascii_lowercase());
    // A snake_case (or SCREAMING_CASE) identifier: a function, field, constant, entry point.
    let snake = strict && is_identifier(span) && span.contains('_') && !span.starts_with('_');
    !(camel || snake) || known.words.contains(span)
}

/// Paths in other packages that the docs cite (the Sponza file inside the
/// `obj-rs` crate, the dungeon inside Debian's castle-game-engine-doc).
const EXTERNAL_PATHS: [&str; 2] = ["tests/fixtures/sponza.obj", "examples/third_person_navigation/data/level"];

/// The repository path a code span names, if it looks like one: a relative
/// path that starts at a top-level entry of the repository, or a file name
/// with a source extension; without placeholders (`STEM`, `NAME`, `*`),
/// URLs or options.
fn repository_path<'s>(span: &'s str, known: &Known) -> Option<&'s str> {
    const SOURCES: [&str; 7] = [".rs", ".wgsl", ".mrsl", ".lalrpop", ".sh", ".ts", ".md"];
    let plain = span.chars().all(|c| c.is_ascii_alphanumeric() || "/._-".contains(c));
    let placeholder = span.chars().any(|c| c.is_ascii_uppercase()) && !span.ends_with(".md");
    if !plain || placeholder || span.starts_with('/') || span.starts_with('.') || span.len() <= 3 {
        return None;
    }
    let span = span.trim_end_matches('/');
    let first = span.split('/').next().unwrap_or(span);
    let top_level = span.contains('/') && known.top_level.contains(first);
    (top_level || SOURCES.iter().any(|e| span.ends_with(e))).then_some(span)
}

fn is_identifier(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || c == '_') && !s.starts_with(|c: char| c.is_ascii_digit())
}

/// The checker itself fails on a planted stale name of each kind, and
/// passes names that exist.
fn self_test() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let known = Known {
        words: ["Shader", "encode", "Layout"].map(String::from).into(),
        functions: ["encode".into()].into(),
        paths: vec!["/runtime/src/lib.rs".into()],
        top_level: ["runtime".into()].into(),
    };
    let doc = root.join("ARCHITECTURE.md");
    let text = "`Shader::encode`, `Layout`, `encode()`, `runtime/src/lib.rs`, `--mode`, `vec3<f32>`.\n\
                `Shader::record_texture`, `MissingType`, `finish_stage_group()`, `runtime/src/gone.rs`.";
    let stale: Vec<String> = stale_names(text, &doc, &root, &known, false).into_iter().collect();
    assert_eq!(stale, ["MissingType", "Shader::record_texture", "finish_stage_group()", "runtime/src/gone.rs"]);
    // In a code map, private snake_case names are held to the code too.
    let stale: Vec<String> = stale_names("`encode`, `record_texture`", &doc, &root, &known, true).into_iter().collect();
    assert_eq!(stale, ["record_texture"]);
}
