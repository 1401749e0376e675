//! The words of the language, for tools that colour, complete and explain
//! it: the editors' TextMate grammar, the playground's CodeMirror mode and a
//! language server. Every list is read from the table the compiler itself
//! uses (the lexer's `Token::KINDS`, the checker's type names, the
//! builtins, the attributes), never kept a second time by hand, so the tools
//! cannot disagree with the compiler; `compiler/tests/it/sourcegen.rs`
//! writes the editor files from it and fails when they are out of date.
//!
//! What a word *is* for colouring ([`Class`]) is decided by one exhaustive
//! `match` over the lexer's tokens: a new token does not compile until it is
//! classified here.

use crate::attributes::ATTRIBUTES;
pub use crate::attributes::{AttributeSpec, Target};
use crate::builtins::Builtin;
use crate::syntax::lexer::Token;
use crate::types::NAMED_TYPES;

/// What a token of fixed text is, as an editor colours it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Class {
    /// Opens a declaration: `in`, `uniform`, `const`, `effect`, `out`.
    Declaration,
    /// A rate: `coarse`, `fine`.
    Rate,
    /// Steers control: `if`, `else`, `for`, `break`, `continue`, `return`, `refine`.
    Control,
    /// `true`, `false`.
    Boolean,
    Operator(Operator),
    Punctuation(Punctuation),
}

/// The kinds of operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Operator {
    /// `=`, `+=`, ...
    Assignment,
    /// `++`, `--`.
    Increment,
    /// `+ - * / %`.
    Arithmetic,
    /// `== != < > <= >=`.
    Comparison,
    /// `! && ||`.
    Logical,
    /// `~ & | ^ << >>`.
    Bitwise,
    /// `?` and `:`.
    Conditional,
}

/// The kinds of punctuation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Punctuation {
    Open(Bracket),
    Close(Bracket),
    /// `;`.
    Terminator,
    /// `,`.
    Separator,
    /// `.` (fields and swizzles).
    Accessor,
    /// `@`, which opens an attribute.
    Attribute,
}

/// The three pairs of brackets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Bracket {
    Round,
    Curly,
    Square,
}

/// A token of fixed text: a keyword, an operator or punctuation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Word {
    pub text: &'static str,
    pub class: Class,
}

/// What a token of fixed text is; `None` for identifiers, literals and comments.
fn class(token: &Token<'_>) -> Option<Class> {
    use Bracket::*;
    use Class::{Boolean, Control, Declaration, Rate};
    use Punctuation::{Accessor, Close, Open, Separator, Terminator};
    use Token::*;
    let operator = Class::Operator;
    let punctuation = Class::Punctuation;
    // No `_` arm: a token added to the lexer must be classified here.
    Some(match token {
        Ident(_) | IntLit(_) | UintLit(_) | SintLit(_) | FloatLit(_) | BlockComment => return None,
        In | Uniform | Const | Effect | Out => Declaration,
        Coarse | Fine => Rate,
        If | Else | For | Break | Continue | Return | Refine => Control,
        True | False => Boolean,
        LParen => punctuation(Open(Round)),
        RParen => punctuation(Close(Round)),
        LBrace => punctuation(Open(Curly)),
        RBrace => punctuation(Close(Curly)),
        LBracket => punctuation(Open(Square)),
        RBracket => punctuation(Close(Square)),
        Semi => punctuation(Terminator),
        Comma => punctuation(Separator),
        Dot => punctuation(Accessor),
        At => punctuation(Punctuation::Attribute),
        Question | Colon => operator(Operator::Conditional),
        Assign | PlusAssign | MinusAssign | StarAssign | SlashAssign => operator(Operator::Assignment),
        PlusPlus | MinusMinus => operator(Operator::Increment),
        Plus | Minus | Star | Slash | Percent => operator(Operator::Arithmetic),
        EqEq | NotEq | Lt | Gt | Le | Ge => operator(Operator::Comparison),
        Bang | AndAnd | OrOr => operator(Operator::Logical),
        Tilde | Amp | Pipe | Caret | Shl | Shr => operator(Operator::Bitwise),
    })
}

/// Every token of fixed text the lexer knows, in the lexer's order, with its class.
pub fn words() -> Vec<Word> {
    Token::KINDS.iter().filter_map(|token| Some(Word { text: token.kind_name(), class: class(token)? })).collect()
}

/// The keywords: the words that are letters.
pub fn keywords() -> Vec<Word> {
    words().into_iter().filter(|w| w.text.chars().all(|c| c.is_ascii_alphabetic())).collect()
}

/// The open and close text of each bracket pair.
pub fn bracket_pairs() -> Vec<(&'static str, &'static str)> {
    let text = |class| words().into_iter().find(|w| w.class == class).map(|w| w.text);
    [Bracket::Round, Bracket::Curly, Bracket::Square]
        .into_iter()
        .filter_map(|b| {
            Some((text(Class::Punctuation(Punctuation::Open(b)))?, text(Class::Punctuation(Punctuation::Close(b)))?))
        })
        .collect()
}

/// The names of the types a program can name (`float3`, `texture2d`, ...).
/// They lex as identifiers, so they are not among the [`words`].
pub fn types() -> Vec<&'static str> {
    NAMED_TYPES.iter().map(|(name, _)| *name).collect()
}

/// A builtin function, as an editor shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BuiltinWord {
    pub name: &'static str,
    /// What it computes, in a line.
    pub doc: &'static str,
    /// How many arguments it takes, as the arity error says it
    /// (`2 or 3 arguments (texture, int2 coord [, int level])`).
    pub arguments: String,
    /// Whether it is a derivative (allowed in effect bodies only, and
    /// evaluated at a neighbouring sample).
    pub derivative: bool,
}

/// Every builtin function.
pub fn builtins() -> Vec<BuiltinWord> {
    Builtin::ALL
        .iter()
        .map(|&b| BuiltinWord {
            name: b.name(),
            doc: b.doc(),
            arguments: b.signature().arity.to_string(),
            derivative: b.is_derivative(),
        })
        .collect()
}

/// Every attribute (written `@name`), with where it may stand.
pub fn attributes() -> &'static [AttributeSpec] {
    &ATTRIBUTES
}

/// How a kind of number literal is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumberForm {
    /// `float`, `hexadecimal` or `decimal`.
    pub name: &'static str,
    /// A regular expression in the syntax that Rust's `regex`, Oniguruma
    /// (TextMate) and JavaScript share. A tool tries the forms in order at
    /// a position: a float's digits would also match as a decimal.
    pub pattern: &'static str,
    /// Literals of this form, each with the lexer's name of its token kind.
    pub examples: &'static [(&'static str, &'static str)],
}

/// The number literals, as the lexer's `IntLit`, `UintLit`, `SintLit` and
/// `FloatLit` patterns read them (logos keeps those in attributes, out of
/// reach at run time; a test lexes every short digit string both ways).
pub const NUMBER_FORMS: [NumberForm; 3] = [
    NumberForm {
        name: "float",
        pattern: r"\b[0-9]+\.[0-9]*(?:[eE][+-]?[0-9]+)?[fF]?|\.[0-9]+(?:[eE][+-]?[0-9]+)?[fF]?|\b[0-9]+[eE][+-]?[0-9]+[fF]?|\b[0-9]+[fF]",
        examples: &[
            ("1.5", "float literal"),
            ("1.", "float literal"),
            (".5", "float literal"),
            ("1e3", "float literal"),
            ("2.5e-2", "float literal"),
            ("1f", "float literal"),
            ("1.5F", "float literal"),
        ],
    },
    NumberForm {
        name: "hexadecimal",
        pattern: r"\b0[xX][0-9a-fA-F]+[uU]?",
        examples: &[("0x2A", "int literal"), ("0XffU", "uint literal"), ("0x2Au", "uint literal")],
    },
    NumberForm {
        name: "decimal",
        pattern: r"\b[0-9]+[uUi]?",
        examples: &[("42", "int literal"), ("42u", "uint literal"), ("42U", "uint literal"), ("42i", "sint literal")],
    },
];

/// A comment that runs to the end of the line.
pub const LINE_COMMENT: &str = "//";

/// A block comment's open and close; block comments do not nest.
pub const BLOCK_COMMENT: (&str, &str) = ("/*", "*/");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::lexer::{LexError, Lexer};

    fn lex(source: &str) -> Vec<Result<(usize, Token<'_>, usize), LexError>> {
        Lexer::new(source).map(|t| t.map_err(|e| e.error)).collect()
    }

    #[test]
    fn every_token_of_fixed_text_has_a_class_and_the_others_none() {
        for token in Token::KINDS {
            let fixed = !matches!(
                token,
                Token::Ident(_) | Token::IntLit(_) | Token::UintLit(_) | Token::SintLit(_) | Token::FloatLit(_)
            );
            assert_eq!(class(&token).is_some(), fixed, "{token:?}");
            if let Some(class) = class(&token) {
                // The word lexes back to its own token.
                assert_eq!(lex(token.kind_name()), [Ok((0, token.clone(), token.kind_name().len()))], "{class:?}");
            }
        }
        assert_eq!(words().len(), Token::KINDS.len() - 5);
        assert_eq!(keywords().len(), 16);
        assert_eq!(bracket_pairs(), [("(", ")"), ("{", "}"), ("[", "]")]);
    }

    #[test]
    fn number_examples_lex_as_their_kind_and_cover_every_literal_kind() {
        let mut covered = vec![];
        for form in NUMBER_FORMS {
            for (text, kind) in form.examples {
                let tokens = lex(text);
                let [Ok((0, token, end))] = tokens.as_slice() else { panic!("{text} lexes as {tokens:?}") };
                assert_eq!((token.kind_name(), *end), (*kind, text.len()), "{text}");
                covered.push(*kind);
            }
        }
        for token in Token::KINDS.iter().filter(|t| t.kind_name().ends_with("literal")) {
            assert!(covered.contains(&token.kind_name()), "no example of a {}", token.kind_name());
        }
    }

    /// Every string of up to five characters that a number may hold (and a
    /// few that end one): where the lexer's first token is a number, the
    /// forms, tried in order at the start, match exactly its text, and
    /// where it is not, none matches.
    #[test]
    fn number_forms_read_numbers_as_the_lexer_does() {
        let forms: Vec<regex::Regex> =
            NUMBER_FORMS.iter().map(|f| regex::Regex::new(&format!("^(?:{})", f.pattern)).unwrap()).collect();
        let alphabet: Vec<char> = "01a.eE+-xXfFuUi_".chars().collect();
        let mut strings = vec![String::new()];
        for _ in 0..5 {
            strings = strings.iter().flat_map(|s| alphabet.iter().map(move |c| format!("{s}{c}"))).collect();
            for s in &strings {
                // A number out of range (`1e100`) is still read as one number.
                let lexed = match Lexer::new(s).next() {
                    Some(Ok((0, token, end))) if token.kind_name().ends_with("literal") => Some(end),
                    Some(Err(e)) if e.error == LexError::BadNumber => Some(e.end),
                    _ => None,
                };
                let matched = forms.iter().find_map(|f| f.find(s)).map(|m| m.end());
                assert_eq!(matched, lexed, "`{s}`: the forms read {matched:?} bytes, the lexer {lexed:?}");
            }
        }
    }

    #[test]
    fn comments_are_what_the_lexer_skips() {
        let (open, close) = BLOCK_COMMENT;
        assert_eq!(lex(&format!("{LINE_COMMENT} in\nin")), [Ok((6, Token::In, 8))]);
        assert_eq!(lex(&format!("{open} in {open} {close}in")), [Ok((11, Token::In, 13))]);
        assert_eq!(lex(&format!("{open} in")), [Err(LexError::UnterminatedComment)]);
    }

    #[test]
    fn builtins_types_and_attributes_are_the_compilers() {
        let builtins = builtins();
        assert_eq!(builtins.len(), Builtin::ALL.len());
        assert!(builtins.iter().all(|b| !b.doc.is_empty() && Builtin::from_name(b.name).is_some()));
        assert!(builtins.iter().any(|b| b.name == "ddx" && b.derivative));
        assert!(types().iter().all(|t| crate::types::Type::from_name(t).is_some()));
        assert!(attributes().iter().any(|a| a.name == "nearest" && a.target == Target::CoarseEffect));
    }
}
