//! The lexer: source text to `(start, Token, end)` triples for the lalrpop parser.
//!
//! Tokens are recognised by a logos-generated automaton. Keywords that name
//! types (`float3`, `texture2d`, ...) are *not* keywords here: they lex as
//! identifiers and the parser turns a type name into a type, which keeps the
//! grammar small and lets diagnostics say "unknown type `flaot3`" instead of
//! "unexpected identifier".
//!
//! Identifiers follow WGSL's rule: a Unicode `XID_Start` character or `_`,
//! then `XID_Continue` characters. The automaton matches any run of ASCII
//! identifier characters and non-ASCII characters, and [`identifier`] checks
//! the non-ASCII ones against the XID tables, so an error names the exact
//! character that is not allowed. A byte order mark that opens the source is
//! skipped (spans stay offsets into the whole source).

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
    /// A non-ASCII character that may not stand where it does in an
    /// identifier-like run: its byte offset from the start of the run.
    BadIdentifierChar(usize),
}

/// The byte order mark, which the lexer skips at the start of the source.
pub const BOM: char = '\u{FEFF}';

fn identifier<'a>(lex: &mut logos::Lexer<'a, Token<'a>>) -> Result<&'a str, LexError> {
    let text = lex.slice();
    for (offset, c) in text.char_indices() {
        let allowed = c.is_ascii()
            || if offset == 0 { unicode_ident::is_xid_start(c) } else { unicode_ident::is_xid_continue(c) };
        if !allowed {
            return Err(LexError::BadIdentifierChar(offset));
        }
    }
    Ok(text)
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

    // Any non-ASCII character starts or continues a run; `identifier` rejects
    // those outside Unicode XID, naming them.
    #[regex(r"([A-Za-z_]|[^\x00-\x7F])([A-Za-z0-9_]|[^\x00-\x7F])*", identifier)]
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

impl Token<'_> {
    /// One token of every kind the parser takes (comments never reach it):
    /// syntax errors probe the parser with each to list what it expects.
    pub const KINDS: [Token<'static>; 60] = {
        use Token::*;
        [
            Ident("x"),
            IntLit(0),
            UintLit(0),
            SintLit(0),
            FloatLit(0.0),
            In,
            Uniform,
            Const,
            Coarse,
            Fine,
            Effect,
            Out,
            Refine,
            If,
            Else,
            For,
            Break,
            Continue,
            Return,
            True,
            False,
            LParen,
            RParen,
            LBrace,
            RBrace,
            LBracket,
            RBracket,
            Semi,
            Comma,
            Dot,
            Question,
            Colon,
            At,
            Assign,
            PlusAssign,
            MinusAssign,
            StarAssign,
            SlashAssign,
            PlusPlus,
            MinusMinus,
            Plus,
            Minus,
            Star,
            Slash,
            Percent,
            Bang,
            Tilde,
            Amp,
            Pipe,
            Caret,
            Shl,
            Shr,
            AndAnd,
            OrOr,
            EqEq,
            NotEq,
            Lt,
            Gt,
            Le,
            Ge,
        ]
    };

    /// The name of the token's kind, as the grammar names its terminal:
    /// `identifier`, `int literal`, ..., or the text of the token.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Token::Ident(_) => "identifier",
            Token::IntLit(_) => "int literal",
            Token::UintLit(_) => "uint literal",
            Token::SintLit(_) => "sint literal",
            Token::FloatLit(_) => "float literal",
            Token::BlockComment => "comment",
            other => token_text(other),
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
        let mut lexer = Token::lexer(source);
        if source.starts_with(BOM) {
            lexer.bump(BOM.len_utf8());
        }
        Lexer { inner: lexer.spanned() }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `Token::KINDS` holds every terminal of the grammar, once: the grammar's
    /// `extern` block names each as `"name" => Token::Variant`.
    #[test]
    fn kinds_cover_every_terminal_of_the_grammar() {
        let grammar = include_str!("../../../grammar/mrsl.lalrpop");
        let terminals: Vec<&str> = grammar
            .lines()
            .filter(|l| l.contains("=> Token::"))
            .filter_map(|l| l.trim().strip_prefix('"')?.split('"').next())
            .collect();
        let mut names: Vec<&str> = Token::KINDS.iter().map(Token::kind_name).collect();
        let mut expected = terminals.clone();
        names.sort_unstable();
        expected.sort_unstable();
        assert_eq!(names, expected);
    }

    #[test]
    fn identifiers_are_unicode_xid() {
        fn kinds(s: &str) -> Vec<Result<Token<'_>, LexErrorAt>> {
            Lexer::new(s).map(|t| t.map(|(_, t, _)| t)).collect()
        }
        assert_eq!(
            kinds("été λ _x1 x\u{301}"),
            vec![Ok(Token::Ident("été")), Ok(Token::Ident("λ")), Ok(Token::Ident("_x1")), Ok(Token::Ident("x\u{301}"))]
        );
        // U+0301 (combining acute) continues an identifier but cannot start one; U+20AC (€) is not XID.
        assert_eq!(kinds("\u{301}x")[0].as_ref().unwrap_err().error, LexError::BadIdentifierChar(0));
        assert_eq!(kinds("price€")[0].as_ref().unwrap_err().error, LexError::BadIdentifierChar(5));
        assert_eq!(kinds("\0")[0].as_ref().unwrap_err().error, LexError::InvalidToken);
    }

    #[test]
    fn a_leading_byte_order_mark_is_skipped_and_spans_stay_in_the_source() {
        let tokens: Vec<_> = Lexer::new("\u{FEFF}in x").map(Result::unwrap).collect();
        assert_eq!(tokens, vec![(3, Token::In, 5), (6, Token::Ident("x"), 7)]);
        // Elsewhere it is an invalid character.
        assert!(Lexer::new("x \u{FEFF}").any(|t| t.is_err()));
    }
}
