//! The code writer: the WGSL text of one kernel, written line by line at an
//! indentation level, and fixed WGSL text written from `.wgsl` templates.
//!
//! # Templates
//!
//! Fixed WGSL lives in `templates/*.wgsl` next to this module (included with
//! `include_str!`), so that it reads as WGSL rather than as Rust strings. A
//! template is written verbatim: every line with the indentation it has in
//! the file (plus that of the level it is written at), blank lines included,
//! and nothing else. Two marks that generated WGSL never uses make it a template:
//!
//! - `{{NAME}}` inside a line is a *placeholder*, replaced by the value the
//!   caller gives for `NAME`: a number, a name or an expression, never text
//!   with a line break. Every placeholder must be given a value (the
//!   sections of one template may share one list of values); values are not
//!   scanned for placeholders again.
//! - A line holding only `{{#NAME}}` (indented or not) is a *hole*: [`cut`]
//!   splits the template there into sections, and the generator writes the
//!   lines that depend on the program (one per effect, per key, per flag
//!   word) between them. The name says what goes there. Sections may also
//!   be alternatives, of which the generator writes one.
//!
//! Either mistake (a missing value, a hole of another name) panics where the
//! template is written, so compiling the test corpus finds it.

use std::fmt::{Display, Write};

/// Indentation of one level.
const INDENT: &str = "    ";

/// The text of one kernel under construction.
#[derive(Default)]
pub(super) struct Code {
    text: String,
}

/// The values of a template's placeholders: `("NAME", &value)`.
pub(super) type Values<'v> = [(&'static str, &'v dyn Display)];

impl Code {
    /// Writes one line at `indent` levels.
    pub(super) fn line(&mut self, indent: usize, text: impl AsRef<str>) {
        for _ in 0..indent {
            self.text.push_str(INDENT);
        }
        self.text.push_str(text.as_ref());
        self.text.push('\n');
    }

    /// Writes a template (or a section of one) with its placeholders filled,
    /// `indent` levels deeper than it stands in its file.
    pub(super) fn template(&mut self, indent: usize, template: &str, values: &Values) {
        for line in fill(template, values).split_inclusive('\n') {
            if line != "\n" {
                for _ in 0..indent {
                    self.text.push_str(INDENT);
                }
            }
            self.text.push_str(line);
        }
    }

    /// Appends text written earlier (whole lines).
    pub(super) fn push_str(&mut self, text: &str) {
        self.text.push_str(text);
    }

    pub(super) fn into_string(self) -> String {
        self.text
    }
}

/// `template` with every `{{NAME}}` replaced by the value given for `NAME`.
pub(super) fn fill(template: &str, values: &Values) -> String {
    let mut out = String::with_capacity(template.len());
    let mut rest = template;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let end = start + rest[start..].find("}}").expect("a template placeholder is closed by `}}`");
        let name = &rest[start + 2..end];
        let (_, value) = values.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("no value for `{name}`"));
        write!(out, "{value}").expect("writing to a String cannot fail");
        rest = &rest[end + 2..];
    }
    out.push_str(rest);
    out
}

/// Cuts `template` at its holes, which must be `holes` in order, into the
/// `N = holes.len() + 1` sections around them (hole lines dropped).
pub(super) fn cut<'t, const N: usize>(template: &'t str, holes: &[&str]) -> [&'t str; N] {
    assert_eq!(holes.len() + 1, N, "a template with {} holes has {} sections", holes.len(), holes.len() + 1);
    let mut sections = [""; N];
    let mut start = 0;
    let mut found = 0;
    for line in template.split_inclusive('\n') {
        let offset = line.as_ptr() as usize - template.as_ptr() as usize;
        let Some(name) = line.trim().strip_prefix("{{#").and_then(|n| n.strip_suffix("}}")) else {
            continue;
        };
        assert!(found < holes.len() && holes[found] == name, "unexpected template hole `{name}`");
        sections[found] = &template[start..offset];
        start = offset + line.len();
        found += 1;
    }
    assert_eq!(found, holes.len(), "a template lacks holes");
    sections[found] = &template[start..];
    sections
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_fill_and_cut() {
        let [head, tail] = cut("fn f() {\n    {{#BODY}}\n    return {{X}}u;\n}\n", &["BODY"]);
        assert_eq!(head, "fn f() {\n");
        let mut code = Code::default();
        code.template(0, head, &[]);
        code.line(1, "let a = 1;");
        code.template(1, tail, &[("X", &7)]);
        assert_eq!(code.into_string(), "fn f() {\n    let a = 1;\n        return 7u;\n    }\n");
        assert_eq!(fill("a {{V}} b", &[("V", &"{{V}}")]), "a {{V}} b");
    }
}
