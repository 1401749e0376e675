//! Every kernel of every corpus `ok/` case, every example and the programs
//! at the compiler's limits is accepted by Tint, the WGSL front end of Dawn
//! (Chrome's WebGPU): the kernels are written with `CompiledProgram::write_dir`
//! and validated by `tests/tint/validate.mjs` through Dawn's Node binding
//! (npm `webgpu`, null backend: Tint's full parser and validator, no GPU).
//! naga validates every kernel inside the compiler already; Tint is stricter
//! in places (255 function parameters, a shallower parser), and a kernel
//! only naga accepts would be one Chrome refuses.
//!
//! Needs Node and `npm ci --prefix tests/tint` (which `.ci/run` does).
//! Without them the check is reported as skipped, and fails under `CI=true`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tint");
    if let Err(why) = ready(&here) {
        if std::env::var_os("CI").is_some_and(|v| v == "true") {
            eprintln!("tint: {why}; CI must run it (`npm ci --prefix tests/tint`)");
            std::process::exit(1);
        }
        println!("SKIPPING the Tint check: {why} (run `npm ci --prefix tests/tint` to enable it)");
        return;
    }
    let out = std::env::temp_dir().join(format!("mrsl-tint-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let programs = programs();
    for (stem, source, storage_channels) in &programs {
        let storage_channels = *storage_channels;
        let options = mrsl::Options { file_name: format!("{stem}.mrsl"), storage_channels, ..mrsl::Options::default() };
        let program = match mrsl::compile(source, &options) {
            Ok(program) => program,
            Err(d) => panic!("{stem} should compile:\n{}", mrsl::render_all(&d, stem, source)),
        };
        let dir = out.join(stem);
        std::fs::create_dir_all(&dir).expect("the temporary directory is writable");
        program.compiled.write_dir(&dir, stem).expect("the kernels are written");
    }
    println!("tint: validating the kernels of {} programs", programs.len());
    let status = Command::new("node")
        .arg(here.join("validate.mjs"))
        .arg(&out)
        .current_dir(&here)
        .status()
        .expect("node runs (checked above)");
    let _ = std::fs::remove_dir_all(&out);
    if !status.success() {
        eprintln!("tint: Tint refused kernels that naga accepted (above); the compiler must not emit them");
        std::process::exit(1);
    }
}

/// Node is on the path and the npm package is installed.
fn ready(here: &Path) -> Result<(), String> {
    match Command::new("node").arg("--version").output() {
        Ok(out) if out.status.success() => {}
        _ => return Err("Node.js is not installed".into()),
    }
    if !here.join("node_modules/webgpu/package.json").exists() {
        return Err("the npm package `webgpu` is not installed in tests/tint".into());
    }
    Ok(())
}

/// The programs checked, and whether with storage channels: every corpus
/// `ok/` case, every example, and wide programs at the compiler's limits;
/// and again with storage channels (`Options::storage_channels`) every
/// example and the corpus case of channels in engine formats, so that each
/// way the kernels load a channel is read through a storage binding too.
fn programs() -> Vec<(String, String, bool)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut programs = vec![];
    for dir in [root.join("compiler/tests/data/ok"), root.join("examples")] {
        let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("the programs are readable")
            .map(|e| e.expect("a directory entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "mrsl"))
            .collect();
        paths.sort();
        for path in paths {
            let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
            let source = std::fs::read_to_string(&path).expect("a program is readable");
            if dir.ends_with("examples") || stem.contains("engine_formats") {
                programs.push((format!("{stem}.storage_channels"), source.clone(), true));
            }
            programs.push((stem, source, false));
        }
    }
    programs.push(("wide_output".into(), wide_output(1000), false));
    programs
}

/// `n` effects, half coarse and half fine, each read directly by one output:
/// the widest program the size budget lets through, whose output's function
/// reads every effect.
fn wide_output(n: usize) -> String {
    let mut source = String::from("in float3 normal;\nin float2 uv;\n");
    for k in 0..n {
        let rate = if k % 2 == 0 { "coarse" } else { "fine" };
        source.push_str(&format!("{rate} effect float e{k} = normal.x * {k}.0 + uv.y;\n"));
    }
    source.push_str("fine out float total {\n    total = 0.0;\n");
    for k in 0..n {
        source.push_str(&format!("    total += e{k};\n"));
    }
    source.push_str("}\n");
    source
}
