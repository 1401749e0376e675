//! Read-only walks over the AST, shared by every stage that looks for some
//! kind of expression (the checker's constant test, the derivative analysis,
//! the code generator's input scan).
//!
//! They live with the tree rather than with any one stage, so that no stage
//! imports another for them: the checker does not depend on the derivative
//! analysis, which only reads the checker's results.

use super::ast::{Expr, ExprKind, Stmt, StmtKind};

/// Calls `f` on every top-level expression of a statement (recursively through sub-statements).
pub fn visit_stmt_exprs<'a>(s: &'a Stmt, f: &mut dyn FnMut(&'a Expr)) {
    match &s.kind {
        StmtKind::Local { init: Some(e), .. } | StmtKind::Return(Some(e)) => f(e),
        StmtKind::Local { init: None, .. } | StmtKind::Return(None) => {}
        StmtKind::Assign { target, value, .. } => {
            f(target);
            f(value);
        }
        StmtKind::Step { target, .. } => f(target),
        StmtKind::If { cond, then, otherwise } => {
            f(cond);
            visit_stmt_exprs(then, f);
            if let Some(o) = otherwise {
                visit_stmt_exprs(o, f);
            }
        }
        StmtKind::For { init, cond, step, body } => {
            if let Some(i) = init {
                visit_stmt_exprs(i, f);
            }
            if let Some(c) = cond {
                f(c);
            }
            if let Some(st) = step {
                visit_stmt_exprs(st, f);
            }
            visit_stmt_exprs(body, f);
        }
        StmtKind::Block(b) => b.stmts.iter().for_each(|s| visit_stmt_exprs(s, f)),
        StmtKind::Refine | StmtKind::Break | StmtKind::Continue => {}
    }
}

/// Visits an expression and all its sub-expressions, parents first.
pub fn visit_expr<'a>(e: &'a Expr, f: &mut dyn FnMut(&'a Expr)) {
    f(e);
    match &e.kind {
        ExprKind::Unary(_, a) => visit_expr(a, f),
        ExprKind::Binary(_, a, b) => {
            visit_expr(a, f);
            visit_expr(b, f);
        }
        ExprKind::Ternary(a, b, c) => {
            visit_expr(a, f);
            visit_expr(b, f);
            visit_expr(c, f);
        }
        ExprKind::Call { args, .. } => args.iter().for_each(|a| visit_expr(a, f)),
        ExprKind::Field { base, .. } => visit_expr(base, f),
        ExprKind::Index { base, index } => {
            visit_expr(base, f);
            visit_expr(index, f);
        }
        _ => {}
    }
}
