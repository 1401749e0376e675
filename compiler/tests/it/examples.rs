//! Every program in the top-level `examples/` folder compiles to valid kernels.

use mrsl::KernelKind;

#[test]
fn every_example_compiles_to_valid_kernels() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("examples/ exists") {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "mrsl") {
            continue;
        }
        let source = std::fs::read_to_string(&path).unwrap();
        let program = crate::compile_ok(&source);
        assert!(program.warnings.is_empty(), "{}: unexpected warnings {:?}", path.display(), program.warnings);
        for block in [2, 4] {
            for kind in [KernelKind::Coarse, KernelKind::Fine] {
                let k = program.kernel(kind, block).expect("kernel generated");
                mrsl::validate_wgsl(&k.wgsl).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            }
        }
        mrsl::validate_wgsl(&program.kernel(KernelKind::Reference, 1).unwrap().wgsl).unwrap();
        count += 1;
    }
    assert!(count >= 6, "expected at least 6 example programs, found {count}");
}
