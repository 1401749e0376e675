//! Data-driven tests: every program under `tests/data/ok` must compile without
//! errors, every program under `tests/data/err` must fail with at least one
//! error. Snapshots hold the source together with the result (layout and
//! kernels, or the rendered diagnostics); every kernel is validated by naga.

use mrsl::{KernelKind, Options, Severity};
use std::fmt::Write;

fn source_of(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).expect("test data is readable")
}

fn file_name(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

#[test]
fn ok_programs() {
    insta::glob!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data"), "ok/*.mrsl", |path| {
        let source = source_of(path);
        let name = file_name(path);
        let options = Options { file_name: name.clone(), ..Options::default() };
        let program = match mrsl::compile(&source, &options) {
            Ok(p) => p,
            Err(d) => panic!("{name} should compile:\n{}", mrsl::render_all(&d, &name, &source)),
        };
        let expects_warning = source.contains("expect-warning:");
        assert_eq!(!program.warnings.is_empty(), expects_warning, "{name}: warnings are {:?}", program.warnings);
        // Every kernel, for both block sizes, is valid WGSL by naga's validator.
        for kernel in &program.kernels {
            if let Err(e) = mrsl::validate_wgsl(&kernel.wgsl) {
                panic!("{name}: {:?} kernel fails naga validation:\n{e}", kernel.kind);
            }
        }
        assert_eq!(
            program.kernels.len(),
            9,
            "coarse+fine for 2x2 and 4x4, reference, two dynamic-mode kernels, hierarchical, checkerboard"
        );
        let mut snapshot = String::new();
        writeln!(snapshot, "----- SOURCE\n{}", source.trim_end()).unwrap();
        if !program.warnings.is_empty() {
            writeln!(snapshot, "----- WARNINGS\n{}", mrsl::render_all(&program.warnings, &name, &source).trim_end())
                .unwrap();
        }
        writeln!(snapshot, "----- LAYOUT\n{}", serde_json::to_string_pretty(&program.layout).unwrap()).unwrap();
        for (kind, block) in [(KernelKind::Coarse, 4), (KernelKind::Fine, 4), (KernelKind::Reference, 1)] {
            let kernel = program.kernel(kind, block).expect("kernel generated");
            writeln!(snapshot, "----- {} KERNEL\n{}", kind.name().to_uppercase(), kernel.wgsl.trim_end()).unwrap();
        }
        insta::assert_snapshot!(snapshot);
    });
}

#[test]
fn err_programs() {
    insta::glob!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data"), "err/*.mrsl", |path| {
        let source = source_of(path);
        let name = file_name(path);
        let options = Options { file_name: name.clone(), ..Options::default() };
        let diagnostics = match mrsl::compile(&source, &options) {
            Ok(_) => panic!("{name} should fail to compile"),
            Err(d) => d,
        };
        assert!(diagnostics.iter().any(|d| d.severity == Severity::Error), "{name}: no error among {diagnostics:?}");
        assert!(!diagnostics.iter().any(|d| d.severity == Severity::Bug), "{name}: internal error {diagnostics:?}");
        // `check` reports the same diagnostics as `compile`.
        assert_eq!(mrsl::check(&source), diagnostics, "{name}: check and compile disagree");
        for d in &diagnostics {
            assert!(d.span().is_some(), "{name}: diagnostic without a source span: {d:?}");
        }
        let rendered = mrsl::render_all(&diagnostics, &name, &source);
        insta::assert_snapshot!(format!(
            "----- SOURCE\n{}\n----- DIAGNOSTICS\n{}",
            source.trim_end(),
            rendered.trim_end()
        ));
    });
}
