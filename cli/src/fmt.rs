//! `mrslc fmt`: programs rewritten in the canonical layout (`mrsl::format`),
//! in place, checked (`--check`, for CI), or from standard input to
//! standard output (`--stdin`), as Gleam's `gleam format` does.

use crate::{Color, read_source, report};
use anyhow::{Result, bail};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// What `mrslc fmt` was asked to do.
pub struct FmtArgs<'a> {
    pub files: &'a [PathBuf],
    pub check: bool,
    pub stdin: bool,
}

/// Runs `mrslc fmt`. Exit 0 when every file is (or now is) formatted; 1
/// with `--check` when some file would change; 2 when a file cannot be read
/// or does not parse (its diagnostics are printed; it is left as it was,
/// and the other files are still formatted).
pub fn fmt(color: Color, args: &FmtArgs<'_>) -> Result<ExitCode> {
    if args.stdin {
        return stdin(color);
    }
    if args.files.is_empty() {
        bail!("no programs to format: name .mrsl files or folders, or pass --stdin");
    }
    let mut files = vec![];
    for path in args.files {
        collect(path, &mut files)?;
    }
    let (mut failed, mut changed) = (0, 0);
    for file in &files {
        let name = file.display().to_string();
        let source = match read_source(file) {
            Ok(source) => source,
            Err(e) => {
                eprintln!("error: {e}");
                failed += 1;
                continue;
            }
        };
        let formatted = match mrsl::format(&source) {
            Ok(formatted) => formatted,
            Err(diagnostic) => {
                report(color, &[diagnostic], &name, &source);
                failed += 1;
                continue;
            }
        };
        if formatted == source {
            continue;
        }
        changed += 1;
        if args.check {
            println!("{name}: not formatted\n{}", first_difference(&source, &formatted));
        } else {
            std::fs::write(file, &formatted).map_err(|e| anyhow::anyhow!("cannot write {name}: {e}"))?;
        }
    }
    if failed > 0 {
        eprintln!("{failed} file{} could not be formatted", if failed == 1 { "" } else { "s" });
        return Ok(ExitCode::from(2));
    }
    if args.check && changed > 0 {
        eprintln!(
            "{changed} of {} file{} would be reformatted (run `mrslc fmt` on them)",
            files.len(),
            plural(files.len())
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// `--stdin`: the program on standard input, formatted to standard output.
fn stdin(color: Color) -> Result<ExitCode> {
    let mut bytes = vec![];
    std::io::stdin().read_to_end(&mut bytes).map_err(|e| anyhow::anyhow!("cannot read standard input: {e}"))?;
    let source = String::from_utf8(bytes)
        .map_err(|e| anyhow::anyhow!(crate::not_utf8("<stdin>", e.as_bytes(), e.utf8_error())))?;
    match mrsl::format(&source) {
        Ok(formatted) => {
            std::io::stdout().write_all(formatted.as_bytes())?;
            Ok(ExitCode::SUCCESS)
        }
        Err(diagnostic) => {
            report(color, &[diagnostic], "<stdin>", &source);
            Ok(ExitCode::from(2))
        }
    }
}

/// A file as named, or the `.mrsl` files under a folder, in name order.
fn collect(path: &Path, files: &mut Vec<PathBuf>) -> Result<()> {
    if !path.is_dir() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for entry in entries {
        if entry.is_dir() {
            collect(&entry, files)?;
        } else if entry.extension().is_some_and(|e| e == "mrsl") {
            files.push(entry);
        }
    }
    Ok(())
}

/// The first line that formatting changes, before and after, with its number.
fn first_difference(source: &str, formatted: &str) -> String {
    let (mut old, mut new) = (source.lines(), formatted.lines());
    let mut line = 1;
    loop {
        match (old.next(), new.next()) {
            (Some(a), Some(b)) if a == b => line += 1,
            (a, b) => {
                let show = |l: Option<&str>| l.map_or("(end of file)".to_string(), |l| format!("`{l}`"));
                return format!("  line {line}:\n  - {}\n  + {}", show(a), show(b));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::first_difference;

    #[test]
    fn the_first_difference_names_its_line() {
        assert_eq!(first_difference("a\nb  \nc\n", "a\nb\nc\n"), "  line 2:\n  - `b  `\n  + `b`");
        assert_eq!(first_difference("a\n", "a\nb\n"), "  line 2:\n  - (end of file)\n  + `b`");
        // Only a missing final line break.
        assert_eq!(first_difference("a", "a\n"), "  line 2:\n  - (end of file)\n  + (end of file)");
    }
}
