//! The lexer: source text to `(start, Token, end)` triples for the lalrpop parser.
//!
//! Tokens are recognised by a logos-generated automaton. Keywords that name
//! types (`float3`, `texture2d`, ...) are *not* keywords here: they lex as
//! identifiers and the parser turns a type name into a type, which keeps the
//! grammar small and lets diagnostics say "unknown type `flaot3`" instead of
//! "unexpected identifier".

use logos::Logos;

/// A lexical error: the span of text that is not a token.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum LexError {
    #[default]
    InvalidToken,
    /// A `/*` with no matching `*/`.
    UnterminatedComment,
    /// A numeric literal that does not fit its type.
    BadNumber,
}

fn block_comment<'a>(lex: &mut logos::Lexer<'a, Token<'a>>) -> logos::FilterResult<(), LexError> {
    // Block comments do not nest, as in C and WGSL's predecessors; the body
    // ends at the first `*/`.
    match lex.remainder().find("*/") {
        Some(end) => {
            lex.bump(end + 2);
            logos::FilterResult::Skip
        }
        None => {
            lex.bump(lex.remainder().len());
            logos::FilterResult::Error(LexError::UnterminatedComment)
        }
    }
}

fn parse_int<'a>(lex: &mut logos::Lexer<'a, Token<'a>>) -> Result<u64, LexError> {
    let text = lex.slice().trim_end_matches(['u', 'U', 'i']);
    let value = if let Some(hex) = text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        u64::from_str_radix(hex, 16)
    } else {
        text.parse::<u64>()
    };
    value.map_err(|_| LexError::BadNumber).and_then(
        |v| {
            if v > u32::MAX as u64 { Err(LexError::BadNumber) } else { Ok(v) }
        },
    )
}

fn parse_float<'a>(lex: &mut logos::Lexer<'a, Token<'a>>) -> Result<f64, LexError> {
    let text = lex.slice().trim_end_matches(['f', 'F']);
    text.parse::<f64>().ok().filter(|v| v.is_finite() && *v <= f32::MAX as f64).ok_or(LexError::BadNumber)
}

/// Every token of the language.
#[derive(Logos, Debug, Clone, PartialEq)]
#[logos(error = LexError)]
#[logos(skip r"[ \t\r\n\f]+")]
#[logos(skip(r"//[^\n]*", allow_greedy = true))]
pub enum Token<'input> {
    #[token("/*", block_comment)]
    BlockComment,

    #[regex(r"[A-Za-z_][A-Za-z0-9_]*", |lex| lex.slice())]
    Ident(&'input str),
    #[regex(r"[0-9]+", parse_int)]
    #[regex(r"0[xX][0-9a-fA-F]+", parse_int)]
    IntLit(u64),
    #[regex(r"[0-9]+[uU]", parse_int)]
    #[regex(r"0[xX][0-9a-fA-F]+[uU]", parse_int)]
    UintLit(u64),
    #[regex(r"[0-9]+i", parse_int)]
    SintLit(u64),
    #[regex(r"[0-9]+\.[0-9]*([eE][+-]?[0-9]+)?[fF]?", parse_float)]
    #[regex(r"\.[0-9]+([eE][+-]?[0-9]+)?[fF]?", parse_float)]
    #[regex(r"[0-9]+[eE][+-]?[0-9]+[fF]?", parse_float)]
    #[regex(r"[0-9]+[fF]", parse_float)]
    FloatLit(f64),

    #[token("in")]
    In,
    #[token("uniform")]
    Uniform,
    #[token("const")]
    Const,
    #[token("coarse")]
    Coarse,
    #[token("fine")]
    Fine,
    #[token("effect")]
    Effect,
    #[token("out")]
    Out,
    #[token("refine")]
    Refine,
    #[token("if")]
    If,
    #[token("else")]
    Else,
    #[token("for")]
    For,
    #[token("break")]
    Break,
    #[token("continue")]
    Continue,
    #[token("return")]
    Return,
    #[token("true")]
    True,
    #[token("false")]
    False,

    #[token("(")]
    LParen,
    #[token(")")]
    RParen,
    #[token("{")]
    LBrace,
    #[token("}")]
    RBrace,
    #[token("[")]
    LBracket,
    #[token("]")]
    RBracket,
    #[token(";")]
    Semi,
    #[token(",")]
    Comma,
    #[token(".")]
    Dot,
    #[token("?")]
    Question,
    #[token(":")]
    Colon,
    #[token("@")]
    At,
    #[token("=")]
    Assign,
    #[token("+=")]
    PlusAssign,
    #[token("-=")]
    MinusAssign,
    #[token("*=")]
    StarAssign,
    #[token("/=")]
    SlashAssign,
    #[token("++")]
    PlusPlus,
    #[token("--")]
    MinusMinus,
    #[token("+")]
    Plus,
    #[token("-")]
    Minus,
    #[token("*")]
    Star,
    #[token("/")]
    Slash,
    #[token("%")]
    Percent,
    #[token("!")]
    Bang,
    #[token("~")]
    Tilde,
    #[token("&")]
    Amp,
    #[token("|")]
    Pipe,
    #[token("^")]
    Caret,
    #[token("<<")]
    Shl,
    #[token(">>")]
    Shr,
    #[token("&&")]
    AndAnd,
    #[token("||")]
    OrOr,
    #[token("==")]
    EqEq,
    #[token("!=")]
    NotEq,
    #[token("<")]
    Lt,
    #[token(">")]
    Gt,
    #[token("<=")]
    Le,
    #[token(">=")]
    Ge,
}

impl std::fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Token::Ident(name) => write!(f, "identifier `{name}`"),
            Token::IntLit(v) | Token::UintLit(v) | Token::SintLit(v) => write!(f, "number `{v}`"),
            Token::FloatLit(v) => write!(f, "number `{v}`"),
            Token::BlockComment => f.write_str("comment"),
            other => write!(f, "`{}`", token_text(other)),
        }
    }
}

fn token_text(token: &Token<'_>) -> &'static str {
    use Token::*;
    match token {
        In => "in",
        Uniform => "uniform",
        Const => "const",
        Coarse => "coarse",
        Fine => "fine",
        Effect => "effect",
        Out => "out",
        Refine => "refine",
        If => "if",
        Else => "else",
        For => "for",
        Break => "break",
        Continue => "continue",
        Return => "return",
        True => "true",
        False => "false",
        LParen => "(",
        RParen => ")",
        LBrace => "{",
        RBrace => "}",
        LBracket => "[",
        RBracket => "]",
        Semi => ";",
        Comma => ",",
        Dot => ".",
        Question => "?",
        Colon => ":",
        At => "@",
        Assign => "=",
        PlusAssign => "+=",
        MinusAssign => "-=",
        StarAssign => "*=",
        SlashAssign => "/=",
        PlusPlus => "++",
        MinusMinus => "--",
        Plus => "+",
        Minus => "-",
        Star => "*",
        Slash => "/",
        Percent => "%",
        Bang => "!",
        Tilde => "~",
        Amp => "&",
        Pipe => "|",
        Caret => "^",
        Shl => "<<",
        Shr => ">>",
        AndAnd => "&&",
        OrOr => "||",
        EqEq => "==",
        NotEq => "!=",
        Lt => "<",
        Gt => ">",
        Le => "<=",
        Ge => ">=",
        Ident(_) | IntLit(_) | UintLit(_) | SintLit(_) | FloatLit(_) | BlockComment => "",
    }
}

/// Adapts the logos lexer to lalrpop's `(start, token, end)` iterator contract.
pub struct Lexer<'input> {
    inner: logos::SpannedIter<'input, Token<'input>>,
}

impl<'input> Lexer<'input> {
    pub fn new(source: &'input str) -> Self {
        Lexer { inner: Token::lexer(source).spanned() }
    }
}

impl<'input> Iterator for Lexer<'input> {
    type Item = Result<(usize, Token<'input>, usize), LexErrorAt>;

    fn next(&mut self) -> Option<Self::Item> {
        let (token, span) = self.inner.next()?;
        Some(match token {
            Ok(token) => Ok((span.start, token, span.end)),
            Err(error) => Err(LexErrorAt { error, start: span.start, end: span.end }),
        })
    }
}

/// A lexical error with its place in the source.
#[derive(Debug, Clone, PartialEq)]
pub struct LexErrorAt {
    pub error: LexError,
    pub start: usize,
    pub end: usize,
}
