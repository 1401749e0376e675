//! Data-driven tests: every program under `tests/data/ok` must compile without
//! errors to the full default kernel table, every program under `tests/data/err`
//! must fail with at least one error. Snapshots hold the source together with
//! the result (the layout and every kernel, or the rendered diagnostics).

use mrsl::{Options, Severity};
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
        crate::assert_kernel_table(&name, &program);
        let mut snapshot = String::new();
        writeln!(snapshot, "----- SOURCE\n{}", source.trim_end()).unwrap();
        if !program.warnings.is_empty() {
            writeln!(snapshot, "----- WARNINGS\n{}", mrsl::render_all(&program.warnings, &name, &source).trim_end())
                .unwrap();
        }
        writeln!(snapshot, "----- LAYOUT\n{}", serde_json::to_string_pretty(&program.layout).unwrap()).unwrap();
        for kernel in &program.kernels {
            let block = kernel.block_size.map(|b| format!(" b{b}")).unwrap_or_default();
            writeln!(snapshot, "----- {}{block} KERNEL\n{}", kernel.kind.name().to_uppercase(), kernel.wgsl.trim_end())
                .unwrap();
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
