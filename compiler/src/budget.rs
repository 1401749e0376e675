//! The size budget of the generated kernels (E0701).
//!
//! A derivative evaluates its operand again at the two positions of its quad
//! pair, with every effect the operand reads evaluated there too
//! (`mrsl_at_<effect>`, which evaluates the effect's whole dependency
//! chain). Where those effects' values use derivatives themselves, each
//! level multiplies the work: a chain of effects whose values each take
//! `fwidth` of the previous one grows by a factor of about four per effect.
//! Shader compilers inline every call, so what the driver compiles is the
//! fully inlined code, and a program that `check` accepts could produce
//! kernels no driver can build.
//!
//! This module counts the operations of the fully inlined code, as the
//! reference kernel evaluates the program (every live effect once per
//! pixel; the other kernels add a bounded amount of code per effect and per
//! neighbour evaluation), and reports E0701 when one effect's count exceeds
//! [`MAX_EFFECT_OPERATIONS`] or the program's exceeds
//! [`MAX_PROGRAM_OPERATIONS`], naming the effects that cost the most. It
//! models what `codegen` writes:
//!
//! - an operation is an expression node or a statement;
//! - a derivative site costs its operand's evaluation at a neighbour (`mrsl_d<k>`)
//!   twice per difference: twice for `ddx` and `ddy`, four times for
//!   `fwidth` and `sample`. The helper's text has both calls; outside the
//!   record modes it runs one of them and takes the operand at the position
//!   itself from its caller (`mrsl_here`), so there the count is an upper
//!   bound of the work executed, and so are the layout's `operations`;
//! - the operand is evaluated with single-definition locals inlined, inputs
//!   loaded, and each effect it reads costing that effect's neighbour
//!   evaluation: its dependency closure, each effect that can refine
//!   evaluated for its value alone (`DerivInfo::value_skips`);
//! - a call of a user function costs the function's body.
//!
//! The count is exact for the text `codegen` writes up to the constant work
//! of each function (loads, positions); it exists to catch code that grows
//! exponentially, not to predict compile times.

use crate::builtins::Builtin;
use crate::check::{Callee, Checked, EffectId, FunctionId, LocalId, Symbol};
use crate::deriv::DerivInfo;
use crate::diagnostic::{Diagnostic, Label};
use crate::graph::EffectGraph;
use crate::syntax::ast::*;
use crate::syntax::visit_expr;
use std::collections::{HashMap, HashSet};

/// The most operations one effect's evaluation may take, fully inlined
/// (see the module documentation). Exponential growth shows here first.
pub const MAX_EFFECT_OPERATIONS: u64 = 1 << 14;

/// The most operations the evaluations of all a program's effects may take
/// together, fully inlined: what polynomial growth (a long chain of
/// derivatives of derivatives' inputs) reaches before any one effect does.
pub const MAX_PROGRAM_OPERATIONS: u64 = 1 << 20;

/// How many of the costliest effects E0701 names.
const NAMED: usize = 5;

/// The operation counts of a program.
pub struct Costs {
    /// Per live effect, in `graph.order`: its evaluation at its own position, fully inlined.
    pub effects: Vec<(EffectId, u64)>,
    /// The same for an evaluation of its value alone (`mrsl_val_<effect>`:
    /// without what only decides the refine flag), as the per-pixel kernels
    /// evaluate it; equal to `effects` for an effect that cannot refine.
    pub values: Vec<(EffectId, u64)>,
    /// The sum of `effects`.
    pub total: u64,
}

/// Counts the operations of the fully inlined code of every live effect.
pub fn costs(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo) -> Costs {
    count(checked, graph, deriv, false)
}

/// What a texture read counts in the cost model: a fetch with filtering
/// costs several arithmetic operations' worth of issue slots and far more
/// latency; 4 is a round figure, the same for every mode, so it moves the
/// model's totals but hardly its ratios between modes.
pub const TEXTURE_READ_OPERATIONS: u64 = 4;

/// The cost model: the operations one evaluation of each live effect
/// executes, as [`costs`] counts them but with every `for` loop's body
/// counted once per iteration of its static trip count (a loop guarded by a
/// uniform, like `if (i < light_count)`, counts its full static bound) and
/// every texture read weighted by [`TEXTURE_READ_OPERATIONS`]. Multiplied
/// by the evaluations a mode makes, it gives a platform-independent figure
/// of shading work.
pub fn evaluation_costs(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo) -> Costs {
    count(checked, graph, deriv, true)
}

fn count(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo, executed: bool) -> Costs {
    let mut counter = Counter { checked, deriv, memo: HashMap::new(), executed };
    // The counter memoises, and recurses only into what is not counted yet.
    // Counting the links of every chain first, callees and dependencies before
    // their users, keeps that recursion to one expression's depth (which the
    // nesting limits bound): chains of functions, effects and inlined
    // definitions can be thousands of links long.
    let functions =
        postorder(checked.functions.len(), |f| checked.functions[f].calls.iter().map(|c| c.index()).collect());
    for f in functions {
        counter.function(FunctionId(f as u32));
    }
    let mut locals: Vec<LocalId> = deriv.definitions.keys().copied().collect();
    locals.sort_by_key(|l| l.index());
    let local_index: HashMap<LocalId, usize> = locals.iter().enumerate().map(|(k, l)| (*l, k)).collect();
    let definitions = postorder(locals.len(), |k| {
        let mut read = vec![];
        visit_expr(deriv.definitions[&locals[k]], &mut |x| {
            if let Some(Symbol::Local(l)) = checked.symbols.get(&x.id)
                && let Some(&j) = local_index.get(l)
            {
                read.push(j);
            }
        });
        read
    });
    for k in definitions {
        let l = locals[k];
        let definition = deriv.definitions[&l];
        counter.memo(Key::Definition(l), |c| c.expr(definition, At::Neighbour(&[])));
    }
    let effects =
        postorder(checked.effects.len(), |e| checked.effects[e].deps.iter().map(|(d, _)| d.index()).collect());
    for e in effects {
        let e = EffectId(e as u32);
        counter.effect(e, true);
        counter.effect(e, false);
        counter.at(e);
    }
    let effects: Vec<(EffectId, u64)> = graph.order.iter().map(|&e| (e, counter.effect(e, false))).collect();
    let values: Vec<(EffectId, u64)> = graph.order.iter().map(|&e| (e, counter.effect(e, true))).collect();
    let total = effects.iter().fold(0u64, |sum, (_, cost)| sum.saturating_add(*cost));
    Costs { effects, values, total }
}

/// E0701 when an effect's inlined code, or the program's, exceeds the budget.
pub fn check(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo) -> Vec<Diagnostic> {
    let costs = costs(checked, graph, deriv);
    let mut worst = costs.effects.clone();
    worst.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let over = worst.iter().take_while(|(_, cost)| *cost > MAX_EFFECT_OPERATIONS).count();
    let message = if over > 0 {
        worst.truncate(over.min(NAMED));
        let what = if over == 1 { "an effect takes".to_string() } else { format!("{over} effects take") };
        format!(
            "the kernels would be too large: {what} more than {} operations once their derivatives' neighbour \
             evaluations are inlined",
            thousands(MAX_EFFECT_OPERATIONS)
        )
    } else if costs.total > MAX_PROGRAM_OPERATIONS {
        worst.truncate(NAMED);
        format!(
            "the kernels would be too large: the program's effects take {} operations once their derivatives' \
             neighbour evaluations are inlined, more than {}",
            thousands(costs.total),
            thousands(MAX_PROGRAM_OPERATIONS)
        )
    } else {
        return vec![];
    };
    let mut diagnostic = Diagnostic::error("E0701", message);
    for (k, &(e, cost)) in worst.iter().enumerate() {
        let info = &checked.effects[e.index()];
        let mut message = format!("`{}` takes {} operations", info.name, thousands(cost));
        let again = neighbour_effects(deriv, e);
        if !again.is_empty() {
            let names: Vec<String> = again.iter().map(|d| format!("`{}`", checked.effects[d.index()].name)).collect();
            message
                .push_str(&format!(": its derivatives evaluate {} again at neighbouring positions", names.join(", ")));
        }
        diagnostic = diagnostic.with_label(if k == 0 {
            Label::primary(info.name_span, message)
        } else {
            Label::secondary(info.name_span, message)
        });
    }
    vec![
        diagnostic
            .with_note(
                "a derivative evaluates its operand again at the neighbouring positions, with every effect the operand \
                 reads and all that effect needs; when those effects take derivatives themselves, the work multiplies \
                 with every step of the chain",
            )
            .with_note(
                "differentiate inputs, or effects whose values do not take derivatives; derivatives in `refine` \
                 conditions cost nothing at the neighbours",
            ),
    ]
}

/// The effects whose values the derivatives of effect `e` need at neighbours, directly.
fn neighbour_effects(deriv: &DerivInfo, e: EffectId) -> Vec<EffectId> {
    let mut out: Vec<EffectId> = vec![];
    for site in deriv.sites.iter().filter(|s| s.effect == e) {
        for &d in &site.effects {
            if !out.contains(&d) {
                out.push(d);
            }
        }
    }
    out
}

/// The nodes `0..n` in an order where every node comes after the nodes
/// `successors` gives for it (cycles broken anywhere), found without recursion.
fn postorder(n: usize, successors: impl Fn(usize) -> Vec<usize>) -> Vec<usize> {
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    for root in 0..n {
        if std::mem::replace(&mut seen[root], true) {
            continue;
        }
        // (node, its successors, how many of them have been visited)
        let mut stack = vec![(root, successors(root), 0usize)];
        while let Some((node, next, k)) = stack.last_mut() {
            if let Some(&s) = next.get(*k) {
                *k += 1;
                if s < n && !std::mem::replace(&mut seen[s], true) {
                    let after = successors(s);
                    stack.push((s, after, 0));
                }
            } else {
                order.push(*node);
                stack.pop();
            }
        }
    }
    order
}

/// `1234567` as `1,234,567`.
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Where an expression is evaluated.
#[derive(Clone, Copy)]
enum At<'s> {
    /// In its body.
    Body,
    /// Rebuilt at a neighbour for a derivative site (with the site's parameters).
    Neighbour(&'s [LocalId]),
}

/// What the counter memoises.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    /// `mrsl_eval_<effect>`.
    Full(EffectId),
    /// `mrsl_val_<effect>`.
    Value(EffectId),
    /// `mrsl_at_<effect>`.
    At(EffectId),
    /// One evaluation of a site's operand at a neighbour (`mrsl_d<k>`).
    Site(usize),
    /// A single-definition local's definition, inlined at a neighbour.
    Definition(LocalId),
    Function(FunctionId),
}

/// Memoised operation counts (`None` while being counted: a cycle counts 0).
struct Counter<'c, 'a> {
    checked: &'c Checked<'a>,
    deriv: &'c DerivInfo<'a>,
    memo: HashMap<Key, Option<u64>>,
    /// Count what executes (loop bodies times their trips, texture reads
    /// weighted) rather than what is written.
    executed: bool,
}

impl Counter<'_, '_> {
    /// Looks `key` up, or computes it with `count`.
    fn memo(&mut self, key: Key, count: impl FnOnce(&mut Self) -> u64) -> u64 {
        match self.memo.get(&key) {
            Some(Some(cost)) => return *cost,
            Some(None) => return 0,
            None => {}
        }
        self.memo.insert(key, None);
        let cost = count(self);
        self.memo.insert(key, Some(cost));
        cost
    }

    /// `mrsl_eval_<e>`, or with `value_only` what a neighbour evaluates:
    /// `mrsl_val_<e>` for an effect that can refine.
    fn effect(&mut self, e: EffectId, value_only: bool) -> u64 {
        let skips = if value_only { self.deriv.value_skips.get(&e) } else { None };
        let key = if skips.is_some() { Key::Value(e) } else { Key::Full(e) };
        let checked = self.checked;
        self.memo(key, |c| {
            let decl = checked.effect_decl(e);
            match &decl.body {
                EffectBody::Expr(x) => c.expr(x, At::Body).saturating_add(1),
                EffectBody::Block(b) => c.stmts(&b.stmts, skips).saturating_add(2),
            }
        })
    }

    /// `mrsl_at_<e>`: the closure of `e`, each effect evaluated for its value.
    fn at(&mut self, e: EffectId) -> u64 {
        let checked = self.checked;
        self.memo(Key::At(e), |c| {
            let mut seen = HashSet::from([e]);
            let mut stack = vec![e];
            let mut cost = 1u64;
            while let Some(x) = stack.pop() {
                cost = cost.saturating_add(c.effect(x, true));
                for &(d, _) in &checked.effects[x.index()].deps {
                    if seen.insert(d) {
                        stack.push(d);
                    }
                }
            }
            cost
        })
    }

    fn stmts(&mut self, stmts: &[Stmt], skips: Option<&HashSet<NodeId>>) -> u64 {
        stmts.iter().fold(0u64, |sum, s| sum.saturating_add(self.stmt(s, skips)))
    }

    fn stmt(&mut self, s: &Stmt, skips: Option<&HashSet<NodeId>>) -> u64 {
        if skips.is_some_and(|skips| skips.contains(&s.id)) {
            return 0;
        }
        let mut parts: Vec<u64> = vec![1];
        match &s.kind {
            StmtKind::Local { init, .. } => {
                if let Some(e) = init {
                    parts.push(self.expr(e, At::Body));
                }
            }
            StmtKind::Assign { target, value, .. } => {
                parts.push(self.expr(target, At::Body));
                parts.push(self.expr(value, At::Body));
            }
            StmtKind::Step { target, .. } => parts.push(self.expr(target, At::Body)),
            StmtKind::Return(Some(e)) => parts.push(self.expr(e, At::Body)),
            StmtKind::If { cond, then, otherwise } => {
                parts.push(self.expr(cond, At::Body));
                parts.push(self.stmt(then, skips));
                if let Some(o) = otherwise {
                    parts.push(self.stmt(o, skips));
                }
            }
            StmtKind::For { init, cond, step, body } => {
                let trips = if self.executed { self.checked.loop_trips.get(&s.id).copied().unwrap_or(1) } else { 1 };
                if let Some(i) = init {
                    parts.push(self.stmt(i, None));
                }
                let mut iteration = self.stmt(body, skips);
                if let Some(st) = step {
                    iteration = iteration.saturating_add(self.stmt(st, None));
                }
                if let Some(c) = cond {
                    iteration = iteration.saturating_add(self.expr(c, At::Body));
                }
                parts.push(iteration.saturating_mul(trips));
            }
            StmtKind::Block(b) => parts.push(self.stmts(&b.stmts, skips)),
            StmtKind::Return(None) | StmtKind::Refine | StmtKind::Break | StmtKind::Continue => {}
        }
        parts.into_iter().fold(0u64, u64::saturating_add)
    }

    fn expr(&mut self, e: &Expr, at: At) -> u64 {
        let c = self.checked;
        let mut cost = 1u64;
        let mut add = |x: u64| cost = cost.saturating_add(x);
        match &e.kind {
            ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) => {}
            ExprKind::Name(_) => match (c.symbols.get(&e.id), at) {
                (Some(Symbol::Local(l)), At::Neighbour(params)) if !params.contains(l) => {
                    if let Some(definition) = self.deriv.definitions.get(l).copied() {
                        add(self.memo(Key::Definition(*l), |c| c.expr(definition, at)));
                    }
                }
                (Some(Symbol::Effect(d)), At::Neighbour(_)) => add(self.at(*d)),
                _ => {}
            },
            ExprKind::Unary(_, a) | ExprKind::Field { base: a, .. } => add(self.expr(a, at)),
            ExprKind::Binary(_, a, b) | ExprKind::Index { base: a, index: b } => {
                add(self.expr(a, at));
                add(self.expr(b, at));
            }
            ExprKind::Ternary(a, b, x) => {
                add(self.expr(a, at));
                add(self.expr(b, at));
                add(self.expr(x, at));
            }
            ExprKind::Call { args, .. } => {
                match c.callees.get(&e.id) {
                    Some(Callee::Builtin(b)) if b.is_derivative() => {
                        // The operand is evaluated at the neighbours, the other arguments here.
                        let operand = b.derivative_operand();
                        let evaluations = match b.plain_derivative() {
                            Builtin::Ddx | Builtin::Ddy => 2,
                            _ => 4,
                        };
                        if let Some(&k) = self.deriv.site_of.get(&e.id) {
                            add(self.site(k).saturating_mul(evaluations));
                        }
                        for (i, a) in args.iter().enumerate() {
                            if Some(i) != operand || matches!(b, Builtin::Sample) {
                                add(self.expr(a, at));
                            }
                        }
                        if self.executed && matches!(b, Builtin::Sample) {
                            add(TEXTURE_READ_OPERATIONS);
                        }
                        return cost;
                    }
                    Some(Callee::Function(f)) => add(self.function(*f)),
                    Some(Callee::Builtin(Builtin::Load | Builtin::SampleLevel | Builtin::SampleGrad))
                        if self.executed =>
                    {
                        add(TEXTURE_READ_OPERATIONS)
                    }
                    _ => {}
                }
                for a in args {
                    add(self.expr(a, at));
                }
            }
        }
        cost
    }

    /// One evaluation of derivative site `k`'s operand at a neighbour: for
    /// a site with a prefix, the body's statements before it (`mrsl_prefix<k>`)
    /// and the effects they read there, then the operand.
    fn site(&mut self, k: usize) -> u64 {
        let (deriv, checked) = (self.deriv, self.checked);
        self.memo(Key::Site(k), |c| {
            let site = &deriv.sites[k];
            let Some(statement) = site.prefix else {
                return c.expr(site.operand, At::Neighbour(&site.params));
            };
            let EffectBody::Block(b) = &checked.effect_decl(site.effect).body else { return 0 };
            let effects = site.effects.iter().fold(0u64, |sum, &d| sum.saturating_add(c.at(d)));
            c.stmts(&b.stmts[..statement], None).saturating_add(effects).saturating_add(c.expr(site.operand, At::Body))
        })
    }

    fn function(&mut self, f: FunctionId) -> u64 {
        let checked = self.checked;
        self.memo(Key::Function(f), |c| {
            let decl = checked.function_decl(f);
            c.stmts(&decl.body.stmts, None).saturating_add(1)
        })
    }
}
