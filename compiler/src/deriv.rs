//! Derivative analysis: how each `ddx`/`ddy`/`fwidth`/`sample` operand is
//! recomputed at the neighbouring sample.
//!
//! Compute shaders have no hardware quads, so a derivative is computed by
//! evaluating its operand again at the neighbour of the 2x2 quad (B pixels
//! away at coarse rate, one pixel at fine rate). The operand is rebuilt from
//! what can be evaluated anywhere: G-buffer inputs (loaded at the neighbour),
//! uniforms, constants, other effects (their value at the neighbour), pure
//! functions, and locals. A local is either *invariant* (its value does not
//! depend on the sample position, like a loop counter: passed as it is) or
//! *single-definition* (assigned exactly once, outside any branch or loop:
//! its defining expression is inlined). Any other local is an error, with
//! the same spirit as hardware's "derivatives need uniform control flow".

use crate::check::{Callee, Checked, EffectId, LocalId, Symbol};
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;
use std::collections::{BTreeSet, HashMap};

/// How one derivative site is recomputed at a neighbour.
#[derive(Debug, Clone)]
pub struct DerivSite<'a> {
    pub effect: EffectId,
    pub call: NodeId,
    /// The expression that is differentiated (for `sample`, the uv argument).
    pub operand: &'a Expr,
    /// Invariant locals the operand reads; passed as arguments.
    pub params: Vec<LocalId>,
    /// Effects the operand reads (directly or through inlined locals): needed at the neighbour.
    pub effects: Vec<EffectId>,
}

/// Per-program derivative information.
#[derive(Debug, Default)]
pub struct DerivInfo<'a> {
    pub sites: Vec<DerivSite<'a>>,
    /// Site index of each derivative call expression.
    pub site_of: HashMap<NodeId, usize>,
    /// Defining expression of each single-definition local (inlined at neighbours).
    pub definitions: HashMap<LocalId, &'a Expr>,
    /// Effects whose value is needed at a neighbour (by some operand), in any order.
    pub effects_at_neighbours: BTreeSet<EffectId>,
}

pub fn analyse<'a>(checked: &Checked<'a>) -> (DerivInfo<'a>, Vec<Diagnostic>) {
    let mut info = DerivInfo::default();
    let mut diagnostics = vec![];
    let program = checked.program;
    let mut effect_index = 0u32;
    for item in &program.items {
        let Item::Effect(effect) = item else { continue };
        let id = EffectId(effect_index);
        effect_index += 1;
        if !checked.derivative_calls.iter().any(|(e, _)| *e == id) {
            continue;
        }
        let body: Vec<&Stmt> = match &effect.body {
            EffectBody::Block(b) => b.stmts.iter().collect(),
            EffectBody::Expr(_) => vec![],
        };
        let facts = LocalFacts::compute(checked, &body);
        for (k, v) in &facts.definitions {
            info.definitions.insert(*k, v);
        }
        let mut calls = vec![];
        match &effect.body {
            EffectBody::Expr(e) => collect_derivative_calls(e, checked, &mut calls),
            EffectBody::Block(b) => b
                .stmts
                .iter()
                .for_each(|s| stmt_calls(s, checked, &mut calls)),
        }
        for call in calls {
            let ExprKind::Call { callee, args } = &call.kind else {
                continue;
            };
            let operand = if callee.name == "sample" {
                &args[2]
            } else {
                &args[0]
            };
            let mut params = BTreeSet::new();
            let mut visiting = vec![];
            let mut effects = BTreeSet::new();
            check_operand(
                checked,
                &facts,
                operand,
                callee,
                &mut params,
                &mut visiting,
                &mut effects,
                &mut diagnostics,
            );
            info.effects_at_neighbours.extend(effects.iter().copied());
            info.site_of.insert(call.id, info.sites.len());
            info.sites.push(DerivSite {
                effect: id,
                call: call.id,
                operand,
                params: params.into_iter().collect(),
                effects: effects.into_iter().collect(),
            });
        }
    }
    (info, diagnostics)
}

fn collect_derivative_calls<'a>(e: &'a Expr, checked: &Checked, out: &mut Vec<&'a Expr>) {
    visit_expr(e, &mut |x| {
        if let ExprKind::Call { callee, .. } = &x.kind {
            if matches!(checked.callees.get(&x.id), Some(Callee::Builtin(b)) if crate::check::is_derivative(b))
            {
                let _ = callee;
                out.push(x);
            }
        }
    });
}

fn stmt_calls<'a>(s: &'a Stmt, checked: &Checked, out: &mut Vec<&'a Expr>) {
    visit_stmt_exprs(s, &mut |e| collect_derivative_calls(e, checked, out));
}

/// Calls `f` on every top-level expression of a statement (recursively through sub-statements).
pub fn visit_stmt_exprs<'a>(s: &'a Stmt, f: &mut dyn FnMut(&'a Expr)) {
    match &s.kind {
        StmtKind::Local { init, .. } => init.iter().for_each(|e| f(e)),
        StmtKind::Assign { target, value, .. } => {
            f(target);
            f(value);
        }
        StmtKind::Step { target, .. } => f(target),
        StmtKind::If {
            cond,
            then,
            otherwise,
        } => {
            f(cond);
            visit_stmt_exprs(then, f);
            if let Some(o) = otherwise {
                visit_stmt_exprs(o, f);
            }
        }
        StmtKind::For {
            init,
            cond,
            step,
            body,
        } => {
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
        StmtKind::Return(e) => e.iter().for_each(|e| f(e)),
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

/// What is known about the locals of one effect body.
struct LocalFacts<'a> {
    invariant: HashMap<LocalId, bool>,
    definitions: HashMap<LocalId, &'a Expr>,
    assignment_count: HashMap<LocalId, u32>,
}

impl<'a> LocalFacts<'a> {
    fn compute(checked: &Checked<'a>, body: &[&'a Stmt]) -> Self {
        let mut facts = LocalFacts {
            invariant: HashMap::new(),
            definitions: HashMap::new(),
            assignment_count: HashMap::new(),
        };
        // Single definitions: declared with an initialiser and never assigned,
        // or declared without one and assigned once at the top level.
        let mut all = vec![];
        for s in body {
            collect_assignments(s, checked, &mut all, false);
        }
        for (local, _, _) in &all {
            *facts.assignment_count.entry(*local).or_default() += 1;
        }
        for (local, value, nested) in &all {
            if facts.assignment_count[local] == 1 && !nested {
                if let Some(v) = value {
                    facts.definitions.insert(*local, *v);
                }
            }
        }
        // Invariance: a fixed point, starting from "everything is invariant".
        for (local, _, _) in &all {
            facts.invariant.insert(*local, true);
        }
        loop {
            let mut changed = false;
            for s in body {
                changed |= facts.mark_varying(s, checked, false);
            }
            if !changed {
                break;
            }
        }
        facts
    }

    fn is_invariant(&self, local: LocalId) -> bool {
        self.invariant.get(&local).copied().unwrap_or(false)
    }

    fn expr_invariant(&self, e: &Expr, checked: &Checked) -> bool {
        let mut invariant = true;
        visit_expr(e, &mut |x| match &x.kind {
            ExprKind::Name(_) => match checked.symbols.get(&x.id) {
                Some(Symbol::Uniform(_) | Symbol::Const(_)) => {}
                Some(Symbol::Local(l)) if self.is_invariant(*l) => {}
                _ => invariant = false,
            },
            ExprKind::Call { .. } if matches!(checked.callees.get(&x.id), Some(Callee::Builtin(b)) if crate::check::is_derivative(b)) => {
                invariant = false
            }
            _ => {}
        });
        invariant
    }

    /// Marks locals assigned from varying values or under varying control flow.
    fn mark_varying(&mut self, s: &Stmt, checked: &Checked, varying_flow: bool) -> bool {
        let mut changed = false;
        let mut mark = |facts: &mut Self, local: LocalId| {
            if facts.invariant.insert(local, false) != Some(false) {
                changed = true;
            }
        };
        match &s.kind {
            StmtKind::Local { init, .. } => {
                if let Some(local) = checked.local_decls.get(&s.id) {
                    let v = varying_flow
                        || init
                            .as_ref()
                            .is_some_and(|e| !self.expr_invariant(e, checked));
                    if v {
                        mark(self, *local);
                    }
                }
            }
            StmtKind::Assign { target, value, .. } => {
                if let Some(local) = root_local(target, checked) {
                    if varying_flow
                        || !self.expr_invariant(value, checked)
                        || !self.expr_invariant(target, checked)
                    {
                        mark(self, local);
                    }
                }
            }
            StmtKind::Step { target, .. } => {
                if let Some(local) = root_local(target, checked) {
                    if varying_flow {
                        mark(self, local);
                    }
                }
            }
            StmtKind::If {
                cond,
                then,
                otherwise,
            } => {
                let v = varying_flow || !self.expr_invariant(cond, checked);
                changed |= self.mark_varying(then, checked, v);
                if let Some(o) = otherwise {
                    changed |= self.mark_varying(o, checked, v);
                }
            }
            StmtKind::For {
                init,
                cond,
                step,
                body,
            } => {
                let v = varying_flow
                    || cond
                        .as_ref()
                        .is_some_and(|c| !self.expr_invariant(c, checked));
                if let Some(i) = init {
                    changed |= self.mark_varying(i, checked, varying_flow);
                }
                if let Some(st) = step {
                    changed |= self.mark_varying(st, checked, v);
                }
                changed |= self.mark_varying(body, checked, v);
            }
            StmtKind::Block(b) => {
                for s in &b.stmts {
                    changed |= self.mark_varying(s, checked, varying_flow);
                }
            }
            _ => {}
        }
        changed
    }
}

fn root_local(e: &Expr, checked: &Checked) -> Option<LocalId> {
    match &e.kind {
        ExprKind::Name(_) => match checked.symbols.get(&e.id) {
            Some(Symbol::Local(l)) => Some(*l),
            _ => None,
        },
        ExprKind::Field { base, .. } | ExprKind::Index { base, .. } => root_local(base, checked),
        _ => None,
    }
}

/// Every assignment in `s`: (local, its value if a whole-variable `=`, nested in a branch/loop).
fn collect_assignments<'a>(
    s: &'a Stmt,
    checked: &Checked,
    out: &mut Vec<(LocalId, Option<&'a Expr>, bool)>,
    nested: bool,
) {
    match &s.kind {
        StmtKind::Local { init, .. } => {
            if let (Some(local), Some(init)) = (checked.local_decls.get(&s.id), init) {
                out.push((*local, Some(init), nested));
            }
        }
        StmtKind::Assign { target, op, value } => {
            if let Some(local) = root_local(target, checked) {
                let whole = matches!(target.kind, ExprKind::Name(_)) && *op == AssignOp::Set;
                out.push((local, if whole { Some(value) } else { None }, nested));
            }
        }
        StmtKind::Step { target, .. } => {
            if let Some(local) = root_local(target, checked) {
                out.push((local, None, nested));
            }
        }
        StmtKind::If {
            then, otherwise, ..
        } => {
            collect_assignments(then, checked, out, true);
            if let Some(o) = otherwise {
                collect_assignments(o, checked, out, true);
            }
        }
        StmtKind::For {
            init, step, body, ..
        } => {
            if let Some(i) = init {
                collect_assignments(i, checked, out, true);
            }
            if let Some(st) = step {
                collect_assignments(st, checked, out, true);
            }
            collect_assignments(body, checked, out, true);
        }
        StmtKind::Block(b) => b
            .stmts
            .iter()
            .for_each(|s| collect_assignments(s, checked, out, nested)),
        _ => {}
    }
}

#[allow(clippy::too_many_arguments)]
fn check_operand(
    checked: &Checked,
    facts: &LocalFacts,
    e: &Expr,
    callee: &Ident,
    params: &mut BTreeSet<LocalId>,
    visiting: &mut Vec<LocalId>,
    effects: &mut BTreeSet<EffectId>,
    diagnostics: &mut Vec<Diagnostic>,
) {
    visit_expr(e, &mut |x| {
        if let ExprKind::Name(name) = &x.kind {
            match checked.symbols.get(&x.id) {
                Some(Symbol::Effect(id)) => {
                    effects.insert(*id);
                }
                Some(Symbol::Local(local)) => {
                    if facts.is_invariant(*local) {
                        params.insert(*local);
                    } else if let Some(def) = facts.definitions.get(local) {
                        if visiting.contains(local) {
                            return;
                        }
                        visiting.push(*local);
                        check_operand(
                            checked,
                            facts,
                            def,
                            callee,
                            params,
                            visiting,
                            effects,
                            diagnostics,
                        );
                        visiting.pop();
                    } else {
                        let decl = checked.locals[local.index()].span;
                        diagnostics.push(
                            Diagnostic::error("E0503", format!("`{}` cannot differentiate `{name}`", callee.name))
                                .with_label(Label::primary(x.span, format!("`{name}` cannot be recomputed at the neighbouring sample")))
                                .with_label(Label::secondary(decl, "declared here"))
                                .with_note(format!(
                                    "a derivative re-evaluates its operand at the neighbouring sample; `{name}` is assigned more than once or inside a branch or loop. \
                                     Assign it exactly once, where it is declared, or differentiate the expression it is built from"
                                )),
                        );
                    }
                }
                _ => {}
            }
        }
    });
}
