//! The effect dependency graph: rate rules, cycles, and the order effects are computed in.

use crate::check::{Checked, EffectId, InputId, Symbol};
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::{EffectBody, Rate, Span};
use crate::syntax::{visit_expr, visit_stmt_exprs};
use petgraph::algo::kosaraju_scc;
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::{BTreeSet, HashSet};

/// What the later stages need of the graph whose nodes are effects and
/// outputs and whose edges are uses (from the used effect to its user); the
/// graph itself is only needed while [`build`] checks it.
#[derive(Debug, Clone)]
pub struct EffectGraph {
    /// Topological order, dependencies first; only effects that reach an output.
    pub order: Vec<EffectId>,
    /// For each effect, the effects that read it.
    pub users: Vec<Vec<EffectId>>,
    /// Whether an output (transitively) needs the effect.
    pub live: Vec<bool>,
    /// For each live effect, the discontinuity keys it reads, directly or
    /// through the effects it reads (ascending; empty for dead effects). A
    /// discontinuity in one of these keys concerns the effect (it is
    /// resampled from the corners on a pixel's side, or refined), and only
    /// these do: an effect that never reads `material` is continuous across
    /// a material edge, so interpolating it there is exact to first order.
    pub keys: Vec<Vec<InputId>>,
}

impl EffectGraph {
    fn node(id: EffectId) -> NodeIndex {
        NodeIndex::new(id.index())
    }
    /// Every effect `id` needs, transitively, including itself; in `order`.
    pub fn closure(&self, id: EffectId, checked: &Checked) -> Vec<EffectId> {
        let mut needed = vec![false; checked.effects.len()];
        let mut stack = vec![id];
        while let Some(e) = stack.pop() {
            if !std::mem::replace(&mut needed[e.index()], true) {
                stack.extend(checked.effects[e.index()].deps.iter().map(|(d, _)| *d));
            }
        }
        self.order.iter().copied().filter(|e| needed[e.index()]).collect()
    }
}

/// A coarse effect's block size for the rate rules: `coarse(N)`'s N, and
/// for plain `coarse` the finer coarse rate, 2, at which the multi-rate mode
/// shades it (so a `coarse(4)` effect cannot read a plain one).
pub fn rule_block(e: &crate::check::EffectInfo) -> u32 {
    e.block.unwrap_or(crate::check::COARSE_BLOCKS[1])
}

/// E0312: coarse effect `user` reads `dep`, of a finer coarse rate.
fn finer_rate_read(checked: &Checked, user: EffectId, dep: EffectId, span: Span) -> Diagnostic {
    let (e, d) = (&checked.effects[user.index()], &checked.effects[dep.index()]);
    let (eb, db) = (rule_block(e), rule_block(d));
    let declared = if d.block.is_some() {
        format!("declared coarse({db}) here")
    } else {
        format!("declared plain `coarse` here, which ranks as {db}x{db}")
    };
    Diagnostic::error("E0312", format!("coarse({eb}) effect `{}` reads `{}`, which is shaded at a finer rate", e.name, d.name))
        .with_label(Label::primary(span, format!("`{}` is shaded once per {db}x{db} block", d.name)))
        .with_label(Label::secondary(checked.effect_decl(dep).rate_span, declared))
        .with_label(Label::secondary(checked.effect_decl(user).rate_span, format!("declared coarse({eb}) here")))
        .with_note(format!(
            "an effect reads effects of its own rate or a coarser one, because the {eb}x{eb} samples are shaded before the {db}x{db} ones; declare `{}` coarse({eb}), or this effect coarse({db})",
            d.name
        ))
}

/// Builds the graph and checks the rate rules and acyclicity.
pub fn build(checked: &Checked) -> (EffectGraph, Vec<Diagnostic>) {
    let mut diagnostics = vec![];
    let effects = &checked.effects;
    // Phase 1: register every node; ids and node indices coincide.
    let mut graph = DiGraph::with_capacity(effects.len(), effects.len() * 2);
    for i in 0..effects.len() {
        graph.add_node(EffectId(i as u32));
    }
    // Phase 2: edges, checking that coarse effects read only coarse effects.
    let mut users = vec![vec![]; effects.len()];
    for (i, e) in effects.iter().enumerate() {
        let user = EffectId(i as u32);
        for &(dep, span) in &e.deps {
            graph.add_edge(EffectGraph::node(dep), EffectGraph::node(user), span);
            users[dep.index()].push(user);
            let d = &effects[dep.index()];
            if e.rate == Rate::Coarse && d.rate != Rate::Coarse {
                diagnostics.push(
                    Diagnostic::error("E0310", format!("coarse effect `{}` depends on fine {} `{}`", e.name, if d.rate == Rate::Out { "output" } else { "effect" }, d.name))
                        .with_label(Label::primary(span, format!("`{}` is only available per pixel", d.name)))
                        .with_label(Label::secondary(checked.effect_decl(dep).rate_span, "declared fine here"))
                        .with_label(Label::secondary(checked.effect_decl(user).rate_span, "declared coarse here"))
                        .with_note("a coarse sample is shaded before any fine effect; make the dependency coarse or this effect fine"),
                );
            } else if e.rate == Rate::Coarse && d.rate == Rate::Coarse && rule_block(e) > rule_block(d) {
                diagnostics.push(finer_rate_read(checked, user, dep, span));
            }
        }
    }
    // Phase 3: strongly connected components; each non-trivial one is a cycle.
    // (Kosaraju's algorithm in petgraph is iterative; its Tarjan recurses
    // once per effect along a chain of dependencies.)
    let mut cyclic = false;
    for scc in kosaraju_scc(&graph) {
        let is_cycle = scc.len() > 1 || graph.contains_edge(scc[0], scc[0]);
        if !is_cycle {
            continue;
        }
        cyclic = true;
        // Edges run from the used effect to its user; report the cycle the way
        // it reads in the source ("a -> b": `a` reads `b`).
        let mut path = cycle_path(&graph, &scc);
        path[1..].reverse();
        let names: Vec<&str> = path.iter().map(|n| effects[graph[*n].index()].name.as_str()).collect();
        let mut shown = names.clone();
        shown.push(names[0]);
        let mut d =
            Diagnostic::error("E0311", format!("effects depend on each other in a cycle: {}", shown.join(" -> ")));
        for (k, &n) in path.iter().enumerate() {
            let next = path[(k + 1) % path.len()];
            let user = &effects[graph[n].index()];
            let span = user.deps.iter().find(|(dep, _)| *dep == graph[next]).map(|(_, s)| *s).unwrap_or(user.name_span);
            let message = format!("`{}` reads `{}`", user.name, effects[graph[next].index()].name);
            d = d.with_label(if k == 0 { Label::primary(span, message) } else { Label::secondary(span, message) });
        }
        diagnostics
            .push(d.with_note("effects form a DAG: break the cycle by computing one value from the inputs directly"));
    }
    // Phase 4: liveness and topological order (skipped for cyclic graphs).
    let mut live = vec![false; effects.len()];
    let mut stack: Vec<EffectId> =
        effects.iter().enumerate().filter(|(_, e)| e.rate == Rate::Out).map(|(i, _)| EffectId(i as u32)).collect();
    while let Some(e) = stack.pop() {
        if !std::mem::replace(&mut live[e.index()], true) {
            stack.extend(effects[e.index()].deps.iter().map(|(d, _)| *d));
        }
    }
    let order = if cyclic {
        vec![]
    } else {
        petgraph::algo::toposort(&graph, None)
            .map(|nodes| nodes.into_iter().map(|n| graph[n]).filter(|e| live[e.index()]).collect())
            .unwrap_or_default()
    };
    let keys = keys_read(checked, &order);
    if !cyclic {
        diagnostics.extend(idle_keys(checked, &order, &keys));
    }
    (EffectGraph { order, users, live, keys }, diagnostics)
}

/// W0002 for each discontinuity key that no live coarse effect reads: it
/// refines nothing, which is almost always a mistake (since keys refine
/// only their readers, a `@key` on a material id no coarse effect reads
/// no longer guards the lighting at silhouettes).
fn idle_keys(checked: &Checked, order: &[EffectId], keys: &[Vec<InputId>]) -> Vec<Diagnostic> {
    let read: BTreeSet<InputId> = order
        .iter()
        .filter(|e| checked.effects[e.index()].rate == Rate::Coarse)
        .flat_map(|e| keys[e.index()].iter().copied())
        .collect();
    let mut out = vec![];
    for (k, info) in checked.inputs.iter().enumerate() {
        if info.key.is_none() || read.contains(&InputId(k as u32)) {
            continue;
        }
        let Some(decl) = checked.program.items.iter().find_map(|item| match item {
            crate::syntax::ast::Item::Input(d) if d.name.name == info.name => Some(d),
            _ => None,
        }) else {
            continue;
        };
        let attr = decl
            .attrs
            .iter()
            .find(|a| matches!(a.name.name.as_str(), "key" | "surface_key"))
            .map(|a| a.span)
            .unwrap_or(decl.name.span);
        out.push(
            Diagnostic::warning("W0002", format!("the discontinuity key `{}` refines nothing", info.name))
                .with_label(Label::primary(attr, format!("no coarse effect reads `{}`", info.name)))
                .with_note(
                    "a discontinuity in a key refines only the coarse effects that read it, directly or through \
                     other effects; fine effects are evaluated per pixel anyway",
                )
                .with_note(format!(
                    "remove the key, or key the channels the coarse effects read (e.g. `@surface_key(normal, 0.25) in \
                     float3 position;` and `@key(0.4) in float3 normal;` for geometric edges) instead of `{}`",
                    info.name
                )),
        );
    }
    out
}

/// The discontinuity keys each effect of `order` reads, directly or through
/// the effects it reads, and for a coarse effect the background channels,
/// whose edges every coarse effect keeps to its side; `order` has
/// dependencies first, so each effect's dependencies are complete when it
/// is reached.
fn keys_read(checked: &Checked, order: &[EffectId]) -> Vec<Vec<InputId>> {
    let background: Vec<InputId> = (0..checked.inputs.len() as u32)
        .map(InputId)
        .filter(|i| checked.inputs[i.index()].background.is_some())
        .collect();
    let mut keys: Vec<BTreeSet<InputId>> = vec![BTreeSet::new(); checked.effects.len()];
    for &e in order {
        let mut read = BTreeSet::new();
        if checked.effects[e.index()].rate == Rate::Coarse {
            read.extend(background.iter().copied());
        }
        let mut note = |x: &crate::syntax::ast::Expr| {
            if let Some(Symbol::Input(i)) = checked.symbols.get(&x.id)
                && checked.inputs[i.index()].key.is_some()
            {
                read.insert(*i);
            }
        };
        match &checked.effect_decl(e).body {
            EffectBody::Expr(x) => visit_expr(x, &mut note),
            EffectBody::Block(b) => {
                for s in &b.stmts {
                    visit_stmt_exprs(s, &mut |x| visit_expr(x, &mut note));
                }
            }
        }
        for (d, _) in &checked.effects[e.index()].deps {
            read.extend(keys[d.index()].iter().copied());
        }
        keys[e.index()] = read;
    }
    keys.into_iter().map(|k| k.into_iter().collect()).collect()
}

/// A simple cycle through the nodes of one strongly connected component,
/// starting from its first declared effect: the first path back to it that a
/// depth-first search finds, taking neighbours in id order (with an explicit
/// stack, as a component may be a cycle of any length).
fn cycle_path(graph: &DiGraph<EffectId, Span>, scc: &[NodeIndex]) -> Vec<NodeIndex> {
    let start = *scc.iter().min().expect("an SCC is never empty");
    let in_scc: HashSet<NodeIndex> = scc.iter().copied().collect();
    let sorted_neighbours = |n: NodeIndex| {
        let mut next: Vec<NodeIndex> = graph.neighbors(n).collect();
        next.sort();
        next.reverse();
        next
    };
    let mut path = vec![start];
    let mut visited: HashSet<NodeIndex> = HashSet::from([start]);
    // The neighbours still to try from each node of `path`, last first.
    let mut untried = vec![sorted_neighbours(start)];
    while let Some(candidates) = untried.last_mut() {
        let Some(n) = candidates.pop() else {
            untried.pop();
            path.pop();
            continue;
        };
        if n == start {
            break;
        }
        if in_scc.contains(&n) && visited.insert(n) {
            path.push(n);
            untried.push(sorted_neighbours(n));
        }
    }
    path
}
