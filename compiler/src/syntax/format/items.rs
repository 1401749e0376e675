//! The layout of declarations, statements and blocks.

use super::{Doc, Printer, hi, is_nil, lo};
use crate::syntax::ast::*;
use pretty::DocAllocator;

/// Where a declaration starts: at its first attribute, if any.
pub fn item_start(item: &Item) -> usize {
    let (attrs, span) = match item {
        Item::Input(d) => (&d.attrs[..], d.span),
        Item::Uniform(d) => (&d.attrs[..], d.span),
        Item::Const(d) => (&[][..], d.span),
        Item::Function(d) => (&[][..], d.span),
        Item::Effect(d) => (&d.attrs[..], d.span),
    };
    attrs.first().map_or(lo(span), |a| lo(a.span).min(lo(span)))
}

/// Where a declaration's last token (its `;` or `}`) ends.
pub fn item_end(item: &Item) -> usize {
    match item {
        Item::Input(d) => hi(d.span),
        Item::Uniform(d) => hi(d.span),
        Item::Const(d) => hi(d.span),
        Item::Function(d) => hi(d.span),
        Item::Effect(d) => hi(d.span),
    }
}

/// The expressions and statements right under a declaration.
pub fn children(item: &Item) -> (Vec<&Expr>, Vec<&Stmt>) {
    fn attr_args(attrs: &[Attribute]) -> Vec<&Expr> {
        attrs.iter().flat_map(|a| &a.args).collect()
    }
    match item {
        Item::Input(d) => (attr_args(&d.attrs), vec![]),
        Item::Uniform(d) => {
            let mut exprs = attr_args(&d.attrs);
            exprs.extend(d.array_len.iter().chain(&d.default).chain(d.elements.iter().flat_map(|e| &e.items)));
            (exprs, vec![])
        }
        Item::Const(d) => (vec![&d.value], vec![]),
        Item::Function(d) => (vec![], d.body.stmts.iter().collect()),
        Item::Effect(d) => match &d.body {
            EffectBody::Expr(e) => {
                let mut exprs = attr_args(&d.attrs);
                exprs.push(e);
                (exprs, vec![])
            }
            EffectBody::Block(b) => (attr_args(&d.attrs), b.stmts.iter().collect()),
        },
    }
}

/// The expressions and statements right under a statement.
pub fn stmt_children(s: &Stmt) -> (Vec<&Expr>, Vec<&Stmt>) {
    match &s.kind {
        StmtKind::Local { init, .. } => (init.iter().collect(), vec![]),
        StmtKind::Assign { target, value, .. } => (vec![target, value], vec![]),
        StmtKind::Step { target, .. } => (vec![target], vec![]),
        StmtKind::If { cond, then, otherwise } => {
            (vec![cond], std::iter::once(&**then).chain(otherwise.as_deref()).collect())
        }
        StmtKind::For { init, cond, step, body } => {
            let stmts = init.as_deref().into_iter().chain(step.as_deref()).chain(std::iter::once(&**body));
            (cond.iter().collect(), stmts.collect())
        }
        StmtKind::Block(b) => (vec![], b.stmts.iter().collect()),
        StmtKind::Return(e) => (e.iter().collect(), vec![]),
        StmtKind::Refine | StmtKind::Break | StmtKind::Continue => (vec![], vec![]),
    }
}

impl<'a> Printer<'a> {
    /// A declaration, without the comments around it.
    pub(super) fn item(&mut self, item: &Item) -> Doc<'a> {
        match item {
            Item::Input(d) => {
                let attrs = self.attributes(&d.attrs);
                let decl = self.words(&["in", &d.ty.name, &d.name.name]);
                attrs.append(decl).append(";")
            }
            Item::Uniform(d) => {
                let mut doc = self.attributes(&d.attrs).append(self.words(&["uniform", &d.ty.name, &d.name.name]));
                if let Some(len) = &d.array_len {
                    doc = doc.append("[").append(self.expr(len)).append("]");
                }
                if let Some(value) = &d.default {
                    doc = doc.append(" = ").append(self.expr(value));
                }
                if let Some(elements) = &d.elements {
                    doc = doc.append(" = ").append(self.elements(&elements.items));
                }
                doc.append(";")
            }
            Item::Const(d) => {
                let decl = self.words(&["const", &d.ty.name, &d.name.name]);
                decl.append(" = ").append(self.expr(&d.value)).append(";")
            }
            Item::Function(d) => {
                let head = self.words(&[&d.ret.name, &d.name.name]);
                let params = self.list(
                    &d.params,
                    |p| (lo(p.ty.span), hi(p.name.span)),
                    |printer, p| {
                        let p: &Param = p;
                        printer.words(&[&p.ty.name, &p.name.name])
                    },
                );
                head.append(params).append(" ").append(self.block(&d.body))
            }
            Item::Effect(d) => self.effect(d),
        }
    }

    fn effect(&mut self, d: &EffectDecl) -> Doc<'a> {
        let rate = match (d.rate, d.coarse_block) {
            (Rate::Coarse, Some((_, n))) => format!("coarse({}) effect", self.slice(n)),
            (Rate::Coarse, None) => "coarse effect".into(),
            (Rate::Fine, _) => "fine effect".into(),
            (Rate::Out, _) => "fine out".into(),
        };
        let doc = self.attributes(&d.attrs).append(self.owned(rate)).append(" ");
        let doc = doc.append(self.words(&[&d.ty.name, &d.name.name]));
        match &d.body {
            EffectBody::Expr(e) => doc.append(" = ").append(self.expr(e)).append(";"),
            EffectBody::Block(b) => doc.append(" ").append(self.block(b)),
        }
    }

    /// Words separated by single spaces.
    fn words(&self, words: &[&str]) -> Doc<'a> {
        self.owned(words.join(" "))
    }

    /// `@name` or `@name(args)`, each followed by a space.
    fn attributes(&mut self, attrs: &[Attribute]) -> Doc<'a> {
        let mut doc = self.nil();
        for attr in attrs {
            doc = doc.append(self.inline(lo(attr.span))).append("@").append(self.owned(attr.name.name.clone()));
            // `@name()` is `@name`.
            if !attr.args.is_empty() {
                doc = doc.append(self.list(&attr.args, |e| (lo(e.span), hi(e.span)), |p, e| p.expr(e)));
            }
            doc = doc.append(" ");
        }
        doc
    }

    /// A block: each statement on a line of its own with its comments, at
    /// one more level; `{}` when it holds nothing.
    pub(super) fn block(&mut self, b: &Block) -> Doc<'a> {
        let open = self.trailing(lo(b.span) + 1);
        let close = hi(b.span) - 1;
        let mut inner = self.nil();
        for (i, s) in b.stmts.iter().enumerate() {
            inner = inner.append(self.hardline()).append(self.statement(s, i == 0));
        }
        let closing = self.closing(close, b.stmts.is_empty());
        if b.stmts.is_empty() && is_nil(&open) && is_nil(&closing) {
            return self.arena.text("{}");
        }
        // The comments after `{` are in the block too: a second one goes on
        // a line of its own, one level in.
        self.arena.text("{").append(open.append(inner).append(closing).nest(4)).append(self.hardline()).append("}")
    }

    /// A statement in a block with its comments: those before it, a blank
    /// line if one was written (not `first` in its block), and those after it.
    fn statement(&mut self, s: &Stmt, first: bool) -> Doc<'a> {
        let (leading, count) = self.leading(lo(s.span), first);
        let mut doc = leading;
        if (!first || count > 0) && self.trivia.blank_before(lo(s.span)) {
            doc = doc.append(self.hardline());
        }
        let body = self.stmt(s);
        doc.append(body).append(self.trailing(self.trivia.after_semi(hi(s.span))))
    }

    /// A statement, ending with its `;` if it has one.
    fn stmt(&mut self, s: &Stmt) -> Doc<'a> {
        match &s.kind {
            StmtKind::Local { .. } | StmtKind::Assign { .. } | StmtKind::Step { .. } => self.simple(s).append(";"),
            StmtKind::If { cond, then, otherwise } => self.if_stmt(cond, then, otherwise.as_deref()),
            StmtKind::For { init, cond, step, body } => {
                let mut head = self.arena.text("for (");
                if let Some(init) = init {
                    head = head.append(self.simple(init));
                }
                head = head.append(";");
                if let Some(cond) = cond {
                    head = head.append(" ").append(self.expr(cond));
                }
                head = head.append(";");
                if let Some(step) = step {
                    head = head.append(" ").append(self.simple(step));
                }
                head.append(")").append(self.body(body))
            }
            StmtKind::Block(b) => self.block(b),
            StmtKind::Refine => self.arena.text("refine;"),
            StmtKind::Return(None) => self.arena.text("return;"),
            StmtKind::Return(Some(e)) => self.arena.text("return ").append(self.expr(e)).append(";"),
            StmtKind::Break => self.arena.text("break;"),
            StmtKind::Continue => self.arena.text("continue;"),
        }
    }

    /// `if (cond) then` and its `else`: `} else` after a block, `else` on a
    /// line of its own after a statement; `else if` stays on one line.
    fn if_stmt(&mut self, cond: &Expr, then: &Stmt, otherwise: Option<&Stmt>) -> Doc<'a> {
        let then_doc = if otherwise.is_none() { self.jump_body(then) } else { None };
        let then_doc = then_doc.unwrap_or_else(|| self.body(then));
        let mut doc = self.arena.text("if (").append(self.expr(cond)).append(")").append(then_doc);
        if let Some(otherwise) = otherwise {
            doc = if matches!(then.kind, StmtKind::Block(_)) {
                doc.append(" else")
            } else {
                doc.append(self.hardline()).append("else")
            };
            doc = match &otherwise.kind {
                StmtKind::If { .. } => {
                    let comments = self.inline(lo(otherwise.span));
                    doc.append(" ").append(comments).append(self.stmt(otherwise))
                }
                _ => doc.append(self.body(otherwise)),
            };
        }
        doc
    }

    /// The body of an `if`, an `else` or a `for`: a block on the same line,
    /// any other statement on the next, one level in.
    fn body(&mut self, s: &Stmt) -> Doc<'a> {
        match &s.kind {
            StmtKind::Block(b) => {
                let comments = self.inline(lo(s.span));
                self.arena.text(" ").append(comments).append(self.block(b))
            }
            _ => {
                let (leading, _) = self.leading(lo(s.span), true);
                let stmt = self.stmt(s);
                let trailing = self.trailing(self.trivia.after_semi(hi(s.span)));
                self.hardline().append(leading).append(stmt).append(trailing).nest(4)
            }
        }
    }

    /// The body of an `if` without `else` that only jumps (`refine;`,
    /// `break;`, `continue;`, `return ...;`): on the `if`'s line when it fits
    /// there, mrsl's idiom `if (fwidth(x) > t) refine;`; else on the next
    /// line as [`Printer::body`] puts it. `None` for any other body, or one
    /// with comments before it.
    fn jump_body(&mut self, s: &Stmt) -> Option<Doc<'a>> {
        let jumps = matches!(s.kind, StmtKind::Refine | StmtKind::Break | StmtKind::Continue | StmtKind::Return(_));
        if !jumps || self.trivia.comments.get(self.next).is_some_and(|c| c.start < lo(s.span)) {
            return None;
        }
        let stmt = self.stmt(s);
        let trailing = self.trailing(self.trivia.after_semi(hi(s.span)));
        Some(self.arena.line().append(stmt).append(trailing).nest(4).group())
    }

    /// A statement that can stand in a `for` header, without its `;`.
    fn simple(&mut self, s: &Stmt) -> Doc<'a> {
        match &s.kind {
            StmtKind::Local { ty, name, init } => {
                let doc = self.words(&[&ty.name, &name.name]);
                match init {
                    Some(e) => doc.append(" = ").append(self.expr(e)),
                    None => doc,
                }
            }
            StmtKind::Assign { target, op, value } => {
                let op = match op {
                    AssignOp::Set => " = ",
                    AssignOp::Add => " += ",
                    AssignOp::Sub => " -= ",
                    AssignOp::Mul => " *= ",
                    AssignOp::Div => " /= ",
                };
                self.expr(target).append(op).append(self.expr(value))
            }
            StmtKind::Step { target, increment } => {
                // `++x` or `x++` as written: the tree does not tell them apart.
                let op = if *increment { "++" } else { "--" };
                if self.source[lo(s.span)..].starts_with(op) {
                    self.arena.text(op).append(self.expr(target))
                } else {
                    self.expr(target).append(op)
                }
            }
            // The grammar allows nothing else in a `for` header.
            _ => self.stmt(s),
        }
    }
}
