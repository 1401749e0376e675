//! The layout of expressions and of argument and parameter lists.
//!
//! Parentheses: the author's are kept, as written (the parser drops them;
//! `trivia` finds them again). The tree came from
//! the source with those parentheses, so they are always enough; those that
//! precedence requires are added all the same, so that the printer is right
//! for any tree.

use super::{Doc, Printer, hi, is_nil, lo};
use crate::syntax::ast::*;
use pretty::DocAllocator;

/// How tightly an expression binds: `?:` loosest, then `||` up to `*`,
/// then unary operators, then calls, fields, indexing and primaries.
fn precedence(e: &Expr) -> u8 {
    match &e.kind {
        ExprKind::Ternary(..) => 0,
        ExprKind::Binary(op, ..) => binary_precedence(*op),
        ExprKind::Unary(..) => 11,
        _ => 12,
    }
}

fn binary_precedence(op: BinaryOp) -> u8 {
    use BinaryOp::*;
    match op {
        Or => 1,
        And => 2,
        BitOr => 3,
        BitXor => 4,
        BitAnd => 5,
        Eq | Ne => 6,
        Lt | Gt | Le | Ge => 7,
        Shl | Shr => 8,
        Add | Sub => 9,
        Mul | Div | Rem => 10,
    }
}

/// The expressions right under an expression.
pub fn children(e: &Expr) -> Vec<&Expr> {
    match &e.kind {
        ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) | ExprKind::Name(_) => vec![],
        ExprKind::Unary(_, a) | ExprKind::Field { base: a, .. } => vec![a],
        ExprKind::Binary(_, a, b) | ExprKind::Index { base: a, index: b } => vec![a, b],
        ExprKind::Ternary(a, b, c) => vec![a, b, c],
        ExprKind::Call { args, .. } => args.iter().collect(),
    }
}

impl<'a> Printer<'a> {
    /// An expression in a place that takes any expression.
    pub(super) fn expr(&mut self, e: &Expr) -> Doc<'a> {
        self.operand(e, false)
    }

    /// An expression with the comments before it, in parentheses when the
    /// author wrote them or when `needed`.
    /// The comments before a `(` go before it, those after it inside.
    fn operand(&mut self, e: &Expr, needed: bool) -> Doc<'a> {
        let opens = self.trivia.open_parens(lo(e.span), hi(e.span)).to_vec();
        let mut doc = self.nil();
        for &open in &opens {
            doc = doc.append(self.inline(open)).append("(");
        }
        let needed = needed && opens.is_empty();
        doc = doc.append(self.inline(lo(e.span)));
        if needed {
            doc = doc.append("(");
        }
        doc = doc.append(self.bare(e));
        let closing = opens.len() + usize::from(needed);
        doc.append(")".repeat(closing))
    }

    /// An expression without its parentheses.
    fn bare(&mut self, e: &Expr) -> Doc<'a> {
        match &e.kind {
            ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Name(_) => self.text(self.slice(e.span)),
            ExprKind::Bool(b) => self.arena.text(if *b { "true" } else { "false" }),
            ExprKind::Unary(op, a) => {
                let symbol = match op {
                    UnaryOp::Neg => "-",
                    UnaryOp::Pos => "+",
                    UnaryOp::Not => "!",
                    UnaryOp::BitNot => "~",
                };
                // `- -x`, not `--x` (a decrement); likewise `+ +x`.
                let doubled = matches!(
                    (op, &a.kind),
                    (UnaryOp::Neg, ExprKind::Unary(UnaryOp::Neg, _)) | (UnaryOp::Pos, ExprKind::Unary(UnaryOp::Pos, _))
                ) && !self.trivia.parenthesised(lo(a.span), hi(a.span));
                let operand = self.operand(a, precedence(a) < 11);
                self.arena.text(if doubled { format!("{symbol} ") } else { symbol.to_string() }).append(operand)
            }
            ExprKind::Binary(op, ..) => self.chain(e, binary_precedence(*op)),
            ExprKind::Ternary(c, a, b) => {
                let c = self.operand(c, precedence(c) == 0);
                let a = self.operand(a, false);
                let b = self.operand(b, false);
                let branches =
                    self.arena.line().append("? ").append(a).append(self.arena.line()).append(": ").append(b);
                c.append(branches.nest(4)).group()
            }
            ExprKind::Call { callee, args } => {
                let name = self.text(self.slice(callee.span));
                match &args[..] {
                    // `f(g(a, b))` breaks inside `g(...)`, one level in, not
                    // before it: nested calls do not step right.
                    [arg] if self.hugs(arg) => name.append("(").append(self.bare(arg)).append(")"),
                    _ => name.append(self.list(args, |e| (lo(e.span), hi(e.span)), |p, e| p.expr(e))),
                }
            }
            ExprKind::Field { base, field } => {
                let needed = precedence(base) < 12 || super::bare_decimal_int(self, base);
                let base = self.operand(base, needed);
                base.append(".").append(self.text(self.slice(field.span)))
            }
            ExprKind::Index { base, index } => {
                let base = self.operand(base, precedence(base) < 12);
                base.append("[").append(self.expr(index)).append("]")
            }
        }
    }

    /// Whether a call's only argument is printed right after its `(`: a
    /// call, without parentheses or a comment before it. (Comments after
    /// it do not count: one left over inside the call is printed after the
    /// call, where formatting again finds it.)
    fn hugs(&self, arg: &Expr) -> bool {
        matches!(arg.kind, ExprKind::Call { .. })
            && !self.trivia.parenthesised(lo(arg.span), hi(arg.span))
            && !self.comment_before(lo(arg.span))
    }

    /// A chain of binary operators of one precedence, `a + b - c`, filling
    /// lines: it breaks before an operator whose operand does not fit on the
    /// line, the following lines one level in.
    fn chain(&mut self, e: &Expr, level: u8) -> Doc<'a> {
        // The operands from the right (the operators associate to the left).
        let mut rest: Vec<(BinaryOp, &Expr)> = vec![];
        let mut first = e;
        while let ExprKind::Binary(op, a, b) = &first.kind {
            if binary_precedence(*op) != level
                || (!std::ptr::eq(first, e) && self.trivia.parenthesised(lo(first.span), hi(first.span)))
            {
                break;
            }
            rest.push((*op, b));
            first = a;
        }
        let mut doc = self.operand(first, precedence(first) < level);
        let mut tail = self.nil();
        for (op, b) in rest.into_iter().rev() {
            let b = self.operand(b, precedence(b) <= level);
            let step = self.arena.line().append(op.symbol()).append(" ").append(b).group();
            tail = tail.append(step);
        }
        doc = doc.append(tail.nest(4));
        doc
    }

    /// `(a, b, c)`: on one line if it fits, else each item on a line of its
    /// own, one level in, the `)` after the last. A comment after a `,`
    /// stays at the end of its line.
    pub(super) fn list<T>(
        &mut self,
        items: &[T],
        span: impl Fn(&T) -> (usize, usize),
        item: impl FnMut(&mut Self, &T) -> Doc<'a>,
    ) -> Doc<'a> {
        if items.is_empty() {
            return self.arena.text("()");
        }
        let inner = self.list_items(items, span, item);
        self.arena.text("(").append(self.arena.line_().append(inner).nest(4)).append(")").group()
    }

    /// An array's elements, `{ a, b }`, or one a line with the braces on
    /// lines of their own when they do not fit.
    pub(super) fn elements(&mut self, items: &[Expr]) -> Doc<'a> {
        let inner = self.list_items(items, |e| (lo(e.span), hi(e.span)), |printer, e| printer.expr(e));
        let line = self.arena.line();
        self.arena.text("{").append(line.clone().append(inner).nest(4)).append(line).append("}").group()
    }

    /// The items of a list, separated by `,` and a line break or a space.
    fn list_items<T>(
        &mut self,
        items: &[T],
        span: impl Fn(&T) -> (usize, usize),
        mut item: impl FnMut(&mut Self, &T) -> Doc<'a>,
    ) -> Doc<'a> {
        let mut inner = self.nil();
        for (i, t) in items.iter().enumerate() {
            let comments = self.inline(span(t).0);
            inner = inner.append(comments).append(item(self, t));
            if i + 1 < items.len() {
                // A comment that ends the line after the `,` (and before the next item).
                let after = self.trivia.comma_after(span(t).1).unwrap_or(span(t).1);
                let next = span(&items[i + 1]).0;
                let ends_line = self.trivia.comments.get(self.next).is_some_and(|c| c.ends_line && c.start >= after);
                let trailing = if ends_line { self.trailing_before(after, next) } else { self.nil() };
                let separator = if is_nil(&trailing) { self.arena.line() } else { self.hardline() };
                inner = inner.append(",").append(trailing).append(separator);
            }
        }
        inner
    }
}
