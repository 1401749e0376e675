//! Static loop bounds. A GPU has no way to stop a runaway loop but its
//! watchdog, so every `for` must have a shape whose trip count is known at
//! compile time, and that count must be modest.

use super::{Checker, err};
use crate::diagnostic::Label;
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};

/// Loops may run at most this many times (a GPU watchdog would stop longer ones).
const MAX_LOOP_TRIPS: u64 = 1 << 16;

impl Checker<'_> {
    /// Loops must have the form `for (T i = c0; i OP c1; i++ | i-- | i += c | i -= c)`
    /// with constant `c`s (the condition may add a dynamic limit:
    /// [`Checker::static_comparison`]), and must not assign `i` in the body, so
    /// that the compiler (and the GPU's watchdog) can rely on a bounded trip count.
    pub(super) fn check_static_bound(
        &mut self,
        s: &Stmt,
        init: Option<&Stmt>,
        cond: Option<&Expr>,
        step: Option<&Stmt>,
        body: &Stmt,
    ) {
        let Some(var) = self.loop_counter(s, init) else { return };
        if !self.loop_condition_is_static(s, &var, cond) || !self.loop_step_is_static(s, &var, step) {
            return;
        }
        if !self.loop_trips_are_bounded(s, &var, init, cond, step) {
            return;
        }
        if let Some(span) = stmt_assigns_name(body, &var) {
            self.error(
                err(
                    "E0401",
                    "loop has no static bound",
                    span,
                    format!("the loop variable `{var}` is assigned in the body"),
                )
                .with_label(Label::secondary(init.map(|i| i.span).unwrap_or(s.span), "declared here")),
            );
        }
    }

    /// The loop's counter: an `int` or `uint` declared with a constant start
    /// value (else an error, and none).
    fn loop_counter(&mut self, s: &Stmt, init: Option<&Stmt>) -> Option<String> {
        let Some(StmtKind::Local { name, init: Some(v), ty }) = init.map(|i| &i.kind) else {
            self.error(
                err("E0401", "loop has no static bound", s.span, "expected `for (int i = START; i < END; i++)`")
                    .with_note("the loop must declare its counter with a constant start value"),
            );
            return None;
        };
        if self.const_eval(v).is_none() {
            self.error(err("E0401", "loop has no static bound", v.span, "the start value must be a constant"));
            return None;
        }
        if !matches!(Type::from_name(&ty.name), Some(Type::Scalar(Scalar::Int | Scalar::Uint))) {
            self.error(err(
                "E0401",
                "loop has no static bound",
                ty.span,
                "the loop variable must be an `int` or `uint`",
            ));
            return None;
        }
        Some(name.name.clone())
    }

    /// Whether the condition compares the counter with a constant (else an error).
    fn loop_condition_is_static(&mut self, s: &Stmt, var: &str, cond: Option<&Expr>) -> bool {
        match cond.and_then(|c| self.static_comparison(var, c)) {
            Some(_) => true,
            None => {
                let compared = cond.and_then(|c| comparison(var, c));
                let (span, label) = match compared {
                    Some((_, _, b)) => (b.span, "not a constant".to_string()),
                    None => (
                        cond.map(|c| c.span).unwrap_or(s.span),
                        format!("expected `{var} < CONSTANT` (or <=, >, >=, !=)"),
                    ),
                };
                self.error(err("E0401", "loop has no static bound", span, label).with_note(format!(
                    "give the loop a constant bound beside the dynamic one: `{var} < 16 && {var} < count`, \
                     `{var} < min(count, 16)`, or test the dynamic one inside: `if ({var} >= count) break;`"
                )));
                false
            }
        }
    }

    /// The comparison of the counter with a constant that bounds the loop, as
    /// (operator, whether the counter is on the left, the constant): the
    /// condition itself (`i < 16`); either side of an `&&` (`i < 16 && i <
    /// count`: the other side may be anything, a dynamic limit); or a `min`
    /// (`max` counting down) of a constant and anything (`i < min(count, 16)`
    /// is bounded by `i < 16`). The loop runs at most as often as that
    /// comparison lets it, which is what the trip count and the cost model need.
    fn static_comparison<'e>(&mut self, var: &str, cond: &'e Expr) -> Option<(BinaryOp, bool, &'e Expr)> {
        if let ExprKind::Binary(BinaryOp::And, a, b) = &cond.kind {
            return self.static_comparison(var, a).or_else(|| self.static_comparison(var, b));
        }
        let (op, var_left, bound) = comparison(var, cond)?;
        if self.const_eval(bound).is_some() {
            return Some((op, var_left, bound));
        }
        // Below the smaller of two values (above the larger): below the constant one.
        let below =
            matches!((op, var_left), (BinaryOp::Lt | BinaryOp::Le, true) | (BinaryOp::Gt | BinaryOp::Ge, false));
        let above =
            matches!((op, var_left), (BinaryOp::Gt | BinaryOp::Ge, true) | (BinaryOp::Lt | BinaryOp::Le, false));
        match &bound.kind {
            ExprKind::Call { callee, args }
                if args.len() == 2 && ((below && callee.name == "min") || (above && callee.name == "max")) =>
            {
                let constant = args.iter().find(|a| self.const_eval(a).is_some())?;
                Some((op, var_left, constant))
            }
            _ => None,
        }
    }

    /// Whether the step moves the counter by a constant (else an error).
    fn loop_step_is_static(&mut self, s: &Stmt, var: &str, step: Option<&Stmt>) -> bool {
        let is_var = |e: &Expr| matches!(&e.kind, ExprKind::Name(n) if n == var);
        let step_ok = match step.map(|st| &st.kind) {
            Some(StmtKind::Step { target, .. }) => is_var(target),
            Some(StmtKind::Assign { target, op: AssignOp::Add | AssignOp::Sub, value }) => {
                is_var(target) && self.const_eval(value).is_some()
            }
            _ => false,
        };
        if !step_ok {
            let span = step.map(|st| st.span).unwrap_or(s.span);
            self.error(err(
                "E0401",
                "loop has no static bound",
                span,
                format!("expected `{var}++`, `{var}--` or `{var} += CONSTANT`"),
            ));
        }
        step_ok
    }

    /// With the shape right, whether the trip count is at most
    /// [`MAX_LOOP_TRIPS`] (else an error); records the count.
    fn loop_trips_are_bounded(
        &mut self,
        s: &Stmt,
        var: &str,
        init: Option<&Stmt>,
        cond: Option<&Expr>,
        step: Option<&Stmt>,
    ) -> bool {
        let start = match init.map(|i| &i.kind) {
            Some(StmtKind::Local { init: Some(v), .. }) => self.const_eval(v).map(|c| c.values[0]),
            _ => None,
        };
        let (op, var_left, limit) = match cond.and_then(|c| self.static_comparison(var, c)) {
            Some((op, var_left, bound)) => (op, var_left, self.const_eval(bound).map(|c| c.values[0])),
            None => (BinaryOp::Lt, true, None),
        };
        let delta = match step.map(|st| &st.kind) {
            Some(StmtKind::Step { increment, .. }) => Some(if *increment { 1.0 } else { -1.0 }),
            Some(StmtKind::Assign { op: AssignOp::Add, value, .. }) => self.const_eval(value).map(|c| c.values[0]),
            Some(StmtKind::Assign { op: AssignOp::Sub, value, .. }) => self.const_eval(value).map(|c| -c.values[0]),
            _ => None,
        };
        let (Some(mut i), Some(limit), Some(delta)) = (start, limit, delta) else { return true };
        let holds = |i: f64| {
            let (x, y) = if var_left { (i, limit) } else { (limit, i) };
            match op {
                BinaryOp::Lt => x < y,
                BinaryOp::Le => x <= y,
                BinaryOp::Gt => x > y,
                BinaryOp::Ge => x >= y,
                _ => x != y,
            }
        };
        let mut trips = 0u64;
        while holds(i) && trips <= MAX_LOOP_TRIPS {
            i += delta;
            trips += 1;
        }
        if trips <= MAX_LOOP_TRIPS {
            self.out.loop_trips.insert(s.id, trips);
            return true;
        }
        self.error(
            err(
                "E0402",
                "loop does not terminate within the iteration limit",
                s.span,
                format!("runs more than {MAX_LOOP_TRIPS} times"),
            )
            .with_note("check the direction of the step against the condition"),
        );
        false
    }
}

/// `cond` as a comparison of the counter `var` with something: (operator,
/// whether the counter is on the left, the other side).
fn comparison<'e>(var: &str, cond: &'e Expr) -> Option<(BinaryOp, bool, &'e Expr)> {
    let is_var = |e: &Expr| matches!(&e.kind, ExprKind::Name(n) if n == var);
    match &cond.kind {
        ExprKind::Binary(op @ (BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge | BinaryOp::Ne), a, b) => {
            if is_var(a) {
                Some((*op, true, b))
            } else if is_var(b) {
                Some((*op, false, a))
            } else {
                None
            }
        }
        _ => None,
    }
}

/// The span of a statement in `s` that assigns `name` (its root variable), if any.
fn stmt_assigns_name(s: &Stmt, name: &str) -> Option<Span> {
    fn root(e: &Expr) -> Option<&str> {
        match &e.kind {
            ExprKind::Name(n) => Some(n),
            ExprKind::Field { base, .. } | ExprKind::Index { base, .. } => root(base),
            _ => None,
        }
    }
    match &s.kind {
        StmtKind::Assign { target, .. } | StmtKind::Step { target, .. } if root(target) == Some(name) => Some(s.span),
        StmtKind::Local { name: n, .. } if n.name == name => None,
        StmtKind::Block(b) => {
            for s in &b.stmts {
                // A declaration of the same name shadows the loop variable from here on.
                if matches!(&s.kind, StmtKind::Local { name: n, .. } if n.name == name) {
                    return None;
                }
                if let Some(span) = stmt_assigns_name(s, name) {
                    return Some(span);
                }
            }
            None
        }
        StmtKind::If { then, otherwise, .. } => {
            stmt_assigns_name(then, name).or_else(|| otherwise.as_ref().and_then(|o| stmt_assigns_name(o, name)))
        }
        StmtKind::For { init, step, body, .. } => init
            .as_ref()
            .and_then(|i| stmt_assigns_name(i, name))
            .or_else(|| step.as_ref().and_then(|i| stmt_assigns_name(i, name)))
            .or_else(|| stmt_assigns_name(body, name)),
        _ => None,
    }
}
