//! The minimal coarse-to-fine interface: pass conditions, interference and slot allocation.
//!
//! A coarse effect `A` is *passed* from the coarse to the fine stage when some
//! effect that reads it may run in the fine stage while `A` itself was
//! computed coarsely. Over the block's refine flags `r_X`:
//!
//! ```text
//! pass(A) = !r_A && (A has a fine user || r_B for some coarse user B)
//! ```
//!
//! where `r_X` is constant false for an effect without a `refine` statement.
//! (Discontinuities refine every effect at once; then nothing is passed, so
//! they never add a case.) Two passed effects *interfere* when both
//! conditions can hold together; because every `r` appears positively in the
//! disjunction and negatively only for the effect itself, that is decidable
//! in linear time: set `r_A = r_A' = false` and check each disjunction still
//! has a fine user or a refinable coarse user other than `A` and `A'`.
//!
//! Slots are then allocated by colouring the interference graph, minimising
//! the total number of 32-bit components (a slot is as wide as its widest
//! effect): exactly by branch and bound up to [`EXACT_LIMIT`] passed effects,
//! by a size-ordered first-fit heuristic beyond.

use crate::check::{Checked, EffectId};
use crate::graph::EffectGraph;
use crate::syntax::ast::Rate;
use petgraph::graph::UnGraph;
use serde::Serialize;

/// Up to this many passed effects, allocation is exact (branch and bound).
pub const EXACT_LIMIT: usize = 24;
/// Search steps after which the exact search keeps the best colouring found.
pub const EXACT_STEP_BUDGET: u64 = 2_000_000;

/// Under which refine flags a coarse effect must be passed to the fine stage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassCondition {
    /// Some user always runs in the fine stage (a fine effect or output).
    pub fine_user: bool,
    /// Coarse users that can refine; `A` is passed when one of them does.
    pub refining_users: Vec<EffectId>,
    /// `A` itself can refine (then `!r_A` is part of the condition).
    pub self_refines: bool,
}

impl PassCondition {
    pub fn possible(&self) -> bool {
        self.fine_user || !self.refining_users.is_empty()
    }
}

/// One slot of the interface record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Slot {
    /// Offset in 32-bit words from the start of a sample's record.
    pub offset: u32,
    /// Width in 32-bit words.
    pub size: u32,
    pub effects: Vec<EffectId>,
}

/// The analysis result.
#[derive(Debug, Clone, PartialEq)]
pub struct Interface {
    /// Pass condition of every coarse effect (None for fine effects and dead ones).
    pub conditions: Vec<Option<PassCondition>>,
    /// Interference edges between passed effects.
    pub interference: Vec<(EffectId, EffectId)>,
    pub slots: Vec<Slot>,
    /// Slot index of each passed effect.
    pub slot_of: Vec<Option<usize>>,
    /// Refine bit of each coarse effect with a `refine` statement.
    pub refine_bit: Vec<Option<u32>>,
    /// 32-bit words of refine flags at the start of every record.
    pub flag_words: u32,
    /// Words per coarse sample: flags, then slots.
    pub stride: u32,
    /// Whether the allocation was proven minimal (exact search finished).
    pub exact: bool,
}

impl Interface {
    pub fn is_passed(&self, e: EffectId) -> bool {
        self.slot_of[e.index()].is_some()
    }
    /// Whether the slot of `e` is shared with another effect.
    pub fn is_shared(&self, e: EffectId) -> bool {
        self.slot_of[e.index()].is_some_and(|s| self.slots[s].effects.len() > 1)
    }
}

/// Computes pass conditions, the interference graph and the slot allocation.
pub fn allocate(checked: &Checked, graph: &EffectGraph) -> Interface {
    allocate_level(checked, graph, &|_| false)
}

/// [`allocate`] for one level of the multi-rate mode: the coarse effects of
/// `checked` (a view of the program, `crate::rates`) except those `outside`
/// holds, which another level provides and which are never passed here.
pub fn allocate_level(checked: &Checked, graph: &EffectGraph, outside: &dyn Fn(EffectId) -> bool) -> Interface {
    let n = checked.effects.len();
    let refines =
        |e: EffectId| checked.effects[e.index()].rate == Rate::Coarse && checked.effects[e.index()].has_refine;
    let mut conditions = vec![None; n];
    for (i, effect) in checked.effects.iter().enumerate() {
        let me = EffectId(i as u32);
        if effect.rate != Rate::Coarse || !graph.live[i] || outside(me) {
            continue;
        }
        let mut fine_user = false;
        let mut refining_users = vec![];
        for &user in &graph.users[i] {
            if !graph.live[user.index()] {
                continue;
            }
            match checked.effects[user.index()].rate {
                Rate::Coarse if refines(user) => refining_users.push(user),
                Rate::Coarse => {}
                Rate::Fine | Rate::Out => fine_user = true,
            }
        }
        refining_users.sort();
        refining_users.dedup();
        conditions[i] = Some(PassCondition { fine_user, refining_users, self_refines: refines(me) });
    }
    let passed: Vec<EffectId> =
        (0..n).filter(|&i| conditions[i].as_ref().is_some_and(|c| c.possible())).map(|i| EffectId(i as u32)).collect();

    let mut interference = vec![];
    for (k, &a) in passed.iter().enumerate() {
        for &b in &passed[k + 1..] {
            if interfere(conditions[a.index()].as_ref(), conditions[b.index()].as_ref(), a, b) {
                interference.push((a, b));
            }
        }
    }
    let sizes: Vec<u32> = passed.iter().map(|e| checked.effects[e.index()].ty.components()).collect();
    let (classes, exact) = colour(&passed, &sizes, &interference);

    let mut refine_bit = vec![None; n];
    let mut bits: u32 = 0;
    for &e in &graph.order {
        if refines(e) {
            refine_bit[e.index()] = Some(bits);
            bits += 1;
        }
    }
    let flag_words = bits.div_ceil(32);
    let mut slots = vec![];
    let mut slot_of = vec![None; n];
    let mut offset = flag_words;
    for class in classes {
        let size = class.iter().map(|&k| sizes[k]).max().unwrap_or(0);
        let mut effects: Vec<EffectId> = class.iter().map(|&k| passed[k]).collect();
        effects.sort();
        for e in &effects {
            slot_of[e.index()] = Some(slots.len());
        }
        slots.push(Slot { offset, size, effects });
        offset += size;
    }
    Interface { conditions, interference, slots, slot_of, refine_bit, flag_words, stride: offset, exact }
}

fn interfere(a: Option<&PassCondition>, b: Option<&PassCondition>, ea: EffectId, eb: EffectId) -> bool {
    let (Some(a), Some(b)) = (a, b) else {
        return false;
    };
    // With r_a = r_b = false (required by both conditions), each disjunction
    // must still be satisfiable by its own, independent literals.
    let alive = |c: &PassCondition| c.fine_user || c.refining_users.iter().any(|u| *u != ea && *u != eb);
    alive(a) && alive(b)
}

/// Colours the interference graph into slots minimising the sum of slot widths.
/// Returns the classes (indices into `nodes`) and whether the result is proven minimal.
pub fn colour(nodes: &[EffectId], sizes: &[u32], edges: &[(EffectId, EffectId)]) -> (Vec<Vec<usize>>, bool) {
    let index: std::collections::HashMap<EffectId, usize> = nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let mut graph: UnGraph<(), ()> = UnGraph::with_capacity(nodes.len(), edges.len());
    for _ in nodes {
        graph.add_node(());
    }
    // The petgraph graph gives degrees; a dense matrix answers adjacency in
    // O(1), which keeps first fit quadratic on near-complete graphs.
    let n = nodes.len();
    let mut matrix = vec![false; n * n];
    for &(a, b) in edges {
        let (a, b) = (index[&a], index[&b]);
        graph.add_edge(petgraph::graph::NodeIndex::new(a), petgraph::graph::NodeIndex::new(b), ());
        matrix[a * n + b] = true;
        matrix[b * n + a] = true;
    }
    let adjacent = |a: usize, b: usize| matrix[a * n + b];
    // Widest first (a class's width is then fixed by its first member), then
    // most constrained first.
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    // Cached: counting neighbours on every comparison made this N^2 log N.
    order.sort_by_cached_key(|&k| {
        (std::cmp::Reverse(sizes[k]), std::cmp::Reverse(graph.neighbors(petgraph::graph::NodeIndex::new(k)).count()), k)
    });

    // First fit: never raises a class's width, since members come widest first.
    let mut greedy: Vec<Vec<usize>> = vec![];
    for &k in &order {
        match greedy.iter_mut().find(|class| class.iter().all(|&m| !adjacent(m, k))) {
            Some(class) => class.push(k),
            None => greedy.push(vec![k]),
        }
    }
    if nodes.len() > EXACT_LIMIT {
        return (greedy, false);
    }
    let cost =
        |classes: &[Vec<usize>]| classes.iter().map(|c| c.iter().map(|&k| sizes[k]).max().unwrap_or(0)).sum::<u32>();
    struct Search<'s> {
        order: &'s [usize],
        sizes: &'s [u32],
        adjacent: &'s dyn Fn(usize, usize) -> bool,
        best: Vec<Vec<usize>>,
        best_cost: u32,
        steps: u64,
    }
    impl Search<'_> {
        fn go(&mut self, depth: usize, classes: &mut Vec<Vec<usize>>, cost: u32) {
            self.steps += 1;
            if cost >= self.best_cost || self.steps > EXACT_STEP_BUDGET {
                return;
            }
            if depth == self.order.len() {
                self.best = classes.clone();
                self.best_cost = cost;
                return;
            }
            let k = self.order[depth];
            for c in 0..classes.len() {
                if classes[c].iter().all(|&m| !(self.adjacent)(m, k)) {
                    classes[c].push(k);
                    self.go(depth + 1, classes, cost);
                    classes[c].pop();
                }
            }
            classes.push(vec![k]);
            self.go(depth + 1, classes, cost + self.sizes[k]);
            classes.pop();
        }
    }
    let greedy_cost = cost(&greedy);
    let mut search =
        Search { order: &order, sizes, adjacent: &adjacent, best: greedy.clone(), best_cost: greedy_cost, steps: 0 };
    search.go(0, &mut vec![], 0);
    let exact = search.steps <= EXACT_STEP_BUDGET;
    let mut best = search.best;
    for class in &mut best {
        class.sort();
    }
    best.sort();
    (best, exact)
}
