//! The one diagnostic type every stage reports through, and its rendering with codespan-reporting.

use crate::span::Span;
use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term;
use serde::Serialize;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Warning,
    Error,
    /// A failure of the compiler itself (e.g. naga rejected generated code).
    Bug,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Label {
    pub span: Span,
    pub message: String,
    pub primary: bool,
}

impl Label {
    pub fn primary(span: Span, message: impl Into<String>) -> Label {
        Label { span, message: message.into(), primary: true }
    }
    pub fn secondary(span: Span, message: impl Into<String>) -> Label {
        Label { span, message: message.into(), primary: false }
    }
}

/// A message about the program, with the places it concerns.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnostic {
    pub severity: Severity,
    /// A stable code, e.g. `E0201`; documented in docs/language.md.
    pub code: &'static str,
    pub message: String,
    pub labels: Vec<Label>,
    pub notes: Vec<String>,
}

impl Diagnostic {
    pub fn error(code: &'static str, message: impl Into<String>) -> Diagnostic {
        Diagnostic { severity: Severity::Error, code, message: message.into(), labels: vec![], notes: vec![] }
    }
    pub fn warning(code: &'static str, message: impl Into<String>) -> Diagnostic {
        Diagnostic { severity: Severity::Warning, ..Diagnostic::error(code, message) }
    }
    pub fn bug(message: impl Into<String>) -> Diagnostic {
        Diagnostic { severity: Severity::Bug, ..Diagnostic::error("E9000", message) }
    }
    pub fn with_label(mut self, label: Label) -> Diagnostic {
        self.labels.push(label);
        self
    }
    pub fn with_note(mut self, note: impl Into<String>) -> Diagnostic {
        self.notes.push(note.into());
        self
    }
    pub fn is_error(&self) -> bool {
        self.severity != Severity::Warning
    }
    /// The primary span, if any.
    pub fn span(&self) -> Option<Span> {
        self.labels.iter().find(|l| l.primary).map(|l| l.span)
    }

    fn to_codespan(&self) -> cs::Diagnostic<()> {
        let severity = match self.severity {
            Severity::Warning => cs::Severity::Warning,
            Severity::Error => cs::Severity::Error,
            Severity::Bug => cs::Severity::Bug,
        };
        let labels = self
            .labels
            .iter()
            .map(|l| {
                let style = if l.primary { cs::LabelStyle::Primary } else { cs::LabelStyle::Secondary };
                cs::Label::new(style, (), l.span.range()).with_message(&l.message)
            })
            .collect();
        cs::Diagnostic::new(severity)
            .with_code(self.code)
            .with_message(&self.message)
            .with_labels(labels)
            .with_notes(self.notes.clone())
    }

    /// Renders without colour, as tests and non-terminal output want it.
    pub fn render(&self, file_name: &str, source: &str) -> String {
        render_all(std::slice::from_ref(self), file_name, source)
    }
}

/// Renders several diagnostics, without colour, one after another.
pub fn render_all(diagnostics: &[Diagnostic], file_name: &str, source: &str) -> String {
    let (shown, skipped) = shown_source(source);
    let config = term::Config::default();
    let mut out = String::new();
    for diagnostic in diagnostics {
        let d = clamp_spans(diagnostic, shown, skipped);
        let file = SimpleFile::new(file_name, visible_at_labels(shown, &d));
        let one = term::emit_into_string(&config, &file, &d.to_codespan())
            .unwrap_or_else(|_| format!("{}[{}]: {}\n", severity_word(d.severity), d.code, d.message));
        out.push_str(&one);
    }
    out
}

/// Renders with ANSI colour to a writer (a terminal).
pub fn emit_colored(
    writer: &mut (impl term::WriteStyle + ?Sized),
    diagnostics: &[Diagnostic],
    file_name: &str,
    source: &str,
) -> std::io::Result<()> {
    let (shown, skipped) = shown_source(source);
    let config = term::Config::default();
    for diagnostic in diagnostics {
        let d = clamp_spans(diagnostic, shown, skipped);
        let file = SimpleFile::new(file_name, visible_at_labels(shown, &d));
        term::emit_to_write_style(writer, &config, &file, &d.to_codespan()).map_err(std::io::Error::other)?;
    }
    Ok(())
}

fn severity_word(severity: Severity) -> &'static str {
    match severity {
        Severity::Warning => "warning",
        Severity::Error => "error",
        Severity::Bug => "bug",
    }
}

/// The text diagnostics show, and how many bytes were cut from its start:
/// a byte order mark is not shown, so that it moves no column on line 1.
fn shown_source(source: &str) -> (&str, usize) {
    match source.strip_prefix('\u{FEFF}') {
        Some(rest) => (rest, source.len() - rest.len()),
        None => (source, 0),
    }
}

/// The source with every character a label starts at and that takes no
/// column on a terminal (NUL, a zero-width space, a combining mark) replaced
/// by a visible stand-in of the same length in bytes, so that the label's
/// caret shows. Columns count characters, so they do not move.
fn visible_at_labels<'s>(source: &'s str, diagnostic: &Diagnostic) -> std::borrow::Cow<'s, str> {
    let mut text = std::borrow::Cow::Borrowed(source);
    for label in &diagnostic.labels {
        let at = label.span.start as usize;
        let Some(c) = source[at..].chars().next() else { continue };
        let combining =
            !c.is_ascii() && unicode_ident::is_xid_continue(c) && !unicode_ident::is_xid_start(c) && !c.is_numeric();
        let invisible = (c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
            || combining
            || matches!(c, '\u{AD}' | '\u{200B}'..='\u{200F}' | '\u{2028}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{FEFF}');
        let stand_in = match c.len_utf8() {
            1 => " ",
            2 => "\u{B7}",
            3 => "\u{25CC}",
            _ => continue,
        };
        if invisible {
            text.to_mut().replace_range(at..at + c.len_utf8(), stand_in);
        }
    }
    text
}

/// Moves every span into the shown source (spans are offsets into the whole
/// source, `skipped` bytes longer) and keeps it inside and on char
/// boundaries, so rendering never fails.
fn clamp_spans(diagnostic: &Diagnostic, source: &str, skipped: usize) -> Diagnostic {
    let floor = |mut i: usize| {
        i = i.saturating_sub(skipped).min(source.len());
        while !source.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let mut d = diagnostic.clone();
    for label in &mut d.labels {
        let end = floor(label.span.end as usize);
        let start = floor(label.span.start as usize).min(end);
        label.span = Span::new(start, end);
    }
    d
}
