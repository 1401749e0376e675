//! The compiler's integration tests, in one binary (see tests/README.md).

mod analysis;
mod contract;
mod corpus;
mod examples;
mod foreign;
mod format;
mod fuzz;
mod highlight;
mod interface;
// The modes the `compile` and `wellformed` fuzz targets build, one per
// execution; the proptest smoke of generated programs builds them the same way.
#[path = "../../fuzz/fuzz_targets/kernels.rs"]
mod kernels;
mod limits;
mod scaling;
mod sourcegen;
mod wellformed;

use mrsl::KernelKind;

/// Compiles with default options, panicking with rendered diagnostics on failure.
#[track_caller]
pub fn compile_ok(source: &str) -> mrsl::Program {
    match mrsl::compile(source, &mrsl::Options::default()) {
        Ok(p) => p,
        Err(d) => panic!("expected the program to compile:\n{}", mrsl::render_all(&d, "test.mrsl", source)),
    }
}

/// The kernels `Options::default()` asks for, as (kind, block size), in the
/// canonical order of `CompiledProgram::kernels` (by kind, then block size).
pub const DEFAULT_KERNELS: [(KernelKind, Option<u32>); 17] = [
    (KernelKind::Coarse, Some(2)),
    (KernelKind::Coarse, Some(4)),
    (KernelKind::Fine, Some(2)),
    (KernelKind::Fine, Some(4)),
    (KernelKind::Tile, Some(2)),
    (KernelKind::Tile, Some(4)),
    (KernelKind::Reference, None),
    (KernelKind::DynamicCoarse, Some(2)),
    (KernelKind::DynamicFine, Some(4)),
    (KernelKind::Hierarchical, None),
    (KernelKind::Checkerboard, None),
    (KernelKind::RateCoarse, None),
    (KernelKind::RateFine, None),
    (KernelKind::MultiCoarse, Some(2)),
    (KernelKind::MultiCoarse, Some(4)),
    (KernelKind::MultiResolve, Some(4)),
    (KernelKind::MultiFine, Some(2)),
];

/// Asserts that `program` (compiled with default options) has exactly the
/// kernels of [`DEFAULT_KERNELS`], and that each kernel's `@compute` entry
/// points are exactly the ones its kind names (`KernelKind::entry_points`),
/// each written as `fn NAME(`: the runtime looks its pipelines up by these names.
#[track_caller]
pub fn assert_kernel_table(name: &str, program: &mrsl::Program) {
    let table: Vec<(KernelKind, Option<u32>)> = program.kernels.iter().map(|k| (k.kind, k.block_size)).collect();
    assert_eq!(table, DEFAULT_KERNELS, "{name}: the kernels generated with default options");
    for kernel in &program.kernels {
        let what = format!("{name}: {} kernel ({:?})", kernel.kind.name(), kernel.block_size);
        for entry_point in kernel.kind.entry_points() {
            assert!(kernel.wgsl.contains(&format!("fn {entry_point}(")), "{what} has no `fn {entry_point}(`");
        }
        let mut expected: Vec<&str> = kernel.kind.entry_points().to_vec();
        expected.sort_unstable();
        let mut found = compute_entry_points(&kernel.wgsl);
        found.sort_unstable();
        assert_eq!(found, expected, "{what}: its `@compute` functions are not the entry points its kind names");
    }
}

/// The names of the functions marked `@compute` in `wgsl`, in text order.
fn compute_entry_points(wgsl: &str) -> Vec<&str> {
    wgsl.match_indices("@compute")
        .map(|(at, _)| {
            let after = &wgsl[at..];
            let name_start = after.find("fn ").expect("an `@compute` attribute precedes a function") + 3;
            let name = &after[name_start..];
            &name[..name.find('(').expect("a function name is followed by `(`")]
        })
        .collect()
}

/// Every program in the top-level `examples/` folder, by file name, in name order.
pub fn examples() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .expect("examples/ exists")
        .map(|entry| entry.expect("examples/ is readable").path())
        .filter(|path| path.extension().is_some_and(|e| e == "mrsl"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|path| {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&path).expect("example is readable"))
        })
        .collect()
}
