//! Derivative analysis: how each `ddx`/`ddy`/`fwidth`/`sample` operand is
//! recomputed at the neighbouring sample.
//!
//! Compute shaders have no hardware quads, so a derivative is computed by
//! evaluating its operand again at the neighbour of the 2x2 quad (B pixels
//! away at coarse rate, one pixel at fine rate). The operand is rebuilt from
//! what can be evaluated anywhere: G-buffer inputs (loaded at the neighbour),
//! uniforms, constants, other effects (their value at the neighbour), pure
//! functions, and locals. A local is either
//!
//! - *invariant*: its value does not depend on the sample position (a loop
//!   counter, a sum of uniforms). It is passed to the neighbour as it is.
//!   Through an inlined definition it must still hold the value it had when
//!   that definition ran: it is assigned only where declared, or it is a loop
//!   counter (which the body cannot assign);
//! - *single-definition*: declared with an initialiser and never assigned
//!   again, or declared without one and assigned exactly once at the top
//!   level of the body before the derivative. Its defining expression is
//!   inlined.
//!
//! Any other local is an error (E0503), in the spirit of hardware's rule that
//! derivatives need uniform control flow.

use crate::check::{Callee, Checked, EffectId, LocalId, Symbol};
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;
use crate::syntax::{visit_expr, visit_stmt_exprs};
use std::collections::{BTreeSet, HashMap, HashSet};

/// How one derivative site is recomputed at a neighbour.
#[derive(Debug, Clone)]
pub struct DerivSite<'a> {
    pub effect: EffectId,
    /// The expression that is differentiated (for `sample`, the uv argument).
    pub operand: &'a Expr,
    /// Invariant locals the operand reads; passed as arguments.
    pub params: Vec<LocalId>,
    /// Effects the operand reads (directly or through inlined locals): needed at the neighbour.
    pub effects: Vec<EffectId>,
    /// The derivative call (its node and span) and its builtin
    /// (`ddx_surface` and its kin: [`crate::builtins::Builtin::on_surface`]).
    pub node: NodeId,
    pub call: Span,
    pub builtin: crate::builtins::Builtin,
    /// Whether the call sits in a statement that only decides the effect's
    /// refine flag ([`DerivInfo::value_skips`]): an evaluation for the value
    /// alone never runs it.
    pub decides_only: bool,
    /// For an operand that reads a local built by a loop, a branch or
    /// several assignments: the index of the top-level statement holding
    /// the call. At a neighbour the operand is the body's statements before
    /// it, run there, then the operand ([`liftable`]); `params` is then
    /// empty and `effects` holds what those statements read.
    pub prefix: Option<usize>,
}

/// Per-program derivative information.
#[derive(Debug, Default)]
pub struct DerivInfo<'a> {
    pub sites: Vec<DerivSite<'a>>,
    /// Site index of each derivative call expression.
    pub site_of: HashMap<NodeId, usize>,
    /// Defining expression of each single-definition local (inlined at neighbours).
    pub definitions: HashMap<LocalId, &'a Expr>,
    /// Effects whose value is needed at a neighbour (by some operand).
    pub effects_at_neighbours: BTreeSet<EffectId>,
    /// For each effect with a `refine` statement, the statements of its body
    /// that its value does not need (the `refine`s and whatever only decides
    /// them): a neighbour evaluation discards the refine flag, so it leaves
    /// them out (see [`value_skips`]).
    pub value_skips: HashMap<EffectId, HashSet<NodeId>>,
}

pub fn analyse<'a>(checked: &Checked<'a>) -> (DerivInfo<'a>, Vec<Diagnostic>) {
    let mut info = DerivInfo::default();
    let mut diagnostics = vec![];
    let program = checked.program;
    let mut effect_index = 0u32;
    let differentiating: HashSet<EffectId> = checked.derivative_calls.iter().map(|(e, _)| *e).collect();
    for item in &program.items {
        let Item::Effect(effect) = item else { continue };
        let id = EffectId(effect_index);
        effect_index += 1;
        let effect_info = &checked.effects[id.index()];
        if let (true, Some(result), EffectBody::Block(b)) = (effect_info.has_refine, effect_info.result, &effect.body) {
            info.value_skips.insert(id, value_skips(checked, result, &b.stmts));
        }
        if !differentiating.contains(&id) {
            continue;
        }
        let body: Vec<&Stmt> = match &effect.body {
            EffectBody::Block(b) => b.stmts.iter().collect(),
            EffectBody::Expr(_) => vec![],
        };
        let facts = LocalFacts::compute(checked, &body);
        for (k, (v, _)) in &facts.definitions {
            info.definitions.insert(*k, v);
        }
        // Derivative calls with the index of the top-level statement holding them.
        let mut calls: Vec<(usize, &Expr)> = vec![];
        match &effect.body {
            EffectBody::Expr(e) => collect_derivative_calls(e, checked, &mut |c| calls.push((0, c))),
            EffectBody::Block(b) => {
                for (index, s) in b.stmts.iter().enumerate() {
                    visit_stmt_exprs(s, &mut |e| collect_derivative_calls(e, checked, &mut |c| calls.push((index, c))));
                }
            }
        }
        for (statement, call) in calls {
            let ExprKind::Call { callee, args } = &call.kind else { continue };
            let Some(Callee::Builtin(builtin)) = checked.callees.get(&call.id) else { continue };
            // A call with the wrong arity was already reported by the checker.
            let Some(operand) = builtin.derivative_operand().and_then(|k| args.get(k)) else { continue };
            let mut walk = OperandWalk {
                checked,
                facts: &facts,
                callee,
                call: call.span,
                body: &body,
                rate: effect.rate,
                statement,
                params: BTreeSet::new(),
                effects: BTreeSet::new(),
                visiting: HashSet::new(),
                path: vec![],
                walked: HashSet::new(),
                reported: HashSet::new(),
                touched: BTreeSet::new(),
                unstable: vec![],
                other_errors: false,
                diagnostics: &mut diagnostics,
            };
            walk.expr(operand);
            let unstable = std::mem::take(&mut walk.unstable);
            let lift = !unstable.is_empty()
                && !walk.other_errors
                && liftable(checked, &body, statement, &walk.touched, &effect.body);
            let (mut params, mut effects) = (walk.params, walk.effects);
            let prefix = if lift {
                // The statements before the call are run at the neighbour: they
                // need no parameters, and the effects they read.
                params.clear();
                for s in &body[..statement] {
                    visit_stmt_exprs(s, &mut |e| effects.extend(effects_read(e, checked)));
                }
                Some(statement)
            } else {
                diagnostics.extend(unstable);
                None
            };
            info.effects_at_neighbours.extend(effects.iter().copied());
            info.site_of.insert(call.id, info.sites.len());
            info.sites.push(DerivSite {
                effect: id,
                operand,
                params: params.into_iter().collect(),
                effects: effects.into_iter().collect(),
                node: call.id,
                call: call.span,
                builtin: *builtin,
                decides_only: false,
                prefix,
            });
        }
    }
    mark_decides_only(&mut info, program);
    (info, diagnostics)
}

/// Sets [`DerivSite::decides_only`] on the derivative calls inside each
/// effect's skipped statements.
fn mark_decides_only(info: &mut DerivInfo, program: &Program) {
    let effects = program.items.iter().filter_map(|item| match item {
        Item::Effect(effect) => Some(effect),
        _ => None,
    });
    for (k, effect) in effects.enumerate() {
        let (Some(skips), EffectBody::Block(b)) = (info.value_skips.get(&EffectId(k as u32)), &effect.body) else {
            continue;
        };
        let mut inside = vec![];
        for s in &b.stmts {
            skipped_statements(s, skips, &mut inside);
        }
        let mut calls = vec![];
        for s in inside {
            visit_stmt_exprs(s, &mut |e| visit_expr(e, &mut |x| calls.extend(info.site_of.get(&x.id).copied())));
        }
        for site in calls {
            info.sites[site].decides_only = true;
        }
    }
}

/// The outermost statements of `s` (itself included) that are in `skips`.
fn skipped_statements<'s>(s: &'s Stmt, skips: &HashSet<NodeId>, out: &mut Vec<&'s Stmt>) {
    if skips.contains(&s.id) {
        out.push(s);
        return;
    }
    match &s.kind {
        StmtKind::If { then, otherwise, .. } => {
            skipped_statements(then, skips, out);
            if let Some(o) = otherwise {
                skipped_statements(o, skips, out);
            }
        }
        StmtKind::For { init, step, body, .. } => {
            for sub in [init.as_deref(), step.as_deref(), Some(body.as_ref())].into_iter().flatten() {
                skipped_statements(sub, skips, out);
            }
        }
        StmtKind::Block(b) => b.stmts.iter().for_each(|sub| skipped_statements(sub, skips, out)),
        _ => {}
    }
}

/// W0003 for each surface derivative (`fwidth_surface`, ...) that can only
/// be its plain form: in a fine effect or output, which is evaluated per
/// pixel, or in a coarse effect that reads no discontinuity key.
pub fn plain_surface_derivatives(
    checked: &Checked,
    graph: &crate::graph::EffectGraph,
    deriv: &DerivInfo,
) -> Vec<Diagnostic> {
    let mut out = vec![];
    for site in deriv.sites.iter().filter(|s| s.builtin.on_surface()) {
        let effect = &checked.effects[site.effect.index()];
        let why = if effect.rate != Rate::Coarse {
            format!("`{}` is evaluated per pixel, where the surface derivatives are the plain ones", effect.name)
        } else if graph.keys[site.effect.index()].is_empty() {
            format!("`{}` reads no discontinuity key, so no difference is taken across one", effect.name)
        } else {
            continue;
        };
        let (name, plain) = (site.builtin.name(), site.builtin.plain_derivative().name());
        out.push(
            Diagnostic::warning("W0003", format!("`{name}` here is `{plain}`"))
                .with_label(Label::primary(site.call, why))
                .with_note(
                    "a surface derivative differs from the plain one only at coarse rate, where the quad pair's \
                     other sample lies across one of the effect's discontinuity keys (docs/language.md, section 9)",
                ),
        );
    }
    out
}

/// Whether a derivative at top-level statement `statement` of a block body,
/// whose operand reads the locals `touched`, can take its operand at the
/// neighbouring sample by running the statements before it there: they
/// hold no `return` (which would end the body with its value) and no
/// derivative (which would differentiate at a neighbour of the neighbour),
/// and the statement itself declares and assigns none of `touched`, so the
/// operand reads at the call what it reads after them. Their `refine`s are
/// left out there: a neighbour evaluation discards the flag.
fn liftable(
    checked: &Checked,
    body: &[&Stmt],
    statement: usize,
    touched: &BTreeSet<LocalId>,
    effect_body: &EffectBody,
) -> bool {
    if !matches!(effect_body, EffectBody::Block(_)) {
        return false;
    }
    let mut derivatives = false;
    for s in &body[..statement] {
        visit_stmt_exprs(s, &mut |e| collect_derivative_calls(e, checked, &mut |_| derivatives = true));
    }
    !derivatives && !body[..statement].iter().any(|s| returns(s)) && !touches(body[statement], checked, touched)
}

/// Whether `s` holds a `return`.
fn returns(s: &Stmt) -> bool {
    match &s.kind {
        StmtKind::Return(_) => true,
        StmtKind::If { then, otherwise, .. } => returns(then) || otherwise.as_deref().is_some_and(returns),
        StmtKind::For { body, .. } => returns(body),
        StmtKind::Block(b) => b.stmts.iter().any(returns),
        _ => false,
    }
}

/// Whether `s` declares or assigns one of `locals`, at any depth.
fn touches(s: &Stmt, checked: &Checked, locals: &BTreeSet<LocalId>) -> bool {
    let hit = |l: Option<LocalId>| l.is_some_and(|l| locals.contains(&l));
    match &s.kind {
        StmtKind::Local { .. } => hit(checked.local_decls.get(&s.id).copied()),
        StmtKind::Assign { target, .. } | StmtKind::Step { target, .. } => hit(root_local(target, checked)),
        StmtKind::If { then, otherwise, .. } => {
            touches(then, checked, locals) || otherwise.as_deref().is_some_and(|o| touches(o, checked, locals))
        }
        StmtKind::For { init, step, body, .. } => [init.as_deref(), step.as_deref(), Some(body.as_ref())]
            .into_iter()
            .flatten()
            .any(|sub| touches(sub, checked, locals)),
        StmtKind::Block(b) => b.stmts.iter().any(|sub| touches(sub, checked, locals)),
        _ => false,
    }
}

/// The effects expression `e` reads.
fn effects_read(e: &Expr, checked: &Checked) -> Vec<EffectId> {
    let mut out = vec![];
    visit_expr(e, &mut |x| {
        if let (ExprKind::Name(_), Some(Symbol::Effect(id))) = (&x.kind, checked.symbols.get(&x.id)) {
            out.push(*id);
        }
    });
    out
}

fn collect_derivative_calls<'a>(e: &'a Expr, checked: &Checked, out: &mut dyn FnMut(&'a Expr)) {
    visit_expr(e, &mut |x| {
        if matches!(checked.callees.get(&x.id), Some(Callee::Builtin(b)) if b.is_derivative()) {
            out(x);
        }
    });
}

/// One assignment to a local, as collected from an effect body.
struct Assignment<'a> {
    local: LocalId,
    /// The value, for whole-variable `=` and declarations with an initialiser.
    value: Option<&'a Expr>,
    /// Inside a branch or loop.
    nested: bool,
    declaration: bool,
    for_init: bool,
    /// Index of the top-level statement it is in.
    statement: usize,
}

/// Where a single-definition local is defined: its top-level statement
/// (`None` when defined by its declaration, which scoping already orders).
type Definition<'a> = (&'a Expr, Option<usize>);

/// What is known about the locals of one effect body.
struct LocalFacts<'a> {
    invariant: HashMap<LocalId, bool>,
    definitions: HashMap<LocalId, Definition<'a>>,
    /// The top-level statement holding each single definition, declarations
    /// included: where an inlined definition reads the locals it names.
    defined_in: HashMap<LocalId, usize>,
    /// The top-level statements holding each local's assignments other than
    /// its declaration's initialiser and a loop's counter updates.
    assigned_in: HashMap<LocalId, Vec<usize>>,
    assignment_count: HashMap<LocalId, u32>,
    loop_counters: HashSet<LocalId>,
}

impl<'a> LocalFacts<'a> {
    fn compute(checked: &Checked<'a>, body: &[&'a Stmt]) -> Self {
        let mut facts = LocalFacts {
            invariant: HashMap::new(),
            definitions: HashMap::new(),
            defined_in: HashMap::new(),
            assigned_in: HashMap::new(),
            assignment_count: HashMap::new(),
            loop_counters: HashSet::new(),
        };
        let mut all = vec![];
        for (index, s) in body.iter().enumerate() {
            collect_assignments(s, checked, &mut all, false, index);
        }
        for a in &all {
            *facts.assignment_count.entry(a.local).or_default() += 1;
            if a.for_init {
                facts.loop_counters.insert(a.local);
            }
            if !a.declaration {
                facts.assigned_in.entry(a.local).or_default().push(a.statement);
            }
        }
        for a in &all {
            if facts.assignment_count[&a.local] != 1 {
                continue;
            }
            match (a.value, a.declaration, a.nested) {
                (Some(v), true, _) => {
                    facts.definitions.insert(a.local, (v, None));
                    facts.defined_in.insert(a.local, a.statement);
                }
                (Some(v), false, false) => {
                    facts.definitions.insert(a.local, (v, Some(a.statement)));
                    facts.defined_in.insert(a.local, a.statement);
                }
                _ => {}
            }
        }
        // Invariance: a fixed point, starting from "everything is invariant".
        for a in &all {
            facts.invariant.insert(a.local, true);
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

    /// An invariant local keeps its value from its declaration on.
    fn is_stable(&self, local: LocalId) -> bool {
        self.loop_counters.contains(&local) || self.assignment_count.get(&local).copied().unwrap_or(0) <= 1
    }

    /// Whether `local` may be assigned at or after top-level statement
    /// `at`, other than by its declaration or as a loop counter. A
    /// definition read there may then see an earlier value than the one a
    /// derivative later in the body sees (a local declared without an
    /// initialiser holds zero until its assignment). Statements are compared
    /// at the top level, so an assignment in the same top-level statement
    /// counts as after: conservative.
    fn assigned_from(&self, local: LocalId, at: usize) -> bool {
        !self.loop_counters.contains(&local) && self.assigned_in.get(&local).is_some_and(|s| s.iter().any(|&q| q >= at))
    }

    fn expr_invariant(&self, e: &Expr, checked: &Checked) -> bool {
        let mut invariant = true;
        visit_expr(e, &mut |x| match &x.kind {
            ExprKind::Name(_) => match checked.symbols.get(&x.id) {
                Some(Symbol::Uniform(_) | Symbol::Const(_)) => {}
                Some(Symbol::Local(l)) if self.is_invariant(*l) => {}
                _ => invariant = false,
            },
            ExprKind::Call { .. } if matches!(checked.callees.get(&x.id), Some(Callee::Builtin(b)) if b.is_derivative()) => {
                invariant = false
            }
            _ => {}
        });
        invariant
    }

    /// Whether a loop body may leave an iteration early depending on the position
    /// (a `break` or `continue` under a varying condition, outside nested loops).
    fn exits_on_varying(&self, s: &Stmt, checked: &Checked, varying: bool) -> bool {
        match &s.kind {
            StmtKind::Break | StmtKind::Continue => varying,
            StmtKind::If { cond, then, otherwise } => {
                let v = varying || !self.expr_invariant(cond, checked);
                self.exits_on_varying(then, checked, v)
                    || otherwise.as_ref().is_some_and(|o| self.exits_on_varying(o, checked, v))
            }
            StmtKind::Block(b) => b.stmts.iter().any(|s| self.exits_on_varying(s, checked, varying)),
            _ => false,
        }
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
                if let Some(local) = checked.local_decls.get(&s.id)
                    && (varying_flow || init.as_ref().is_some_and(|e| !self.expr_invariant(e, checked)))
                {
                    mark(self, *local);
                }
            }
            StmtKind::Assign { target, value, .. } => {
                if let Some(local) = root_local(target, checked)
                    && (varying_flow || !self.expr_invariant(value, checked) || !self.expr_invariant(target, checked))
                {
                    mark(self, local);
                }
            }
            StmtKind::Step { target, .. } => {
                if let Some(local) = root_local(target, checked)
                    && varying_flow
                {
                    mark(self, local);
                }
            }
            StmtKind::If { cond, then, otherwise } => {
                let v = varying_flow || !self.expr_invariant(cond, checked);
                changed |= self.mark_varying(then, checked, v);
                if let Some(o) = otherwise {
                    changed |= self.mark_varying(o, checked, v);
                }
            }
            StmtKind::For { init, cond, step, body } => {
                let v = varying_flow
                    || cond.as_ref().is_some_and(|c| !self.expr_invariant(c, checked))
                    || self.exits_on_varying(body, checked, false);
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

/// The local an assignment target writes (`x`, `x.y`, `x[i]`), if it is one.
pub(crate) fn root_local(e: &Expr, checked: &Checked) -> Option<LocalId> {
    match &e.kind {
        ExprKind::Name(_) => match checked.symbols.get(&e.id) {
            Some(Symbol::Local(l)) => Some(*l),
            _ => None,
        },
        ExprKind::Field { base, .. } | ExprKind::Index { base, .. } => root_local(base, checked),
        _ => None,
    }
}

fn collect_assignments<'a>(
    s: &'a Stmt,
    checked: &Checked,
    out: &mut Vec<Assignment<'a>>,
    nested: bool,
    statement: usize,
) {
    let mut push = |local, value, declaration, for_init| {
        out.push(Assignment { local, value, nested, declaration, for_init, statement })
    };
    match &s.kind {
        StmtKind::Local { init, .. } => {
            if let (Some(local), Some(init)) = (checked.local_decls.get(&s.id), init) {
                push(*local, Some(init), true, false);
            }
        }
        StmtKind::Assign { target, op, value } => {
            if let Some(local) = root_local(target, checked) {
                let whole = matches!(target.kind, ExprKind::Name(_)) && *op == AssignOp::Set;
                push(local, if whole { Some(value) } else { None }, false, false);
            }
        }
        StmtKind::Step { target, .. } => {
            if let Some(local) = root_local(target, checked) {
                push(local, None, false, false);
            }
        }
        StmtKind::If { then, otherwise, .. } => {
            collect_assignments(then, checked, out, true, statement);
            if let Some(o) = otherwise {
                collect_assignments(o, checked, out, true, statement);
            }
        }
        StmtKind::For { init, step, body, .. } => {
            if let Some(i) = init
                && let (StmtKind::Local { init: Some(v), .. }, Some(local)) = (&i.kind, checked.local_decls.get(&i.id))
            {
                out.push(Assignment {
                    local: *local,
                    value: Some(v),
                    nested: true,
                    declaration: true,
                    for_init: true,
                    statement,
                });
            }
            if let Some(st) = step {
                collect_assignments(st, checked, out, true, statement);
            }
            collect_assignments(body, checked, out, true, statement);
        }
        StmtKind::Block(b) => b.stmts.iter().for_each(|s| collect_assignments(s, checked, out, nested, statement)),
        _ => {}
    }
}

/// Walks a derivative operand, inlining single definitions and collecting
/// the invariant locals and effects it needs. The definitions are followed
/// depth-first with an explicit stack, each once: a chain of any length
/// neither recurses nor, when locals are read more than once, repeats work.
struct OperandWalk<'w, 'a> {
    checked: &'w Checked<'a>,
    facts: &'w LocalFacts<'a>,
    callee: &'w Ident,
    /// The derivative call, and the effect body and rate it is in (for diagnostics).
    call: Span,
    body: &'w [&'a Stmt],
    rate: Rate,
    /// Top-level statement holding the derivative.
    statement: usize,
    params: BTreeSet<LocalId>,
    effects: BTreeSet<EffectId>,
    /// Single-definition locals whose definition is being walked: the current path.
    visiting: HashSet<LocalId>,
    /// The same path in order, for diagnostics: the operand's own local first.
    path: Vec<LocalId>,
    /// Single-definition locals whose definition has been walked.
    walked: HashSet<LocalId>,
    reported: HashSet<LocalId>,
    /// Every local the operand reads, directly or through definitions.
    touched: BTreeSet<LocalId>,
    /// E0503 for the locals that cannot be rebuilt at the neighbour by
    /// inlining (built by a loop, a branch or several assignments): reported
    /// unless the body's statements before the call can be run there instead.
    unstable: Vec<Diagnostic>,
    /// Whether an error other than those was reported.
    other_errors: bool,
    diagnostics: &'w mut Vec<Diagnostic>,
}

/// A name read by an expression being walked: its span, text and symbol.
type NameRead = (Span, String, Option<Symbol>);

impl<'a> OperandWalk<'_, 'a> {
    /// Walks the operand `e`, then the definitions it leads to.
    fn expr(&mut self, e: &'a Expr) {
        // Each frame: the local whose definition it walks (none for the
        // operand), the names that definition reads, and the next to visit.
        let mut stack: Vec<(Option<LocalId>, Vec<NameRead>, usize)> = vec![(None, self.names(e), 0)];
        while let Some((through, names, next)) = stack.last_mut() {
            let Some((span, name, symbol)) = names.get(*next).cloned() else {
                if let Some(done) = *through {
                    self.visiting.remove(&done);
                    self.path.pop();
                    self.walked.insert(done);
                }
                stack.pop();
                continue;
            };
            *next += 1;
            let through = *through;
            match symbol {
                Some(Symbol::Effect(id)) => {
                    self.effects.insert(id);
                }
                Some(Symbol::Local(local)) => {
                    if let Some(definition) = self.local(local, span, &name, through) {
                        self.visiting.insert(local);
                        self.path.push(local);
                        stack.push((Some(local), self.names(definition), 0));
                    }
                }
                _ => {}
            }
        }
    }

    /// The names `e` reads, in source order.
    fn names(&self, e: &'a Expr) -> Vec<NameRead> {
        let mut names = vec![];
        visit_expr(e, &mut |x| {
            if let ExprKind::Name(name) = &x.kind {
                names.push((x.span, name.clone(), self.checked.symbols.get(&x.id).copied()));
            }
        });
        names
    }

    /// Checks a local the operand reads (`through`: the single-definition
    /// local whose definition reads it); returns its definition when that
    /// must be walked next.
    fn local(&mut self, local: LocalId, span: Span, name: &str, through: Option<LocalId>) -> Option<&'a Expr> {
        let facts = self.facts;
        self.touched.insert(local);
        // Where the read happens: at the derivative, or where the definition
        // that reads the local stands (it is inlined, but reads the values
        // of that point of the body).
        let reading_at = match through {
            Some(t) => facts.defined_in.get(&t).copied().unwrap_or(self.statement),
            None => self.statement,
        };
        if facts.is_invariant(local) {
            if through.is_some() && !facts.is_stable(local) {
                self.error(local, span, name, Why::Stale);
                return None;
            }
            // Passed as an argument, it has the value of the derivative's
            // point; a definition that reads it earlier, before its
            // assignment, saw another value.
            if through.is_some() && facts.assigned_from(local, reading_at) {
                self.error(local, span, name, Why::Before);
                return None;
            }
            self.params.insert(local);
            return None;
        }
        match facts.definitions.get(&local) {
            // Read again through its own definition: a definition that reads
            // the local it assigns (`a = a + x;`), directly or through others,
            // reads the value from before the assignment, which inlining
            // cannot give (and would never finish).
            Some(_) if self.visiting.contains(&local) => {
                self.error(local, span, name, Why::SelfRead);
                None
            }
            Some((_, Some(defined_at))) if *defined_at >= reading_at => {
                self.error(local, span, name, Why::Before);
                None
            }
            Some(_) if self.walked.contains(&local) => None,
            Some((definition, _)) => Some(*definition),
            None => {
                self.error(local, span, name, Why::Unstable);
                None
            }
        }
    }

    fn error(&mut self, local: LocalId, span: Span, name: &str, why: Why) {
        if !self.reported.insert(local) {
            return;
        }
        let before = self.diagnostics.len();
        self.report(local, span, name, why);
        if why == Why::Unstable {
            self.unstable.extend(self.diagnostics.drain(before..));
        } else {
            self.other_errors = true;
        }
    }

    fn report(&mut self, local: LocalId, span: Span, name: &str, why: Why) {
        const NOTE: &str = "a derivative re-evaluates its operand at the neighbouring sample: differentiate locals \
                            that are assigned exactly once, where they are declared, or the expression they are built \
                            from; a local built by a loop, a branch or several assignments can be differentiated in a \
                            later top-level statement that does not assign it, with no derivative or `return` before \
                            that statement (they run again at the neighbouring sample)";
        let decl = self.checked.locals[local.index()].span;
        let unstable = format!(
            "`{name}` is assigned more than once or inside a branch or loop, so it cannot be recomputed at the neighbouring sample"
        );
        // Reached through an inlined definition: `span` is in that definition,
        // away from the derivative, so the derivative is the primary label
        // and the labels below it trace the operand to `name`.
        let (Some(&first), Some(&through)) = (self.path.first(), self.path.last()) else {
            let why = match why {
                Why::Before => format!("`{name}` is differentiated before it is assigned"),
                Why::SelfRead => format!("`{name}` is read by its own definition, before it is assigned"),
                Why::Stale | Why::Unstable => unstable,
            };
            self.diagnostics.push(
                Diagnostic::error("E0503", format!("`{}` cannot differentiate `{name}`", self.callee.name))
                    .with_label(Label::primary(span, why))
                    .with_label(Label::secondary(decl, "declared here"))
                    .with_note(NOTE),
            );
            return;
        };
        let operand = &self.checked.locals[first.index()].name;
        let via = &self.checked.locals[through.index()].name;
        let callee = &self.callee.name;
        let site = match why {
            Why::SelfRead => None,
            // The assignment that comes too late: a local assigned after the
            // definition that reads it is assigned once, so its first assignment.
            Why::Before => assignments(self.body, self.checked, local).first().map(|(span, _)| (*span, Nesting::Later)),
            Why::Stale | Why::Unstable => assignment_site(self.body, self.checked, local),
        };
        let used = match (why, site) {
            (Why::Before, _) => {
                format!("`{via}` is computed from `{name}` before `{name}` is assigned")
            }
            (Why::SelfRead, _) if via == name => {
                format!("`{name}` is read by its own definition, before it is assigned")
            }
            (Why::SelfRead, _) => {
                format!("`{via}` is computed from `{name}`, which reads `{via}` before it is assigned")
            }
            (Why::Stale, _) => format!(
                "`{via}` is computed from `{name}`, which is assigned more than once, so its value at the neighbouring \
                 sample is not known"
            ),
            (Why::Unstable, Some(_)) => {
                format!("`{via}` is computed from `{name}`, which cannot be recomputed at the neighbouring sample")
            }
            (Why::Unstable, None) => format!("`{via}` is computed from `{name}`: {unstable}"),
        };
        let mut d = Diagnostic::error("E0503", format!("`{callee}` cannot differentiate `{operand}`"))
            .with_label(Label::primary(
                self.call,
                format!("`{callee}` re-evaluates `{operand}` at the neighbouring sample"),
            ))
            .with_label(Label::secondary(span, used));
        d = match site {
            Some((at, nesting)) => d.with_label(Label::secondary(
                at,
                match nesting {
                    Nesting::Loop => format!("`{name}` is assigned inside a loop"),
                    Nesting::Branch => format!("`{name}` is assigned inside a branch"),
                    Nesting::Again => format!("`{name}` is assigned again here"),
                    Nesting::Later => format!("`{name}` is assigned here"),
                },
            )),
            None => d.with_label(Label::secondary(decl, "declared here")),
        };
        d = d.with_note(NOTE);
        if let (Why::Unstable, Some((_, Nesting::Loop | Nesting::Branch))) = (why, site) {
            let rate = match self.rate {
                Rate::Coarse => "coarse effect",
                Rate::Fine | Rate::Out => "fine effect",
            };
            let ty = &self.checked.locals[local.index()].ty;
            d = d.with_note(format!(
                "help: or build `{name}` in an effect of its own, `{rate} {ty} {name}_effect {{ ... }}`, and read \
                 that: an effect is recomputed at the neighbouring sample however it is built"
            ));
        }
        self.diagnostics.push(d);
    }
}

// ---- Value-only evaluation ------------------------------------------------------

/// The statements of a block effect body that its value, the final value of
/// `result`, does not need: `refine;` and the statements that only decide
/// it, and any other statement whose only effect is on locals the value never
/// reads.
///
/// `refine;` sets the effect's refine flag and nothing else: it does not end
/// the body, and no expression reads the flag. Expressions have no side
/// effects (functions are pure, loops have static bounds), so a statement
/// that assigns no needed local can be left out without changing the value.
/// A neighbour evaluation discards the refine flag, so it evaluates the body
/// without these statements, and with them the derivatives of the refine
/// predicates, which would otherwise re-evaluate neighbours of neighbours.
///
/// A statement is kept when it assigns a needed local (the result, or a local
/// a kept statement reads) or holds a `break` or `continue` of an enclosing
/// loop; a kept `if` or `for` keeps the kept statements inside it. Needed
/// locals are found by a backward fixed point over the body (loops can carry
/// values from one iteration to the next).
pub fn value_skips(checked: &Checked, result: LocalId, body: &[Stmt]) -> HashSet<NodeId> {
    let mut needed = HashSet::from([result]);
    loop {
        let before = needed.len();
        for s in body.iter().rev() {
            mark_needed(s, checked, &mut needed);
        }
        if needed.len() == before {
            break;
        }
    }
    let mut skipped = HashSet::new();
    for s in body {
        collect_skipped(s, checked, &needed, &mut skipped);
    }
    skipped
}

/// Whether statement `s` is kept in a value-only evaluation, given the needed locals.
fn kept(s: &Stmt, checked: &Checked, needed: &HashSet<LocalId>) -> bool {
    affects(s, checked, needed) || escapes(s)
}

/// Whether `s` assigns a needed local.
fn affects(s: &Stmt, checked: &Checked, needed: &HashSet<LocalId>) -> bool {
    match &s.kind {
        StmtKind::Local { .. } => checked.local_decls.get(&s.id).is_none_or(|l| needed.contains(l)),
        StmtKind::Assign { target, .. } | StmtKind::Step { target, .. } => {
            root_local(target, checked).is_none_or(|l| needed.contains(&l))
        }
        StmtKind::If { then, otherwise, .. } => {
            affects(then, checked, needed) || otherwise.as_ref().is_some_and(|o| affects(o, checked, needed))
        }
        StmtKind::For { body, .. } => affects(body, checked, needed),
        StmtKind::Block(b) => b.stmts.iter().any(|s| affects(s, checked, needed)),
        StmtKind::Refine | StmtKind::Break | StmtKind::Continue => false,
        // Effects cannot return (E0305); keep one anyway.
        StmtKind::Return(_) => true,
    }
}

/// Whether `s` holds a `break` or `continue` of a loop around it.
fn escapes(s: &Stmt) -> bool {
    match &s.kind {
        StmtKind::Break | StmtKind::Continue => true,
        StmtKind::If { then, otherwise, .. } => escapes(then) || otherwise.as_ref().is_some_and(|o| escapes(o)),
        StmtKind::Block(b) => b.stmts.iter().any(escapes),
        _ => false,
    }
}

/// Adds the locals that `s` reads, if it is kept, to `needed` (sub-statements
/// last to first).
fn mark_needed(s: &Stmt, checked: &Checked, needed: &mut HashSet<LocalId>) {
    if !kept(s, checked, needed) {
        return;
    }
    let read = |e: &Expr, needed: &mut HashSet<LocalId>| {
        visit_expr(e, &mut |x| {
            if let Some(Symbol::Local(l)) = checked.symbols.get(&x.id) {
                needed.insert(*l);
            }
        })
    };
    match &s.kind {
        StmtKind::Local { init, .. } => {
            if let Some(e) = init {
                read(e, needed);
            }
        }
        StmtKind::Assign { target, value, .. } => {
            read(target, needed);
            read(value, needed);
        }
        StmtKind::Step { target, .. } => read(target, needed),
        StmtKind::Return(Some(e)) => read(e, needed),
        StmtKind::If { cond, then, otherwise } => {
            read(cond, needed);
            if let Some(o) = otherwise {
                mark_needed(o, checked, needed);
            }
            mark_needed(then, checked, needed);
        }
        StmtKind::For { init, cond, step, body } => {
            // A kept loop is kept whole: its header reads what it reads.
            for header in [init, step].into_iter().flatten() {
                visit_stmt_exprs(header, &mut |e| read(e, needed));
            }
            if let Some(c) = cond {
                read(c, needed);
            }
            mark_needed(body, checked, needed);
        }
        StmtKind::Block(b) => b.stmts.iter().rev().for_each(|s| mark_needed(s, checked, needed)),
        StmtKind::Return(None) | StmtKind::Refine | StmtKind::Break | StmtKind::Continue => {}
    }
}

/// Collects the statements of `s` (itself, or inside it when it is kept)
/// that are not kept.
fn collect_skipped(s: &Stmt, checked: &Checked, needed: &HashSet<LocalId>, skipped: &mut HashSet<NodeId>) {
    if !kept(s, checked, needed) {
        skipped.insert(s.id);
        return;
    }
    match &s.kind {
        StmtKind::If { then, otherwise, .. } => {
            collect_skipped(then, checked, needed, skipped);
            if let Some(o) = otherwise {
                collect_skipped(o, checked, needed, skipped);
            }
        }
        StmtKind::For { body, .. } => collect_skipped(body, checked, needed, skipped),
        StmtKind::Block(b) => b.stmts.iter().for_each(|s| collect_skipped(s, checked, needed, skipped)),
        _ => {}
    }
}

/// Why a local in a derivative operand cannot be recomputed at a neighbour.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Why {
    /// Invariant, but assigned again: an inlined definition may have read another value.
    Stale,
    /// Its single assignment comes after the derivative, or, read through an
    /// inlined definition, at or after that definition (an invariant local
    /// passed as an argument included).
    Before,
    /// Neither invariant nor single-definition.
    Unstable,
    /// Read by its own definition, directly or through others (`a = a + x;`):
    /// the value from before the assignment, which inlining cannot give.
    SelfRead,
}

/// Why an assignment makes a local impossible to recompute at a neighbour.
#[derive(Clone, Copy, PartialEq)]
enum Nesting {
    Loop,
    Branch,
    /// A second assignment at the top level of the body.
    Again,
    /// The assignment that comes after a read (for `Why::Before`).
    Later,
}

/// For diagnostics: the assignment to `local` that stops it from being
/// recomputed at a neighbour, the first one inside a loop, else inside a
/// branch, else the second one.
fn assignment_site(body: &[&Stmt], checked: &Checked, local: LocalId) -> Option<(Span, Nesting)> {
    let sites = assignments(body, checked, local);
    let find = |n: Nesting| sites.iter().find(|(_, k)| *k == Some(n)).map(|(span, _)| (*span, n));
    find(Nesting::Loop)
        .or_else(|| find(Nesting::Branch))
        .or_else(|| sites.get(1).map(|(span, _)| (*span, Nesting::Again)))
}

/// The assignments to `local` in source order (declarations with an
/// initialiser included), each with the loop or branch it is in, if any.
fn assignments(body: &[&Stmt], checked: &Checked, local: LocalId) -> Vec<(Span, Option<Nesting>)> {
    fn walk(
        s: &Stmt,
        checked: &Checked,
        local: LocalId,
        nesting: Option<Nesting>,
        out: &mut Vec<(Span, Option<Nesting>)>,
    ) {
        match &s.kind {
            StmtKind::Local { init: Some(_), .. } if checked.local_decls.get(&s.id) == Some(&local) => {
                out.push((s.span, nesting))
            }
            StmtKind::Assign { target, .. } | StmtKind::Step { target, .. }
                if root_local(target, checked) == Some(local) =>
            {
                out.push((s.span, nesting))
            }
            StmtKind::If { then, otherwise, .. } => {
                let inner = nesting.or(Some(Nesting::Branch));
                walk(then, checked, local, inner, out);
                if let Some(o) = otherwise {
                    walk(o, checked, local, inner, out);
                }
            }
            StmtKind::For { step, body, .. } => {
                if let Some(st) = step {
                    walk(st, checked, local, Some(Nesting::Loop), out);
                }
                walk(body, checked, local, Some(Nesting::Loop), out);
            }
            StmtKind::Block(b) => b.stmts.iter().for_each(|s| walk(s, checked, local, nesting, out)),
            _ => {}
        }
    }
    let mut sites = vec![];
    for s in body {
        walk(s, checked, local, None, &mut sites);
    }
    sites
}
