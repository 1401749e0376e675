//! Front end: source text to [`ast::Program`], with lexical and syntax errors as diagnostics.

pub mod ast;
pub mod format;
pub mod lexer;
mod visit;

pub use visit::{visit_expr, visit_stmt_exprs};

use crate::diagnostic::{Diagnostic, Label};
use crate::foreign;
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

/// Parses one expression (a derivative operand's text), or `None`.
pub fn parse_expression(source: &str) -> Option<ast::Expr> {
    generated::ExprParser::new().parse(&IdGen::default(), Lexer::new(source)).ok()
}

type ParseError<'a> = lalrpop_util::ParseError<usize, Token<'a>, LexErrorAt>;

fn syntax_diagnostic(source: &str, error: ParseError<'_>) -> Diagnostic {
    use lalrpop_util::ParseError::*;
    match error {
        InvalidToken { location } => Diagnostic::error("E0001", "invalid token")
            .with_label(Label::primary(Span::new(location, location + 1), "not a token of mrsl")),
        UnrecognizedEof { location, expected } => {
            foreign_construct(source, location, None).unwrap_or_else(|| unexpected(source, location, None, &expected))
        }
        UnrecognizedToken { token: (start, token, end), expected } => {
            let found = Some((start, token, end));
            foreign_construct(source, start, found.as_ref())
                .unwrap_or_else(|| unexpected(source, start, found, &expected))
        }
        ExtraToken { token: (start, token, end) } => Diagnostic::error("E0002", format!("unexpected {token}"))
            .with_label(Label::primary(Span::new(start, end), "extra token")),
        User { error } => lexical_diagnostic(source, error),
    }
}

/// Where the parser stopped on a construct of another shading language
/// (`while (c) {`, `discard;`, `struct S {`, `static const`, `vec3<f32>`, a
/// local array `float w[3]`): E0003 with what mrsl writes instead, in place
/// of the list of expected tokens. The foreign word is looked for where such
/// constructs start: the statement or declaration, the parameter, the token
/// the parser stopped at and the one before it. A word used as a name
/// (`loop = 2.0;`, `case.x`) is not taken for the construct.
fn foreign_construct(source: &str, location: usize, found: Option<&(usize, Token<'_>, usize)>) -> Option<Diagnostic> {
    let mut tokens = Before::scan(source, location).tokens;
    let stopped_at = tokens.len();
    tokens.extend(found.cloned());
    if let (Some((start, Token::LBracket, end)), [.., (_, Token::Ident(_), _), (_, Token::Ident(_), _)]) =
        (found, &tokens[..stopped_at])
    {
        return Some(foreign::array_diagnostic(Span::new(*start, *end)));
    }
    let starts_after = |delimiters: &[Token<'_>]| {
        tokens[..stopped_at].iter().rposition(|(_, t, _)| delimiters.contains(t)).map_or(0, |i| i + 1)
    };
    let statement = starts_after(&[Token::Semi, Token::LBrace, Token::RBrace]);
    let parameter = starts_after(&[Token::LParen, Token::Comma]).max(statement);
    let mut candidates = vec![statement, parameter, stopped_at.saturating_sub(1), stopped_at];
    candidates.dedup();
    candidates.into_iter().filter(|&i| i < tokens.len()).find_map(|i| {
        let (start, Token::Ident(word), end) = tokens[i] else { return None };
        let next = tokens.get(i + 1).map(|t| &t.1);
        let used_as_name = matches!(
            next,
            Some(
                Token::Assign
                    | Token::PlusAssign
                    | Token::MinusAssign
                    | Token::StarAssign
                    | Token::SlashAssign
                    | Token::Dot
                    | Token::LBracket
                    | Token::PlusPlus
                    | Token::MinusMinus
            )
        );
        if used_as_name {
            return None;
        }
        let span = Span::new(start, end);
        foreign::keyword_diagnostic(word, span).or_else(|| {
            // A type of another language with parameters: `vec3<f32>`, `texture_2d<f32>`.
            let help = foreign::help(word).filter(|_| next == Some(&Token::Lt))?;
            Some(
                Diagnostic::error("E0003", format!("`{word}<...>` is not an mrsl type"))
                    .with_label(Label::primary(span, "a generic type"))
                    .with_note(help),
            )
        })
    })
}

/// The tokens that end a construct, in the order they are preferred when
/// several are expected: the one a diagnostic proposes to add.
const CLOSERS: [Token<'static>; 4] = [Token::Semi, Token::RParen, Token::RBracket, Token::RBrace];

/// An unexpected token (`found`), or the end of the file (`None`) at
/// `location`. When a closing token is what is missing, this is reported as
/// rustc does, "expected `;`" right after the previous token: the closer is
/// expected, the parser takes the unexpected token after it, and the break is
/// clear (the unexpected token is on a later line or is itself a delimiter,
/// or the file ends).
fn unexpected(
    source: &str,
    location: usize,
    found: Option<(usize, Token<'_>, usize)>,
    expected: &[String],
) -> Diagnostic {
    let before = Before::scan(source, location);
    // lalrpop's list can miss tokens (after an identifier it may name only
    // `(`), so the parser is asked about every kind of token.
    let mut names: Vec<&str> = expected.iter().map(|e| e.trim_matches('"')).collect();
    for kind in &Token::KINDS {
        if !names.contains(&kind.kind_name()) && accepts(&before.tokens, std::slice::from_ref(kind)) {
            names.push(kind.kind_name());
        }
    }
    let found_text = match &found {
        Some((_, token, _)) => token.to_string(),
        None => "end of file".to_string(),
    };
    let prev_end = before.tokens.last().map(|t| t.2);
    let clear_break = match &found {
        None => true,
        Some((start, token, _)) => {
            prev_end.is_some_and(|end| source[end..*start].contains('\n'))
                || matches!(token, Token::Semi | Token::RParen | Token::RBracket | Token::RBrace | Token::LBrace)
        }
    };
    let closer = CLOSERS.iter().find(|c| {
        names.contains(&c.kind_name())
            && match &found {
                Some((_, token, _)) => closes_before(&before.tokens, c, token),
                None => true,
            }
    });
    if let (Some(closer), Some(end), true) = (closer, prev_end, clear_break) {
        let closer = closer.kind_name();
        let mut d = Diagnostic::error("E0002", format!("expected `{closer}`, found {found_text}"))
            .with_label(Label::primary(Span::new(end, end), format!("add `{closer}` here")));
        if let Some((start, _, token_end)) = found.as_ref().filter(|f| f.0 > end) {
            d = d.with_label(Label::secondary(Span::new(*start, *token_end), "unexpected token"));
        }
        let opener = match closer {
            ")" => Some('('),
            "]" => Some('['),
            "}" => Some('{'),
            _ => None,
        };
        if let Some(&(c, at)) = opener.and_then(|o| before.open.iter().rev().find(|(c, _)| *c == o)) {
            d = d.with_label(Label::secondary(Span::new(at, at + 1), format!("unclosed `{c}`")));
        }
        return d.with_note(expected_note(&names));
    }
    let (span, label) = match found {
        Some((start, _, end)) => (Span::new(start, end), "unexpected here"),
        None => (Span::new(location, location), "the program ends here"),
    };
    let message = if found.is_some() { format!("unexpected {found_text}") } else { "unexpected end of file".into() };
    Diagnostic::error("E0002", message).with_label(Label::primary(span, label)).with_note(expected_note(&names))
}

/// Whether adding `closer`, and then perhaps a few more closers, lets the
/// parser go on to `found`: then a missing `closer` is the first thing to fix.
fn closes_before<'a>(prefix: &[(usize, Token<'a>, usize)], closer: &Token<'static>, found: &Token<'a>) -> bool {
    let mut added = vec![closer.clone()];
    for _ in 0..CLOSERS.len() {
        let mut next = added.clone();
        next.push(found.clone());
        if accepts(prefix, &next) {
            return true;
        }
        let more = CLOSERS.iter().find(|c| {
            let mut next = added.clone();
            next.push((*c).clone());
            accepts(prefix, &next)
        });
        match more {
            Some(c) => added.push(c.clone()),
            None => return false,
        }
    }
    false
}

/// Whether the parser, given `prefix` and then `next`, takes every token of
/// `next` (it asks for the token after them).
fn accepts<'a>(prefix: &[(usize, Token<'a>, usize)], next: &[Token<'a>]) -> bool {
    const PROBE: usize = usize::MAX;
    let at = prefix.last().map_or(0, |t| t.2);
    let stream = prefix
        .iter()
        .cloned()
        .map(Ok)
        .chain(next.iter().map(|t| Ok((at, t.clone(), at))))
        .chain(std::iter::once(Err(LexErrorAt { error: LexError::InvalidToken, start: PROBE, end: PROBE })));
    let ids = IdGen::default();
    matches!(
        generated::ProgramParser::new().parse(&ids, stream),
        Err(lalrpop_util::ParseError::User { error }) if error.start == PROBE
    )
}

/// What precedes an error location: the tokens before it and the delimiters
/// still open there (with their offsets).
struct Before<'a> {
    tokens: Vec<(usize, Token<'a>, usize)>,
    open: Vec<(char, usize)>,
}

impl<'a> Before<'a> {
    fn scan(source: &'a str, location: usize) -> Before<'a> {
        let mut before = Before { tokens: vec![], open: vec![] };
        // The parser read these tokens without a lexical error, so lexing
        // again up to `location` sees the same ones.
        for (start, token, end) in Lexer::new(source).map_while(Result::ok) {
            if start >= location || end > location {
                break;
            }
            match token {
                Token::LParen => before.open.push(('(', start)),
                Token::LBracket => before.open.push(('[', start)),
                Token::LBrace => before.open.push(('{', start)),
                Token::RParen | Token::RBracket | Token::RBrace => {
                    before.open.pop();
                }
                _ => {}
            }
            before.tokens.push((start, token, end));
        }
        before
    }
}

/// "expected one of ...": every expected token, never cut off, grouped:
/// delimiters first, then other punctuation, binary operators in precedence
/// order, keywords, and identifiers and literals.
fn expected_note(names: &[&str]) -> String {
    const ORDER: &[&str] = &[
        ";", ")", "]", "}", ",", ":", "=", "+=", "-=", "*=", "/=", "++", "--", ".", "[", "(", "{", "?", "@", "!", "~",
    ];
    const BINARY: &[&str] =
        &["||", "&&", "|", "^", "&", "==", "!=", "<", ">", "<=", ">=", "<<", ">>", "+", "-", "*", "/", "%"];
    const KEYWORDS: &[&str] = &[
        "in", "uniform", "const", "coarse", "fine", "effect", "out", "refine", "if", "else", "for", "break",
        "continue", "return", "true", "false",
    ];
    const NUMBERS: &[&str] = &["int literal", "uint literal", "sint literal", "float literal"];
    let has = |n: &str| names.contains(&n);
    let all_binary = BINARY.iter().all(|b| has(b));
    let mut items: Vec<String> = vec![];
    let quoted = |n: &str| format!("`{n}`");
    for n in ORDER {
        if has(n) && !(all_binary && BINARY.contains(n)) {
            items.push(quoted(n));
        }
    }
    if !all_binary {
        items.extend(BINARY.iter().filter(|b| has(b) && !ORDER.contains(b)).map(|b| quoted(b)));
    }
    items.extend(KEYWORDS.iter().filter(|k| has(k)).map(|k| quoted(k)));
    if has("identifier") {
        items.push("an identifier".into());
    }
    if NUMBERS.iter().all(|n| has(n)) {
        items.push("a number".into());
    } else {
        items.extend(NUMBERS.iter().filter(|n| has(n)).map(|n| format!("an {n}")));
    }
    // Anything not classified above (a token added to the grammar later).
    let known = |n: &&str| {
        ORDER.contains(n) || BINARY.contains(n) || KEYWORDS.contains(n) || NUMBERS.contains(n) || *n == "identifier"
    };
    items.extend(names.iter().filter(|n| !known(n)).map(|n| quoted(n)));
    if all_binary {
        items.push(format!("a binary operator ({})", BINARY.iter().map(|b| quoted(b)).collect::<Vec<_>>().join(", ")));
    }
    match items.as_slice() {
        [] => "expected nothing more".into(),
        [one] => format!("expected {one}"),
        [a, b] => format!("expected {a} or {b}"),
        [rest @ .., last] => format!("expected one of {}, or {last}", rest.join(", ")),
    }
}

/// A lexical error: the character, comment or number that is not a token.
fn lexical_diagnostic(source: &str, error: LexErrorAt) -> Diagnostic {
    let end = error.end.max(error.start + 1).min(source.len().max(error.start));
    match error.error {
        LexError::InvalidToken if source[error.start..].starts_with('#') => directive(source, error.start),
        LexError::InvalidToken => invalid_character(source, error.start, "not a token of mrsl"),
        LexError::BadIdentifierChar(offset) => {
            let at = error.start + offset;
            let c = source[at..].chars().next().unwrap_or(lexer::BOM);
            let label = if offset > 0 {
                "not allowed in an identifier"
            } else if unicode_ident::is_xid_continue(c) {
                "an identifier cannot start with this character"
            } else {
                "not a token of mrsl"
            };
            invalid_character(source, at, label)
        }
        LexError::UnterminatedComment => Diagnostic::error("E0001", "unterminated block comment")
            .with_label(Label::primary(Span::new(error.start, end), "this `/*` has no matching `*/`")),
        LexError::BadNumber => Diagnostic::error("E0001", "number out of range")
            .with_label(Label::primary(Span::new(error.start, end), "does not fit in 32 bits")),
    }
}

/// A preprocessor line (`#include "brdf.hlsl"`, `#define PI 3.14`): E0003.
fn directive(source: &str, at: usize) -> Diagnostic {
    let rest = &source[at + 1..];
    let len = 1 + rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
    let span = Span::new(at, at + len);
    foreign::keyword_diagnostic(&source[at..at + len], span).unwrap_or_else(|| {
        Diagnostic::error("E0003", format!("`{}` is not mrsl", &source[at..at + len]))
            .with_label(Label::primary(span, "a preprocessor directive"))
            .with_note("help: mrsl has no preprocessor: delete the line")
    })
}

/// "invalid character `$` (U+0024)", or for a character that does not show,
/// its code point and name: "invalid character U+0000 (NUL)".
fn invalid_character(source: &str, at: usize, label: &str) -> Diagnostic {
    let Some(c) = source.get(at..).and_then(|rest| rest.chars().next()) else {
        return Diagnostic::error("E0001", "invalid character")
            .with_label(Label::primary(Span::new(at, at + 1), label.to_string()));
    };
    let code = format!("U+{:04X}", c as u32);
    let name = invisible_name(c);
    let message = match name {
        Some(name) => format!("invalid character {code} ({name})"),
        None if c.is_control() || c.is_whitespace() => format!("invalid character {code}"),
        None => format!("invalid character `{c}` ({code})"),
    };
    let (label, note) = if c.is_whitespace() {
        ("not a space mrsl accepts", Some("tokens are separated by ASCII spaces, tabs, line breaks and form feeds"))
    } else if name.is_some() {
        (label, Some("this character does not show in most editors: delete it"))
    } else if !c.is_ascii() {
        (
            label,
            Some(
                "identifiers start with a letter or `_` and go on with letters, digits or `_`, as Unicode XID \
                 defines them (the rule of WGSL); other characters may appear only in comments",
            ),
        )
    } else {
        (label, None)
    };
    let d = Diagnostic::error("E0001", message)
        .with_label(Label::primary(Span::new(at, at + c.len_utf8()), label.to_string()));
    match note {
        Some(note) => d.with_note(note),
        None => d,
    }
}

/// Names of characters that cannot be seen in a rendered line.
fn invisible_name(c: char) -> Option<&'static str> {
    Some(match c {
        '\0' => "NUL",
        '\u{0B}' => "vertical tab",
        '\u{7F}' => "delete",
        '\u{A0}' => "no-break space",
        '\u{AD}' => "soft hyphen",
        '\u{200B}' => "zero-width space",
        '\u{200C}' => "zero-width non-joiner",
        '\u{200D}' => "zero-width joiner",
        '\u{2028}' => "line separator",
        '\u{2029}' => "paragraph separator",
        '\u{2060}' => "word joiner",
        lexer::BOM => "byte order mark",
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    /// The plain rendering of every diagnostic of `source`.
    fn rendered(source: &str) -> String {
        crate::render_all(&crate::check(source), "t.mrsl", source)
    }

    /// The column (in characters, from 0) of the first `^` in `text`.
    fn caret_column(text: &str) -> usize {
        let line = text.lines().find(|l| l.contains('^')).expect("a caret");
        line.chars().position(|c| c == '^').unwrap()
    }

    /// The column (in characters, from 0) of `word` in `line`.
    fn column_of(line: &str, word: &str) -> usize {
        line[..line.find(word).unwrap()].chars().count()
    }

    #[test]
    fn a_nul_byte_is_named_and_its_caret_shows() {
        let source = "in float3 normal;\nfine out float4 color = float4(normal\0, 1.0);\n";
        let text = rendered(source);
        assert!(text.starts_with("error[E0001]: invalid character U+0000 (NUL)\n"), "{text}");
        assert!(text.contains("t.mrsl:2:38"), "{text}");
        // The NUL is shown as a space, with the caret under it.
        let line = text.lines().find(|l| l.contains("float4(normal")).unwrap();
        assert!(!line.contains('\0'), "{text}");
        assert_eq!(caret_column(&text), column_of(line, "normal ,") + "normal".len(), "{text}");
    }

    #[test]
    fn invisible_and_non_xid_characters_are_named_with_their_code_points() {
        let first = |source: &str| rendered(source).lines().next().unwrap().to_string();
        let program = |c: &str| format!("in float3 normal;\nfine out float4 color = float4(normal{c}, 1.0);\n");
        assert_eq!(first(&program("$")), "error[E0001]: invalid character `$` (U+0024)");
        assert_eq!(first(&program("\u{200B}")), "error[E0001]: invalid character U+200B (zero-width space)");
        assert_eq!(first(&program("\u{FEFF}")), "error[E0001]: invalid character U+FEFF (byte order mark)");
        assert_eq!(first(&program("\u{A0}")), "error[E0001]: invalid character U+00A0 (no-break space)");
        assert_eq!(first(&program("°")), "error[E0001]: invalid character `°` (U+00B0)");
        assert_eq!(first(&program("\u{1}")), "error[E0001]: invalid character U+0001");
    }

    #[test]
    fn a_byte_order_mark_is_accepted_and_moves_no_column() {
        let source = "\u{FEFF}in float3 normal; fine out float4 color = float4(nromal, 1.0);\n";
        let text = rendered(source);
        assert!(text.starts_with("error[E0100]: unknown name `nromal`"), "{text}");
        assert!(text.contains("t.mrsl:1:50"), "{text}");
        let line = text.lines().find(|l| l.contains("float4(nromal")).unwrap();
        assert!(!line.contains('\u{FEFF}'), "{text}");
        assert_eq!(caret_column(&text), column_of(line, "nromal"), "{text}");
        assert!(crate::check("\u{FEFF}in float3 normal;\nfine out float4 color = float4(normal, 1.0);").is_empty());
    }

    #[test]
    fn a_missing_closer_is_expected_after_the_previous_token_with_every_expected_token_listed() {
        let source = "in float3 normal;\nfine out float4 color {\n    float e = normal.x\n    color = float4(e);\n}\n";
        let d = &crate::check(source)[0];
        assert_eq!(d.message, "expected `;`, found identifier `color`");
        let end = source.find(".x").unwrap() + 2;
        assert_eq!(d.span(), Some(super::Span::new(end, end)));
        assert_eq!(d.labels[0].message, "add `;` here");
        assert_eq!(
            d.notes,
            ["expected one of `;`, `.`, `[`, `?`, or a binary operator (`||`, `&&`, `|`, `^`, `&`, `==`, `!=`, `<`, \
              `>`, `<=`, `>=`, `<<`, `>>`, `+`, `-`, `*`, `/`, `%`)"]
        );
        // On one line, a token that is not a delimiter is only unexpected.
        let d = &crate::check("in float3 normal;\nfine out float4 color = float4(normal b, 1.0);\n")[0];
        assert_eq!(d.message, "unexpected identifier `b`");
        assert!(!d.notes[0].contains("..."));
    }
}
