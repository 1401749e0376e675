//! `mrslc fmt` as a user runs it: files rewritten in place (only those that
//! change), `--check` (exit 1, nothing written), `--stdin`, and a file that
//! does not parse (its diagnostic, exit 2, left as it was). No GPU needed.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

const MESSY: &str = "in float3 normal;\nfine out float4 color=float4(normal,1.0);   // out\n";
const FORMATTED: &str = "in float3 normal;\nfine out float4 color = float4(normal, 1.0);  // out\n";
const BROKEN: &str = "in float3 normal\nfine out float4 color = float4(normal, 1.0);\n";

/// A fresh directory for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrslc-fmt-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn mrslc(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mrslc"))
        .args(args)
        .arg("--color=never")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mrslc runs");
    let input = stdin.unwrap_or("").to_string();
    let mut pipe = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || pipe.write_all(input.as_bytes()));
    let output = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    output
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn formats_files_in_place_and_folders_of_them() {
    let dir = scratch("in-place");
    let (messy, tidy) = (dir.join("messy.mrsl"), dir.join("sub/tidy.mrsl"));
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(&messy, MESSY).unwrap();
    std::fs::write(&tidy, FORMATTED).unwrap();
    std::fs::write(dir.join("notes.txt"), MESSY).unwrap();
    let modified = std::fs::metadata(&tidy).unwrap().modified().unwrap();
    let run = mrslc(&["fmt", dir.to_str().unwrap()], None);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), FORMATTED);
    assert_eq!(std::fs::metadata(&tidy).unwrap().modified().unwrap(), modified, "a formatted file is not written");
    assert_eq!(std::fs::read_to_string(dir.join("notes.txt")).unwrap(), MESSY, "only .mrsl files are taken");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_lists_what_would_change_and_writes_nothing() {
    let dir = scratch("check");
    let (messy, tidy) = (dir.join("messy.mrsl"), dir.join("tidy.mrsl"));
    std::fs::write(&messy, MESSY).unwrap();
    std::fs::write(&tidy, FORMATTED).unwrap();
    let run = mrslc(&["fmt", "--check", messy.to_str().unwrap(), tidy.to_str().unwrap()], None);
    assert_eq!(run.status.code(), Some(1), "{}", text(&run.stderr));
    let out = text(&run.stdout);
    assert!(out.contains("messy.mrsl: not formatted"), "{out}");
    assert!(out.contains("line 2:\n  - `fine out float4 color=float4(normal,1.0);   // out`"), "{out}");
    assert!(!out.contains("tidy.mrsl"), "{out}");
    assert!(text(&run.stderr).contains("1 of 2 files would be reformatted"), "{}", text(&run.stderr));
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), MESSY, "--check writes nothing");
    let clean = mrslc(&["fmt", "--check", tidy.to_str().unwrap()], None);
    assert_eq!(clean.status.code(), Some(0), "{}", text(&clean.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stdin_is_formatted_to_stdout() {
    let run = mrslc(&["fmt", "--stdin"], Some(MESSY));
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(text(&run.stdout), FORMATTED);
    let broken = mrslc(&["fmt", "--stdin"], Some(BROKEN));
    assert_eq!(broken.status.code(), Some(2));
    assert!(broken.stdout.is_empty(), "nothing is written for a program with an error");
    assert!(text(&broken.stderr).contains("<stdin>:1:17"), "{}", text(&broken.stderr));
}

#[test]
fn a_file_that_does_not_parse_is_reported_and_left_as_it_was() {
    let dir = scratch("broken");
    let (broken, messy, missing) = (dir.join("broken.mrsl"), dir.join("messy.mrsl"), dir.join("missing.mrsl"));
    std::fs::write(&broken, BROKEN).unwrap();
    std::fs::write(&messy, MESSY).unwrap();
    let run = mrslc(&["fmt", broken.to_str().unwrap(), messy.to_str().unwrap(), missing.to_str().unwrap()], None);
    assert_eq!(run.status.code(), Some(2));
    let err = text(&run.stderr);
    assert!(err.contains("error[E0002]: expected `;`, found `fine`"), "{err}");
    assert!(err.contains("broken.mrsl:1:17"), "{err}");
    assert!(err.contains("cannot read") && err.contains("missing.mrsl"), "{err}");
    assert!(err.contains("2 files could not be formatted"), "{err}");
    assert_eq!(std::fs::read_to_string(&broken).unwrap(), BROKEN);
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), FORMATTED, "the other files are formatted");
    let none = mrslc(&["fmt"], None);
    assert_eq!(none.status.code(), Some(2));
    assert!(text(&none.stderr).contains("no programs to format"), "{}", text(&none.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}
