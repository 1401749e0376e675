//! The web runtime's and the playground's tests (`npm test` in web/: Dawn
//! over SwiftShader through npm `webgpu`, and headless Chromium), run by
//! `cargo test` with the mrslc it built, so that the README's one test
//! command runs them too.
//!
//! Needs Node and `npm ci --prefix web` (which `.ci/run` does). Without them
//! the suite is reported as skipped, and fails under `CI=true`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let web = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../web");
    if let Err(why) = ready(&web) {
        if std::env::var_os("CI").is_some_and(|v| v == "true") {
            eprintln!("web: {why}; CI must run it (`npm ci --prefix web`)");
            return ExitCode::FAILURE;
        }
        println!("SKIPPING the web runtime's tests: {why} (run `npm ci --prefix web` to enable them)");
        return ExitCode::SUCCESS;
    }
    let status = Command::new("npm")
        .args(["test", "--silent"])
        .current_dir(&web)
        .env("MRSLC", env!("CARGO_BIN_EXE_mrslc"))
        .status()
        .expect("npm runs (checked above)");
    if status.success() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}

/// Node and npm are on the path and web/'s packages are installed.
fn ready(web: &Path) -> Result<(), String> {
    for tool in ["node", "npm"] {
        match Command::new(tool).arg("--version").output() {
            Ok(out) if out.status.success() => {}
            _ => return Err(format!("`{tool}` is not installed")),
        }
    }
    if !web.join("node_modules/typescript/package.json").exists() {
        return Err("web/'s npm packages are not installed".into());
    }
    Ok(())
}
