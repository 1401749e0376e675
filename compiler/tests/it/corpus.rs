//! Data-driven tests over `tests/data` (see tests/README.md). Every program
//! under `ok/` must compile, with exactly the warnings its `// expect-warning:`
//! header names (none without one), to the full default kernel table. Every
//! program under `err/` must fail with exactly the diagnostic codes its
//! `// expect:` header names. An ok/ case has a folder of snapshots
//! (`snapshots/ok/CASE/`): the source with its layout, its plan, and one file
//! per kernel; an err/ case one snapshot of the source and its rendered
//! diagnostics.

use mrsl::{Diagnostic, Options, Severity};
use std::fmt::Write;

/// The header of an `err/` file: the code of every diagnostic, in report order.
const ERR_HEADER: &str = "expect";
/// The header of an `ok/` file that compiles with warnings: their codes, in report order.
const OK_HEADER: &str = "expect-warning";

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
        let header = header_codes(&source, OK_HEADER).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            header_codes(&source, ERR_HEADER).is_ok_and(|h| h.is_none()),
            "{name}: an ok/ file states its warnings with `// {OK_HEADER}:`, not `// {ERR_HEADER}:`"
        );
        // `check` reports the warnings `compile` does.
        assert_eq!(mrsl::check(&source), program.warnings, "{name}: check and compile disagree");
        let warned = codes(&program.warnings);
        match header {
            Some(expected) => assert_eq!(
                expected,
                warned,
                "{name}: the `// {OK_HEADER}:` header does not list the codes of the warnings reported:\n{}",
                mrsl::render_all(&program.warnings, &name, &source)
            ),
            None => assert!(
                warned.is_empty(),
                "{name} compiles with warnings {warned:?}; fix the program, or name their codes in a \
                 `// {OK_HEADER}: {}: ...` header:\n{}",
                warned.join(", "),
                mrsl::render_all(&program.warnings, &name, &source)
            ),
        }
        crate::assert_kernel_table(&name, &program);
        // One golden file per output, in a folder per case: the layout (with
        // the source and warnings), the plan, and each kernel on its own, so
        // a change to one kernel family rewrites only that family's files.
        let mut settings = insta::Settings::clone_current();
        settings.set_snapshot_path(format!("snapshots/ok/{}", name.trim_end_matches(".mrsl")));
        settings.set_prepend_module_to_snapshot(false);
        settings.remove_snapshot_suffix();
        settings.set_omit_expression(true);
        settings.bind(|| {
            insta::assert_snapshot!("layout", layout_snapshot(&source, &name, &program));
            insta::assert_snapshot!("plan", plan_snapshot(&program.layout.plan));
            for kernel in &program.kernels {
                let file = kernel.file_name("");
                insta::assert_snapshot!(file.trim_start_matches('.').trim_end_matches(".wgsl"), kernel.wgsl.trim_end());
            }
        });
    });
}

/// The cases whose hierarchical kernel also has a golden file compiled with
/// packed records (`Options::packed_records`): values of every kind a
/// record packs (int, uint and bool; matrices; a background rule and a
/// surface key), as `snapshots/ok/CASE/hierarchical.packed.snap`.
const PACKED_CASES: [&str; 3] =
    ["0036_int_uint_bool_coarse", "0054_matrix_select_and_nearest", "0075_background_and_surface_key"];

#[test]
fn packed_record_kernels() {
    for case in PACKED_CASES {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/ok/{case}.mrsl"));
        let source = source_of(&path);
        let options = Options {
            file_name: file_name(&path),
            packed_records: true,
            ..Options::for_modes(&[mrsl_abi::Mode::Hierarchical])
        };
        let program = mrsl::compile(&source, &options).unwrap_or_else(|d| panic!("{case}: {d:?}"));
        assert!(program.layout.hierarchical.packed);
        let kernel = program.kernel(mrsl_abi::KernelKind::Hierarchical, 1).expect("a hierarchical kernel");
        let mut settings = insta::Settings::clone_current();
        settings.set_snapshot_path(format!("snapshots/ok/{case}"));
        settings.set_prepend_module_to_snapshot(false);
        settings.remove_snapshot_suffix();
        settings.set_omit_expression(true);
        settings.bind(|| insta::assert_snapshot!("hierarchical.packed", kernel.wgsl.trim_end()));
    }
}

/// The source, the warnings if any, and the layout without its plan.
fn layout_snapshot(source: &str, name: &str, program: &mrsl::Program) -> String {
    let mut snapshot = String::new();
    writeln!(snapshot, "----- SOURCE\n{}", source.trim_end()).unwrap();
    if !program.warnings.is_empty() {
        writeln!(snapshot, "----- WARNINGS\n{}", mrsl::render_all(&program.warnings, name, source).trim_end()).unwrap();
    }
    let mut layout = serde_json::to_value(&program.layout).unwrap();
    layout.as_object_mut().unwrap().remove("plan");
    writeln!(snapshot, "----- LAYOUT\n{}", serde_json::to_string_pretty(&layout).unwrap()).unwrap();
    snapshot
}

/// The plan as a reviewer reads it: per mode its kernels, counts and steps
/// (a pass with a line per binding and per dispatch); then one resource per
/// line. Each item is its JSON, as the layout holds it.
fn plan_snapshot(plan: &mrsl::Plan) -> String {
    let mut snapshot = String::new();
    for mode in &plan.modes {
        writeln!(snapshot, "----- MODE {}", mode.mode).unwrap();
        writeln!(snapshot, "kernels: {}", json(&mode.kernels)).unwrap();
        writeln!(snapshot, "counts: {}", json(&mode.counts)).unwrap();
        for step in &mode.steps {
            let mrsl_abi::plan::Step::Pass(pass) = step else {
                writeln!(snapshot, "{}", json(step)).unwrap();
                continue;
            };
            writeln!(snapshot, "pass {:?} ({:?}) {}", pass.label, pass.stage, json(&pass.kernel)).unwrap();
            for binding in &pass.bindings {
                writeln!(snapshot, "  binding {}", json(binding)).unwrap();
            }
            for dispatch in &pass.dispatches {
                writeln!(snapshot, "  dispatch {}", json(dispatch)).unwrap();
            }
        }
    }
    writeln!(snapshot, "----- RESOURCES").unwrap();
    for resource in &plan.resources {
        writeln!(snapshot, "{}", json(resource)).unwrap();
    }
    snapshot
}

/// Compact JSON of a value of the plan.
fn json(value: &impl serde::Serialize) -> String {
    serde_json::to_string(value).unwrap()
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
        // A failed compile holds an error or an internal error (a bug: naga
        // rejected a kernel), so ruling out the second leaves the first.
        assert!(!diagnostics.iter().any(|d| d.severity == Severity::Bug), "{name}: internal error {diagnostics:?}");
        // `check` reports the same diagnostics as `compile`.
        assert_eq!(mrsl::check(&source), diagnostics, "{name}: check and compile disagree");
        for d in &diagnostics {
            assert!(d.span().is_some(), "{name}: diagnostic without a source span: {d:?}");
        }
        let rendered = mrsl::render_all(&diagnostics, &name, &source);
        let reported = codes(&diagnostics);
        assert!(
            header_codes(&source, OK_HEADER).is_ok_and(|h| h.is_none()),
            "{name}: an err/ file lists warnings with the errors, in its `// {ERR_HEADER}:` header"
        );
        match header_codes(&source, ERR_HEADER).unwrap_or_else(|e| panic!("{name}: {e}")) {
            Some(expected) => assert_eq!(
                expected, reported,
                "{name}: the `// {ERR_HEADER}:` header does not list the codes of the diagnostics reported:\n{rendered}"
            ),
            None => panic!(
                "{name} has no header; add one as its first line, naming the code of every diagnostic \
                 reported, in order: `// {ERR_HEADER}: {}: what the case tests`\n{rendered}",
                reported.join(", ")
            ),
        }
        insta::assert_snapshot!(format!(
            "----- SOURCE\n{}\n----- DIAGNOSTICS\n{}",
            source.trim_end(),
            rendered.trim_end()
        ));
    });
}

/// The header parser itself: a header can only be read one way, and anything
/// else (prose without codes, a misplaced or repeated header) is an error.
#[test]
fn headers_name_codes_in_the_opening_comment() {
    let read = |source: &str| header_codes(source, ERR_HEADER);
    assert_eq!(read("// expect: E0100: unknown name\nin float x;"), Ok(Some(vec!["E0100".into()])));
    assert_eq!(
        read("// about the case\n// expect: E0205, E0205 W0001: a: b\n"),
        Ok(Some(vec!["E0205".into(), "E0205".into(), "W0001".into()]))
    );
    assert_eq!(read("// expect: E0100"), Ok(Some(vec!["E0100".into()])));
    assert_eq!(read("\u{FEFF}// expect: E0100"), Ok(Some(vec!["E0100".into()])), "after a byte order mark");
    assert_eq!(read("// just a comment\nin float x;"), Ok(None));
    assert_eq!(read("// expect-warning: W0001: unused"), Ok(None));
    assert!(read("// expect: unknown name `nromal`").is_err(), "prose without codes");
    assert!(read("// expect: E100: short code").is_err());
    assert!(read("// expect: : no codes").is_err());
    assert!(read("// expect: E0100\n// expect: E0201\n").is_err(), "two headers");
    assert!(read("in float x;\n// expect: E0100\n").is_err(), "header after the opening comment");
    assert_eq!(header_codes("// expect-warning: W0001: unused", OK_HEADER), Ok(Some(vec!["W0001".into()])));
}

fn source_of(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).expect("test data is readable")
}

fn file_name(path: &std::path::Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

fn codes(diagnostics: &[Diagnostic]) -> Vec<String> {
    diagnostics.iter().map(|d| d.code.to_string()).collect()
}

/// The codes of the `// KEY: CODE, CODE: what the case tests` header of
/// `source`: `None` without one. The header must sit in the comment lines that
/// open the file, once; the codes (`E0100`, `W0001`), separated by commas or
/// spaces, run up to the first `:` or the end of the line, and there is at least one.
fn header_codes(source: &str, key: &str) -> Result<Option<Vec<String>>, String> {
    let prefix = format!("// {key}:");
    // A byte order mark may open a file, as the compiler accepts it.
    let source = source.strip_prefix('\u{FEFF}').unwrap_or(source);
    let opening = source.lines().take_while(|line| line.trim_start().starts_with("//")).count();
    let mut found = None;
    for (index, line) in source.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix(&prefix) else { continue };
        let line_number = index + 1;
        if index >= opening {
            return Err(format!(
                "line {line_number}: the `// {key}:` header must be in the comments that open the file"
            ));
        }
        if found.is_some() {
            return Err(format!("line {line_number}: a second `// {key}:` header"));
        }
        let code_list = rest.split_once(':').map_or(rest, |(list, _)| list);
        let codes: Vec<String> = code_list.split([',', ' ']).filter(|c| !c.is_empty()).map(String::from).collect();
        if codes.is_empty() || !codes.iter().all(|c| is_code(c)) {
            return Err(format!(
                "line {line_number}: `{}` should name diagnostic codes first, as in \
                 `// {key}: E0100, E0201: what the case tests`",
                line.trim()
            ));
        }
        found = Some(codes);
    }
    Ok(found)
}

fn is_code(text: &str) -> bool {
    let bytes = text.as_bytes();
    bytes.len() == 5 && matches!(bytes[0], b'E' | b'W') && bytes[1..].iter().all(u8::is_ascii_digit)
}
