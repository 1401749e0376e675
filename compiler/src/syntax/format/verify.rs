//! The formatter's own check: the formatted text parses to the input's tree
//! (spans aside) and holds the input's comments.

use super::trivia::Trivia;
use crate::syntax::ast::*;

/// `Err` with what differs when `formatted` is not the program `original`
/// with the comments `comments`.
pub fn same_program(original: &Program, comments: &[String], formatted: &str) -> Result<(), String> {
    let reparsed = crate::syntax::parse(formatted).map_err(|d| format!("the result does not parse ({})", d.message))?;
    let (mut a, mut b) = (original.clone(), reparsed);
    erase_program(&mut a);
    erase_program(&mut b);
    if a != b {
        return Err("the result is another program".into());
    }
    let mut before: Vec<String> = comments.iter().map(|c| normal(c)).collect();
    let mut after: Vec<String> = Trivia::scan(formatted).comments.iter().map(|c| normal(c.text)).collect();
    before.sort();
    after.sort();
    if before != after {
        return Err("a comment was lost or changed".into());
    }
    Ok(())
}

/// A comment as the formatter may change it: without trailing whitespace.
pub fn normal(comment: &str) -> String {
    comment.lines().map(str::trim_end).collect::<Vec<_>>().join("\n")
}

const NOWHERE: Span = Span { start: 0, end: 0 };

fn erase_program(program: &mut Program) {
    for item in &mut program.items {
        match item {
            Item::Input(d) => {
                erase_attrs(&mut d.attrs);
                (d.span, d.ty.span, d.name.span) = (NOWHERE, NOWHERE, NOWHERE);
            }
            Item::Uniform(d) => {
                erase_attrs(&mut d.attrs);
                (d.span, d.ty.span, d.name.span) = (NOWHERE, NOWHERE, NOWHERE);
                d.array_len.iter_mut().chain(&mut d.default).for_each(erase_expr);
                if let Some(elements) = &mut d.elements {
                    elements.span = NOWHERE;
                    elements.items.iter_mut().for_each(erase_expr);
                }
            }
            Item::Const(d) => {
                (d.span, d.ty.span, d.name.span) = (NOWHERE, NOWHERE, NOWHERE);
                erase_expr(&mut d.value);
            }
            Item::Function(d) => {
                (d.span, d.ret.span, d.name.span) = (NOWHERE, NOWHERE, NOWHERE);
                for p in &mut d.params {
                    (p.ty.span, p.name.span) = (NOWHERE, NOWHERE);
                }
                erase_block(&mut d.body);
            }
            Item::Effect(d) => {
                erase_attrs(&mut d.attrs);
                (d.span, d.rate_span, d.ty.span, d.name.span) = (NOWHERE, NOWHERE, NOWHERE, NOWHERE);
                if let Some((_, span)) = &mut d.coarse_block {
                    *span = NOWHERE;
                }
                match &mut d.body {
                    EffectBody::Expr(e) => erase_expr(e),
                    EffectBody::Block(b) => erase_block(b),
                }
            }
        }
    }
}

fn erase_attrs(attrs: &mut [Attribute]) {
    for a in attrs {
        (a.span, a.name.span) = (NOWHERE, NOWHERE);
        a.args.iter_mut().for_each(erase_expr);
    }
}

fn erase_block(b: &mut Block) {
    b.span = NOWHERE;
    b.stmts.iter_mut().for_each(erase_stmt);
}

fn erase_stmt(s: &mut Stmt) {
    s.span = NOWHERE;
    match &mut s.kind {
        StmtKind::Local { ty, name, init } => {
            (ty.span, name.span) = (NOWHERE, NOWHERE);
            init.iter_mut().for_each(erase_expr);
        }
        StmtKind::Assign { target, value, .. } => {
            erase_expr(target);
            erase_expr(value);
        }
        StmtKind::Step { target, .. } => erase_expr(target),
        StmtKind::If { cond, then, otherwise } => {
            erase_expr(cond);
            erase_stmt(then);
            otherwise.iter_mut().for_each(|s| erase_stmt(s));
        }
        StmtKind::For { init, cond, step, body } => {
            init.iter_mut().chain(step.iter_mut()).for_each(|s| erase_stmt(s));
            cond.iter_mut().for_each(erase_expr);
            erase_stmt(body);
        }
        StmtKind::Block(b) => erase_block(b),
        StmtKind::Return(e) => e.iter_mut().for_each(erase_expr),
        StmtKind::Refine | StmtKind::Break | StmtKind::Continue => {}
    }
}

fn erase_expr(e: &mut Expr) {
    e.span = NOWHERE;
    match &mut e.kind {
        ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) | ExprKind::Name(_) => {}
        ExprKind::Unary(_, a) => erase_expr(a),
        ExprKind::Binary(_, a, b) | ExprKind::Index { base: a, index: b } => {
            erase_expr(a);
            erase_expr(b);
        }
        ExprKind::Ternary(a, b, c) => {
            erase_expr(a);
            erase_expr(b);
            erase_expr(c);
        }
        ExprKind::Call { callee, args } => {
            callee.span = NOWHERE;
            args.iter_mut().for_each(erase_expr);
        }
        ExprKind::Field { base, field } => {
            field.span = NOWHERE;
            erase_expr(base);
        }
    }
}
