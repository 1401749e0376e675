//! Front end: source text to [`ast::Program`], with lexical and syntax errors as diagnostics.

pub mod ast;
pub mod lexer;
mod visit;

pub use visit::{visit_expr, visit_stmt_exprs};

use crate::diagnostic::{Diagnostic, Label};
use ast::{IdGen, Program, Span};
use lexer::{LexError, LexErrorAt, Lexer, Token};

#[allow(clippy::all, unused_parens, dead_code)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/mrsl.rs"));
}

/// Parses a whole program. Stops at the first syntax error: recovery would
/// only produce follow-on noise for a language this small.
pub fn parse(source: &str) -> Result<Program, Diagnostic> {
    let ids = IdGen::default();
    generated::ProgramParser::new().parse(&ids, Lexer::new(source)).map_err(|error| syntax_diagnostic(source, error))
}

type ParseError<'a> = lalrpop_util::ParseError<usize, Token<'a>, LexErrorAt>;

fn syntax_diagnostic(source: &str, error: ParseError<'_>) -> Diagnostic {
    use lalrpop_util::ParseError::*;
    match error {
        InvalidToken { location } => Diagnostic::error("E0001", "invalid token")
            .with_label(Label::primary(Span::new(location, location + 1), "not a token of mrsl")),
        UnrecognizedEof { location, expected } => Diagnostic::error("E0002", "unexpected end of file")
            .with_label(Label::primary(Span::new(location, location), "the program ends here"))
            .with_note(expected_note(&expected)),
        UnrecognizedToken { token: (start, token, end), expected } => {
            Diagnostic::error("E0002", format!("unexpected {token}"))
                .with_label(Label::primary(Span::new(start, end), "unexpected here"))
                .with_note(expected_note(&expected))
        }
        ExtraToken { token: (start, token, end) } => Diagnostic::error("E0002", format!("unexpected {token}"))
            .with_label(Label::primary(Span::new(start, end), "extra token")),
        User { error } => {
            let span = Span::new(error.start, error.end.max(error.start + 1).min(source.len().max(error.start)));
            let (message, label) = match error.error {
                LexError::InvalidToken => ("invalid character", "not a token of mrsl"),
                LexError::UnterminatedComment => ("unterminated block comment", "this `/*` has no matching `*/`"),
                LexError::BadNumber => ("number out of range", "does not fit in 32 bits"),
            };
            Diagnostic::error("E0001", message).with_label(Label::primary(span, label))
        }
    }
}

fn expected_note(expected: &[String]) -> String {
    // lalrpop lists terminals with their quotes; show a short, readable list.
    let mut names: Vec<String> = expected.iter().map(|e| e.trim_matches('"').to_string()).collect();
    names.sort();
    names.dedup();
    if names.len() > 8 {
        let shown = names[..8].iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ");
        format!("expected one of {shown}, ...")
    } else {
        let shown = names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ");
        format!("expected one of {shown}")
    }
}
