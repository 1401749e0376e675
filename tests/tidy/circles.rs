//! Import circles: within each crate, no two modules reach each other's
//! items. A module's references (`use` declarations and paths in its code,
//! tests aside) that start at `crate`, `super` or `self` are resolved to the
//! module they name; a reference from module `a::b::x` to `a::c::y` is an
//! edge between the siblings `a::b` and `a::c` (their common parent's
//! children). A reference up to an ancestor (`super::Item` from a submodule)
//! or down into a child is not an edge: a module and the modules it is made
//! of are one unit. Any cycle among siblings fails, named along its path.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The crates' module trees: the directory of their root file.
const CRATES: [&str; 6] = ["abi/src", "compiler/src", "runtime/src", "lab/src", "cli/src", "bevy_mrsl/src"];

/// A module path inside its crate (`["codegen", "fine"]`; the root is empty).
type Module = Vec<String>;

/// `crate: a <-> b <-> c` for every cycle among sibling modules.
pub fn circles(root: &Path, files: impl Fn(&Path) -> Vec<PathBuf>) -> Vec<String> {
    let mut failures = vec![];
    for tree in CRATES {
        let dir = root.join(tree);
        let modules: BTreeMap<Module, PathBuf> =
            files(&dir).into_iter().filter_map(|f| module_of(&dir, &f).map(|m| (m, f))).collect();
        let known: BTreeSet<Module> = modules.keys().cloned().collect();
        let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for (module, file) in &modules {
            let text = std::fs::read_to_string(file).unwrap_or_default();
            let Ok(syntax) = syn::parse_file(&text) else { continue };
            let mut paths = Paths::default();
            paths.visit_file(&syntax);
            for path in paths.found {
                let Some(target) = resolve(module, &path, &known) else { continue };
                if let Some((from, to)) = siblings(module, &target) {
                    edges.entry(from).or_default().insert(to);
                }
            }
        }
        for cycle in cycles(&edges) {
            let names: Vec<String> = cycle.iter().map(|m| m.join("::")).collect();
            failures.push(format!(
                "{tree}: an import circle: {} (move what both need where neither imports the other)",
                names.join(" <-> ")
            ));
        }
    }
    failures
}

/// The TypeScript trees whose modules must not import each other around a circle.
const TS_TREES: [&str; 2] = ["web/src", "web/playground/src"];

/// `tree: a <-> b` for every cycle among a TypeScript tree's modules, from
/// their relative imports and re-exports (`from './x.js'`).
pub fn ts_circles(root: &Path, files: impl Fn(&Path) -> Vec<PathBuf>) -> Vec<String> {
    let mut failures = vec![];
    for tree in TS_TREES {
        let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for file in files(&root.join(tree)) {
            let Some(stem) = file.file_stem().map(|s| s.to_string_lossy().into_owned()) else { continue };
            let text = std::fs::read_to_string(&file).unwrap_or_default();
            for line in text.lines().filter(|l| l.starts_with("import ") || l.starts_with("export ")) {
                let Some(from) = line.split(" from ").nth(1) else { continue };
                let target = from.trim().trim_end_matches(';').trim_matches(|c| c == '\'' || c == '"');
                if let Some(name) = target.strip_prefix("./").and_then(|t| t.strip_suffix(".js")) {
                    edges.entry(vec![stem.clone()]).or_default().insert(vec![name.to_string()]);
                }
            }
        }
        for cycle in cycles(&edges) {
            let names: Vec<String> = cycle.iter().map(|m| m.join("/")).collect();
            failures.push(format!(
                "{tree}: an import circle: {} (move what both need where neither imports the other)",
                names.join(" <-> ")
            ));
        }
    }
    failures
}

/// The module a source file is, from its path under the crate's `src/`.
fn module_of(dir: &Path, file: &Path) -> Option<Module> {
    let rel = file.strip_prefix(dir).ok()?;
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    let last = parts.pop()?;
    let stem = last.strip_suffix(".rs")?;
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    Some(parts)
}

/// The module a path from `module` names: the longest prefix of its
/// segments, after `crate`, `super` and `self`, that is a known module.
fn resolve(module: &Module, path: &[String], known: &BTreeSet<Module>) -> Option<Module> {
    let mut at: Module = match path.first()?.as_str() {
        "crate" => vec![],
        "super" | "self" => module.clone(),
        _ => return None,
    };
    let mut rest = &path[1..];
    if path[0] == "super" {
        at.pop();
    }
    while rest.first().is_some_and(|s| s == "super") {
        at.pop();
        rest = &rest[1..];
    }
    let mut target = at.clone();
    for segment in rest {
        let mut next = target.clone();
        next.push(segment.clone());
        if !known.contains(&next) {
            break;
        }
        target = next;
    }
    Some(target)
}

/// The siblings a reference from `from` to `to` connects: the children of
/// their common parent that hold each; `None` when one holds the other.
fn siblings(from: &Module, to: &Module) -> Option<(Module, Module)> {
    let common = from.iter().zip(to).take_while(|(a, b)| a == b).count();
    if common == from.len() || common == to.len() {
        return None;
    }
    Some((from[..=common].to_vec(), to[..=common].to_vec()))
}

/// The cycles of a directed graph: each strongly connected component of
/// more than one module, in a path order that follows its edges.
fn cycles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    let nodes: BTreeSet<&Module> = edges.keys().chain(edges.values().flatten()).collect();
    let reaches = |from: &Module| -> BTreeSet<Module> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(m) = stack.pop() {
            for next in edges.get(&m).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<&Module, BTreeSet<Module>> = nodes.iter().map(|&m| (m, reaches(m))).collect();
    let mut done = BTreeSet::new();
    let mut cycles = vec![];
    for &m in &nodes {
        if done.contains(m) || !reach[m].contains(m) {
            continue;
        }
        let component: Vec<Module> =
            nodes.iter().filter(|&&n| reach[m].contains(n) && reach[n].contains(m)).map(|&n| n.clone()).collect();
        done.extend(component.iter().cloned());
        if component.len() > 1 {
            cycles.push(component);
        }
    }
    cycles
}

/// Every path in a file outside its tests: `use` trees (each leaf's path)
/// and paths in code.
#[derive(Default)]
struct Paths {
    found: Vec<Vec<String>>,
}

impl Paths {
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.found.push([prefix.clone(), vec![n.ident.to_string()]].concat()),
            syn::UseTree::Rename(r) => self.found.push([prefix.clone(), vec![r.ident.to_string()]].concat()),
            syn::UseTree::Glob(_) => self.found.push(prefix.clone()),
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| self.use_tree(prefix, t)),
        }
    }
}

impl<'ast> Visit<'ast> for Paths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !crate::is_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !crate::is_test(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.use_tree(&mut vec![], &u.tree);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.found.push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }
}

/// The checks fail on a circle of two files written for them, and not on a
/// parent and child that use each other or a file that imports one of them.
pub fn self_test() {
    let dir = std::env::temp_dir().join(format!("mrsl-tidy-circles-{}", std::process::id()));
    let src = dir.join("abi/src");
    std::fs::create_dir_all(src.join("m")).unwrap();
    let write = |name: &str, text: &str| std::fs::write(src.join(name), text).unwrap();
    write("lib.rs", "//! root\nmod a;\nmod b;\nmod m;\npub struct Root;\n");
    write("a.rs", "//! a\nuse crate::b::B;\npub struct A;\n");
    write("b.rs", "//! b\npub struct B;\nfn f() -> crate::a::A { todo() }\n");
    write("m/mod.rs", "//! m\nmod c;\nuse self::c::C;\npub struct M;\n");
    write("m/c.rs", "//! c\nuse super::M;\npub struct C;\n");
    let files = |d: &Path| {
        let mut all = vec![];
        let mut stack = vec![d.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                let p = e.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "rs") {
                    all.push(p);
                }
            }
        }
        all
    };
    let web = dir.join("web/src");
    std::fs::create_dir_all(&web).unwrap();
    std::fs::write(web.join("a.ts"), "import { B } from './b.js';\nexport const A = 1;\n").unwrap();
    std::fs::write(web.join("b.ts"), "import type { A } from './a.js';\nexport const B = 2;\n").unwrap();
    std::fs::write(web.join("c.ts"), "import { B } from './b.js';\n").unwrap();
    let ts_files = |d: &Path| {
        let mut all: Vec<PathBuf> = std::fs::read_dir(d).into_iter().flatten().flatten().map(|e| e.path()).collect();
        all.sort();
        all
    };
    let found_ts = ts_circles(&dir, ts_files);
    let found = circles(&dir, files);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found, ["abi/src: an import circle: a <-> b (move what both need where neither imports the other)"]);
    assert_eq!(found_ts, ["web/src: an import circle: a <-> b (move what both need where neither imports the other)"]);
}
