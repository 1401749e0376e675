//! `mrslc fmt`: one canonical layout for every program, whatever its input
//! layout, with every comment kept where it was written.
//!
//! The program is parsed (a syntax error is the parser's own diagnostic),
//! the comments, blank lines and parentheses the parser drops are read back
//! from the source ([`trivia`]), and the tree is printed as a Wadler-style
//! document by the `pretty` crate, which chooses the line breaks: a group
//! stays on one line when it fits in [`WIDTH`] columns and breaks otherwise.
//! The layout, in short (docs/language.md, section 1, says it for users):
//!
//! - four spaces a level; one declaration or statement a line; at most one
//!   blank line where the author left any between declarations, statements
//!   or comments, none at the start or end of a block;
//! - one space around binary operators, after `,` and around `=`; an
//!   attribute on its declaration's line; a non-block `if`/`for` body on a
//!   line of its own, indented; `} else {`;
//! - literals as written (`1.0`, `1e3`, `2u`), and `++x` or `x++`;
//! - the author's parentheses are kept: they never change the meaning,
//!   authors write them to show how a formula reads, and the kernels quote
//!   derivative operands as written;
//! - a long expression breaks before its operators and `?`/`:`, filling
//!   each line, its continuation lines four spaces in; a long argument or
//!   parameter list puts each item on a line of its own, and the `)` stays
//!   on the last;
//! - a comment after code on its line stays there, and such comments on
//!   consecutive lines are aligned, two spaces after the longest code.
//!
//! The result is parsed again and compared with the input's tree, spans
//! aside, and its comments with the input's: a formatter bug is an internal
//! error (E9000), never a changed program.

mod exprs;
mod items;
mod lines;
mod trivia;
mod verify;

use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::{Expr, ExprKind, Program, Span, Stmt};
use pretty::{Arena, DocAllocator, DocBuilder};
use trivia::Trivia;

/// The width lines are broken at, as rustfmt's default.
pub const WIDTH: usize = 100;

/// The deepest nesting of statements and expressions the formatter takes,
/// (it recurses over the tree): well above what the compiler accepts
/// (`limits`: 398 nested expression nodes, 126 levels of blocks).
pub const MAX_DEPTH: usize = 2000;

/// Formats a program in the canonical layout. A syntax error is returned
/// as the parser reports it; a program nested deeper than [`MAX_DEPTH`] is
/// E0602.
pub fn format(source: &str) -> Result<String, Diagnostic> {
    let program = crate::syntax::parse(source)?;
    too_deep(&program)?;
    let trivia = Trivia::scan(source);
    let comments: Vec<String> = trivia.comments.iter().map(|c| c.text.to_string()).collect();
    let arena = Arena::new();
    // A character the source does not hold marks where each trailing comment starts.
    let mark = (0xE000..=0xF8FF).filter_map(char::from_u32).find(|c| !source.contains(*c)).unwrap_or('\u{F8FF}');
    let mut printer = Printer { arena: &arena, source, trivia, next: 0, mark, line_ended_at: None };
    let doc = printer.program(&program);
    let mut rendered = String::new();
    doc.1.render_fmt(WIDTH, &mut rendered).map_err(|_| internal("the layout could not be rendered"))?;
    let mut formatted = lines::finish(&rendered, mark);
    // A byte order mark the file opens with stays (the lexer skips it).
    if source.starts_with(crate::syntax::lexer::BOM) && !formatted.is_empty() {
        formatted.insert(0, crate::syntax::lexer::BOM);
    }
    verify::same_program(&program, &comments, &formatted).map_err(|what| internal(&what))?;
    Ok(formatted)
}

/// An expression's text in the canonical layout, on one line, its comments
/// left out: how a kernel quotes a derivative operand, so that formatting a
/// program leaves its kernels byte-identical. Text that does not parse as
/// an expression comes back with its spaces collapsed.
pub fn expression(text: &str) -> String {
    let collapsed = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut code = text.to_string();
    for comment in Trivia::scan(text).comments {
        let end = comment.start + comment.text.len();
        code.replace_range(comment.start..end, &" ".repeat(comment.text.len()));
    }
    let Some(expr) = crate::syntax::parse_expression(&code) else { return collapsed(text) };
    let arena = Arena::new();
    let trivia = Trivia::scan(&code);
    let mut printer = Printer { arena: &arena, source: &code, trivia, next: 0, mark: '\u{F8FF}', line_ended_at: None };
    let mut rendered = String::new();
    match printer.expr(&expr).1.render_fmt(usize::MAX / 2, &mut rendered) {
        Ok(()) => collapsed(&rendered),
        Err(_) => collapsed(text),
    }
}

/// A formatter bug, reported instead of writing a changed program.
fn internal(what: &str) -> Diagnostic {
    Diagnostic::bug(format!("internal error in the formatter: {what}"))
        .with_note("nothing was written; please report this program")
}

/// E0602 when statements and expressions nest deeper than [`MAX_DEPTH`]
/// (measured without recursion).
fn too_deep(program: &Program) -> Result<(), Diagnostic> {
    enum Node<'p> {
        Stmt(&'p Stmt),
        Expr(&'p Expr),
    }
    let mut stack: Vec<(Node<'_>, usize)> = vec![];
    for item in &program.items {
        let (exprs, stmts) = items::children(item);
        stack.extend(exprs.into_iter().map(|e| (Node::Expr(e), 1)));
        stack.extend(stmts.into_iter().map(|s| (Node::Stmt(s), 1)));
    }
    while let Some((node, depth)) = stack.pop() {
        let span = match node {
            Node::Stmt(s) => s.span,
            Node::Expr(e) => e.span,
        };
        if depth > MAX_DEPTH {
            return Err(Diagnostic::error("E0602", "nested too deeply to format")
                .with_label(Label::primary(span, format!("more than {MAX_DEPTH} levels deep")))
                .with_note("the compiler takes far less nesting than this (docs/language.md, section 14)"));
        }
        match node {
            Node::Stmt(s) => {
                let (exprs, stmts) = items::stmt_children(s);
                stack.extend(exprs.into_iter().map(|e| (Node::Expr(e), depth + 1)));
                stack.extend(stmts.into_iter().map(|s| (Node::Stmt(s), depth + 1)));
            }
            Node::Expr(e) => stack.extend(exprs::children(e).into_iter().map(|e| (Node::Expr(e), depth + 1))),
        }
    }
    Ok(())
}

type Doc<'a> = DocBuilder<'a, Arena<'a>>;

/// Prints a program's tree as a document, taking its comments in source
/// order: each is printed before the first node that starts after it, or
/// after the code it follows on its line.
struct Printer<'a> {
    arena: &'a Arena<'a>,
    source: &'a str,
    trivia: Trivia<'a>,
    /// The first comment not printed yet.
    next: usize,
    /// Marks the start of a trailing comment in the rendered text (for `lines`).
    mark: char,
    /// Where the code ends that the last trailing `//` comment follows.
    line_ended_at: Option<usize>,
}

impl<'a> Printer<'a> {
    /// Text, measured in characters (identifiers and comments may be Unicode).
    fn text(&self, text: &'a str) -> Doc<'a> {
        self.sized(text.chars().count(), self.arena.text(text))
    }

    fn owned(&self, text: String) -> Doc<'a> {
        self.sized(text.chars().count(), self.arena.text(text))
    }

    /// `doc`, measured as `width` columns when the layout fits lines
    /// (pretty measures bytes). `doc` is a text: pretty renders no other
    /// document inside a measured one.
    fn sized(&self, width: usize, doc: Doc<'a>) -> Doc<'a> {
        match &*doc {
            pretty::Doc::OwnedText(_) | pretty::Doc::BorrowedText(_) | pretty::Doc::SmallText(_) => {
                DocBuilder(self.arena, pretty::Doc::RenderLen(width, doc.into_doc()).into())
            }
            _ => doc,
        }
    }

    fn nil(&self) -> Doc<'a> {
        self.arena.nil()
    }

    fn hardline(&self) -> Doc<'a> {
        self.arena.hardline()
    }

    fn slice(&self, span: Span) -> &'a str {
        &self.source[lo(span)..hi(span)]
    }

    /// The comments before `pos` not printed yet, each followed by a line
    /// break (a block comment that code follows on its line stays before
    /// it): the comments before a declaration or a statement. A blank line
    /// goes before each that had one, unless it is `first` in the file or
    /// its block. Returns the document and how many comments it holds.
    fn leading(&mut self, pos: usize, first: bool) -> (Doc<'a>, usize) {
        let mut doc = self.nil();
        let mut count = 0;
        while let Some(c) = self.take_before(pos) {
            if c.blank_before && !(first && count == 0) {
                doc = doc.append(self.hardline());
            }
            count += 1;
            let after = if c.line || c.ends_line { self.hardline() } else { self.arena.space() };
            doc = doc.append(self.comment(c.text)).append(after);
        }
        (doc, count)
    }

    /// The comments before `pos` not printed yet, each after a line break:
    /// those before a closing brace or at the end of the file (where
    /// `lines` drops a first line break). `first`: no code precedes them in
    /// their block or file.
    fn closing(&mut self, pos: usize, first: bool) -> Doc<'a> {
        let mut doc = self.nil();
        let mut first = first;
        while let Some(c) = self.take_before(pos) {
            doc = doc.append(self.hardline());
            if c.blank_before && !first {
                doc = doc.append(self.hardline());
            }
            first = false;
            doc = doc.append(self.comment(c.text));
        }
        doc
    }

    /// The comments before `pos` not printed yet, inside an expression: a
    /// `//` comment (or a block comment that ends its line) breaks the line.
    fn inline(&mut self, pos: usize) -> Doc<'a> {
        let mut doc = self.nil();
        while let Some(c) = self.take_before(pos) {
            let after = if c.line || c.ends_line { self.hardline() } else { self.arena.space() };
            doc = doc.append(self.comment(c.text)).append(after);
        }
        doc
    }

    /// The next comment not printed yet, if it starts before `pos`.
    fn take_before(&mut self, pos: usize) -> Option<trivia::Comment<'a>> {
        let c = self.trivia.comments.get(self.next).filter(|c| c.start < pos).cloned()?;
        self.next += 1;
        Some(c)
    }

    /// The comments after code that ends at `end`: those left over inside
    /// it, and those that start on its line. The caller ends the line.
    fn trailing(&mut self, end: usize) -> Doc<'a> {
        self.trailing_before(end, usize::MAX)
    }

    /// [`Printer::trailing`], of the comments that start before `limit`.
    /// It stops after a `//` comment: what comes after it goes on a later
    /// line, printed with what follows (as it will be when formatted again).
    fn trailing_before(&mut self, end: usize, limit: usize) -> Doc<'a> {
        let mut doc = self.nil();
        // A statement that ends where the one it holds ends (`if (c) x;`)
        // takes no comment after one of its inner statement's `//` comments.
        if self.line_ended_at == Some(end) {
            return doc;
        }
        while let Some(c) = self.trivia.comments.get(self.next).cloned() {
            if c.start >= limit || (c.start >= end && self.trivia.breaks_between(end, c.start)) {
                break;
            }
            self.next += 1;
            if is_nil(&doc) {
                // The first is marked for `lines` to align, and takes no
                // width: a comment never makes the code before it break.
                let text = self.arena.text(format!("{}{}", self.mark, c.text));
                doc = doc.append(self.sized(0, text));
            } else {
                doc = doc.append(self.arena.text(format!(" {}", c.text)));
            }
            if c.line {
                self.line_ended_at = Some(end);
                break;
            }
        }
        doc
    }

    /// Whether a comment not printed yet starts before `pos`.
    fn comment_before(&self, pos: usize) -> bool {
        self.trivia.comments.get(self.next).is_some_and(|c| c.start < pos)
    }

    /// A comment's text; the lines of a block comment after its first are
    /// printed as written (re-indenting them would change the comment).
    fn comment(&self, text: &'a str) -> Doc<'a> {
        self.text(text)
    }

    /// The whole program: its declarations, their comments, and the comments
    /// after the last.
    fn program(&mut self, program: &Program) -> Doc<'a> {
        let mut doc = self.nil();
        for (i, item) in program.items.iter().enumerate() {
            let start = items::item_start(item);
            if i > 0 {
                doc = doc.append(self.hardline());
            }
            let (leading, count) = self.leading(start, i == 0);
            doc = doc.append(leading);
            if (i > 0 || count > 0) && self.trivia.blank_before(start) {
                doc = doc.append(self.hardline());
            }
            let item_doc = self.item(item);
            doc = doc.append(item_doc).append(self.trailing(items::item_end(item)));
        }
        doc.append(self.closing(self.source.len() + 1, program.items.is_empty()))
    }
}

/// Whether a document is empty.
fn is_nil(doc: &Doc<'_>) -> bool {
    matches!(&**doc, pretty::Doc::Nil)
}

/// Where a span starts, as an offset into the source.
fn lo(span: Span) -> usize {
    span.range().start
}

/// Where a span ends, as an offset into the source.
fn hi(span: Span) -> usize {
    span.range().end
}

/// Whether an expression is a plain decimal integer (`1 .x` must print as
/// `(1).x`: `1.x` would lex as the float `1.`).
fn bare_decimal_int(printer: &Printer<'_>, e: &Expr) -> bool {
    matches!(e.kind, ExprKind::Int(..)) && printer.slice(e.span).bytes().all(|b| b.is_ascii_digit())
}

#[cfg(test)]
mod tests;
