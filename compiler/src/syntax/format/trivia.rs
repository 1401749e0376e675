//! What the parser drops and the formatter keeps: the comments, the blank
//! lines and the author's parentheses, read from the source around the
//! tokens of a program that parsed.
//!
//! The lexer skips comments (the parser never sees them), so they are
//! recovered here rather than by a lexer mode: every byte between two tokens
//! is whitespace or a comment, and a scan of those gaps finds each comment
//! exactly. The lexer's token list stays as it is.

use crate::syntax::lexer::{Lexer, Token};
use std::collections::HashMap;

/// A comment as written: its text (`// ...` or `/* ... */`) and where it stands.
#[derive(Debug, Clone)]
pub struct Comment<'a> {
    pub start: usize,
    pub text: &'a str,
    /// A `//` comment, which ends its line.
    pub line: bool,
    /// Only whitespace follows it on its line (always so for `//`).
    pub ends_line: bool,
    /// A blank line separates it from what precedes it.
    pub blank_before: bool,
}

/// The kinds of token the layout asks about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Semi,
    Comma,
    Other,
}

/// The trivia of one source.
pub struct Trivia<'a> {
    source: &'a str,
    /// Every token, as `(start, kind, end)`, in order.
    tokens: Vec<(usize, Kind, usize)>,
    pub comments: Vec<Comment<'a>>,
    /// The spans `(start, end)` of the expressions written inside grouping
    /// parentheses (not those of a call, an `if`, a `for` or `coarse(N)`),
    /// each with where its `(`s start, the outermost first.
    parenthesised: HashMap<(usize, usize), Vec<usize>>,
    /// Each grouping pair, from its `(` to after its `)`, with the span of
    /// the expression inside: `((x))` is two pairs around `x`.
    pairs: HashMap<(usize, usize), (usize, usize)>,
}

impl<'a> Trivia<'a> {
    /// Scans a source that parsed (so that it lexes without error).
    pub fn scan(source: &'a str) -> Trivia<'a> {
        let mut trivia =
            Trivia { source, tokens: vec![], comments: vec![], parenthesised: HashMap::new(), pairs: HashMap::new() };
        let mut gap_start = if source.starts_with(crate::syntax::lexer::BOM) { 3 } else { 0 };
        // The open parentheses: their start, and whether they group.
        let mut open: Vec<(usize, bool)> = vec![];
        let mut previous: Option<Token<'a>> = None;
        for (start, token, end) in Lexer::new(source).map_while(Result::ok) {
            trivia.comments_in(gap_start, start);
            gap_start = end;
            let kind = match token {
                Token::Semi => Kind::Semi,
                Token::Comma => Kind::Comma,
                Token::LParen => {
                    let call = matches!(previous, Some(Token::Ident(_) | Token::If | Token::For | Token::Coarse));
                    open.push((start, !call));
                    Kind::Other
                }
                Token::RParen => {
                    if let Some((open_start, true)) = open.pop() {
                        trivia.group(open_start, start);
                    }
                    Kind::Other
                }
                _ => Kind::Other,
            };
            trivia.tokens.push((start, kind, end));
            previous = Some(token);
        }
        trivia.comments_in(gap_start, source.len());
        trivia
    }

    /// Records the pair of a grouping `(` (at `open`) and its `)` (at
    /// `close`) around the expression from the first token inside to the
    /// last, or around the expression of the pair right inside it.
    fn group(&mut self, open: usize, close: usize) {
        let first = self.tokens.partition_point(|t| t.0 <= open);
        if let (Some(first), Some(last)) = (self.tokens.get(first), self.tokens.last()) {
            let inside = (first.0, last.2);
            let expr = self.pairs.get(&inside).copied().unwrap_or(inside);
            self.parenthesised.entry(expr).or_default().insert(0, open);
            self.pairs.insert((open, close + 1), expr);
        }
    }

    /// The comments in `source[from..to]`, which holds no token.
    fn comments_in(&mut self, from: usize, to: usize) {
        let gap = &self.source[from..to];
        let mut at = 0;
        while let Some(offset) = gap[at..].find('/') {
            let start = at + offset;
            let rest = &gap[start..];
            let len = if rest.starts_with("//") {
                rest.find('\n').unwrap_or(rest.len())
            } else if let Some(body) = rest.strip_prefix("/*") {
                body.find("*/").map_or(rest.len(), |e| e + 4)
            } else {
                // Not possible between tokens; skip the byte rather than loop.
                at = start + 1;
                continue;
            };
            let (abs, text) = (from + start, &rest[..len]);
            let text = text.trim_end_matches(['\r', ' ', '\t', '\u{0C}']);
            let line_end = self.source[abs..].find('\n').map_or(self.source.len(), |n| abs + n);
            self.comments.push(Comment {
                start: abs,
                text,
                line: text.starts_with("//"),
                ends_line: self.source[abs + len..line_end.max(abs + len)].trim().is_empty(),
                blank_before: self.blank_before(abs),
            });
            at = start + len;
        }
    }

    /// Whether a blank line precedes `pos`: the whitespace right before it
    /// holds two line breaks or more.
    pub fn blank_before(&self, pos: usize) -> bool {
        let before = &self.source[..pos];
        let space = before.len() - before.trim_end_matches([' ', '\t', '\r', '\n', '\u{0C}']).len();
        before[pos - space..].matches('\n').count() >= 2
    }

    /// Whether the author wrote the expression at `start..end` in parentheses.
    pub fn parenthesised(&self, start: usize, end: usize) -> bool {
        self.parenthesised.contains_key(&(start, end))
    }

    /// Where the `(`s the author wrote around the expression at
    /// `start..end` start, the outermost first.
    pub fn open_parens(&self, start: usize, end: usize) -> &[usize] {
        self.parenthesised.get(&(start, end)).map_or(&[], Vec::as_slice)
    }

    /// The end of the `;` that follows `pos` (a statement's span leaves it
    /// out), or `pos` when the next token is not `;`.
    pub fn after_semi(&self, pos: usize) -> usize {
        self.next_token(pos).filter(|t| t.1 == Kind::Semi).map_or(pos, |t| t.2)
    }

    /// The end of the first `,` at or after `pos`, if any.
    pub fn comma_after(&self, pos: usize) -> Option<usize> {
        let first = self.tokens.partition_point(|t| t.0 < pos);
        self.tokens[first..].iter().find(|t| t.1 == Kind::Comma).map(|t| t.2)
    }

    fn next_token(&self, pos: usize) -> Option<(usize, Kind, usize)> {
        self.tokens.get(self.tokens.partition_point(|t| t.0 < pos)).copied()
    }

    /// Whether a line break separates `from` and `to`.
    pub fn breaks_between(&self, from: usize, to: usize) -> bool {
        from < to && self.source[from..to].contains('\n')
    }
}
