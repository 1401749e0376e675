//! Diagnostics as the playground's API returns them (JSON with their spans'
//! lines and columns), and the name programs are compiled under there: what
//! the compile and export endpoints share.

use mrsl::{Diagnostic, Severity};
use serde_json::{Value, json};

/// The name the playground's program goes by in kernel headers and diagnostics.
pub const PROGRAM_NAME: &str = "program.mrsl";

/// Diagnostics as JSON: spans in UTF-8 bytes, with the 1-based line and
/// column (in characters) of their start, and the text `mrslc check` prints.
pub fn diagnostics(found: &[Diagnostic], source: &str) -> Vec<Value> {
    found
        .iter()
        .map(|d| {
            let labels: Vec<Value> = d
                .labels
                .iter()
                .map(|l| {
                    let start = floor_char_boundary(source, l.span.start as usize);
                    let end = floor_char_boundary(source, (l.span.end as usize).max(start));
                    let (line, column) = line_column(source, start);
                    json!({ "start": start, "end": end, "line": line, "column": column,
                            "message": l.message, "primary": l.primary })
                })
                .collect();
            // An internal error (E9000) is an error to the page.
            let severity = if d.severity == Severity::Warning { "warning" } else { "error" };
            json!({ "severity": severity, "code": d.code, "message": d.message, "labels": labels,
                    "notes": d.notes, "rendered": d.render(PROGRAM_NAME, source) })
        })
        .collect()
}

/// `offset` clamped to the source and moved back to a character's start.
fn floor_char_boundary(source: &str, offset: usize) -> usize {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// The 1-based line and column (in characters) of byte `offset`.
fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_are_byte_offsets_with_lines_and_columns_in_characters() {
        let source = "// é\nfine out float4 color = float4(nope, 1.0);\n";
        let found = diagnostics(&mrsl::check(source), source);
        let label = &found[0]["labels"][0];
        let start = source.find("nope").unwrap();
        assert_eq!((label["start"].as_u64(), label["end"].as_u64()), (Some(start as u64), Some(start as u64 + 4)));
        assert_eq!((label["line"].as_u64(), label["column"].as_u64()), (Some(2), Some(32)));
        assert_eq!(found[0]["severity"], "error");
        assert!(found[0]["rendered"].as_str().unwrap().contains("program.mrsl:2:32"), "{}", found[0]["rendered"]);
        assert_eq!(line_column("aé\nb", 3), (1, 3));
        assert_eq!(floor_char_boundary("aé", 2), 1);
        assert_eq!(floor_char_boundary("a", 9), 1);
    }
}
