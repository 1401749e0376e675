//! Function lengths: no function of the crates' sources (tests aside) runs
//! over [`MAX_FUNCTION_LINES`] lines, so that each reads as one concern.
//! The sources are parsed (`syn`), so braces in strings and raw strings do
//! not count.

use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The longest a function may be, from `fn` to its closing brace.
pub const MAX_FUNCTION_LINES: usize = 100;

/// The source trees checked: each crate's `src/` (and the lab's and the
/// CLI's examples); tests, benches and fuzz targets are not.
const SOURCE_TREES: [&str; 8] =
    ["abi/src", "compiler/src", "runtime/src", "runtime/wgpu29", "lab/src", "lab/examples", "cli/src", "bevy_mrsl/src"];

/// `path: name runs N lines (at most M)` for every function over the limit.
pub fn too_long(root: &Path, files: impl Fn(&Path) -> Vec<PathBuf>) -> Vec<String> {
    let mut failures = vec![];
    for tree in SOURCE_TREES {
        for file in files(&root.join(tree)) {
            let text = std::fs::read_to_string(&file).unwrap_or_default();
            let name = file.strip_prefix(root).unwrap_or(&file).display().to_string();
            let syntax = match syn::parse_file(&text) {
                Ok(syntax) => syntax,
                Err(e) => {
                    failures.push(format!("{name}: does not parse ({e})"));
                    continue;
                }
            };
            let mut lengths = Lengths::default();
            lengths.visit_file(&syntax);
            for (function, lines) in lengths.functions {
                if lines > MAX_FUNCTION_LINES {
                    failures.push(format!(
                        "{name}: `{function}` runs {lines} lines (at most {MAX_FUNCTION_LINES}: split it by concern)"
                    ));
                }
            }
        }
    }
    failures
}

/// Every function's name and lines, outside `#[cfg(test)]` modules and `#[test]` functions.
#[derive(Default)]
struct Lengths {
    functions: Vec<(String, usize)>,
}

impl Lengths {
    fn record(&mut self, name: &syn::Ident, fn_token: &syn::token::Fn, block: &syn::Block) {
        let lines = block.brace_token.span.close().end().line + 1 - fn_token.span.start().line;
        self.functions.push((name.to_string(), lines));
    }
}

impl<'ast> Visit<'ast> for Lengths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !crate::is_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !crate::is_test(&f.attrs) {
            self.record(&f.sig.ident, &f.sig.fn_token, &f.block);
            syn::visit::visit_item_fn(self, f);
        }
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !crate::is_test(&f.attrs) {
            self.record(&f.sig.ident, &f.sig.fn_token, &f.block);
            syn::visit::visit_impl_item_fn(self, f);
        }
    }

    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(block) = &f.default {
            self.record(&f.sig.ident, &f.sig.fn_token, block);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }
}

/// The check measures what it should: a long function fails, a long test does not.
pub fn self_test() {
    let long_body = "    let x = 1;\n".repeat(MAX_FUNCTION_LINES);
    let source = format!(
        "fn short() {{}}\nfn long() {{\n{long_body}}}\n#[cfg(test)]\nmod tests {{\n    fn long_test() {{\n{long_body}    }}\n}}\n\
         const S: &str = \"}}}}}}\";\n"
    );
    let mut lengths = Lengths::default();
    lengths.visit_file(&syn::parse_file(&source).expect("the self-test source parses"));
    let names: Vec<(&str, usize)> = lengths.functions.iter().map(|(n, l)| (n.as_str(), *l)).collect();
    assert_eq!(names, [("short", 1), ("long", MAX_FUNCTION_LINES + 2)], "function lengths self-test");
}
