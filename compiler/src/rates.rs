//! The multi-rate mode's levels as views of the program, so that its
//! kernels are the block kernels written over a view (docs/language.md,
//! section 8.4, and "What the kernels do").
//!
//! - The **outer** view keeps the `coarse(4)` effects coarse and makes every
//!   other coarse effect fine: its coarse kernel at 4x4 is the 4x4 level, and
//!   its fine kernel (the `multi_resolve` pass) resolves the `coarse(4)`
//!   effects at every pixel exactly as `coarse4x4`'s fine kernel does
//!   (resampled edge-aware, or evaluated where refined), then stores those
//!   that cross the boundary, those a finer effect reads, per pixel.
//! - The **inner** view keeps every coarse effect coarse, but the
//!   `coarse(4)` ones are *loaded*: their value anywhere is what the resolve
//!   pass stored at that pixel, so they never refine and are never passed.
//!   Its coarse kernel at 2x2 is the 2x2 level, its fine kernel the pixels.
//!
//! Each view has its own interface, allocated and coloured as the block
//! modes' is, over the effects of its level: every boundary is minimal in
//! the sense the block modes' interface is.

use crate::check::{Checked, EffectId};
use crate::graph::EffectGraph;
use crate::interface::{self, Interface};
use crate::syntax::ast::Rate;
use mrsl_abi::geometry::{DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK};
use mrsl_abi::{LevelsLayout, NeighbourLayout, NeighbourValue};

/// One level of the multi-rate mode: the program as its kernels see it.
pub struct View<'a> {
    pub checked: Checked<'a>,
    /// The graph the kernels are written from: in the outer view only the
    /// `coarse(4)` effects are computed (`order`), though liveness is the program's.
    pub graph: EffectGraph,
    pub interface: Interface,
}

/// Both levels, and what crosses from the outer one to the inner one.
pub struct Levels<'a> {
    pub outer: View<'a>,
    pub inner: View<'a>,
    /// The `coarse(4)` effects stored per pixel, with their word offsets, in dependency order.
    pub values: Vec<(EffectId, u32)>,
    /// Words per pixel of the stored values.
    pub words: u32,
}

/// Whether `e` is a `coarse(4)` effect: one the outer level shades.
pub fn is_outer(checked: &Checked, e: EffectId) -> bool {
    let info = &checked.effects[e.index()];
    info.rate == Rate::Coarse && info.block == Some(DYNAMIC_OUTER_BLOCK)
}

/// The views of a checked program.
pub fn levels<'a>(checked: &Checked<'a>, graph: &EffectGraph) -> Levels<'a> {
    let outer_ids: Vec<bool> = (0..checked.effects.len()).map(|i| is_outer(checked, EffectId(i as u32))).collect();
    let mut outer = checked.clone();
    for (i, e) in outer.effects.iter_mut().enumerate() {
        if e.rate == Rate::Coarse && !outer_ids[i] {
            e.rate = Rate::Fine;
        }
    }
    // Pass conditions count every reader outside the level as a fine user,
    // so they are computed over the program's liveness and users.
    let outer_interface = interface::allocate(&outer, graph);
    let mut outer_graph = graph.clone();
    outer_graph.order.retain(|e| outer_ids[e.index()]);

    let mut inner = checked.clone();
    for (i, e) in inner.effects.iter_mut().enumerate() {
        if outer_ids[i] {
            // Refined, if at all, at the outer level, before it was stored.
            e.has_refine = false;
        }
    }
    let inner_interface = interface::allocate_level(&inner, graph, &|e| outer_ids[e.index()]);

    let mut values = vec![];
    let mut words = 0;
    for &e in &graph.order {
        let crosses = graph.users[e.index()].iter().any(|u| graph.live[u.index()] && !outer_ids[u.index()]);
        if outer_ids[e.index()] && crosses {
            values.push((e, words));
            words += checked.effects[e.index()].ty.components();
        }
    }
    Levels {
        outer: View { checked: outer, graph: outer_graph, interface: outer_interface },
        inner: View { checked: inner, graph: graph.clone(), interface: inner_interface },
        values,
        words,
    }
}

impl Levels<'_> {
    /// The layout of both levels; the stored values at `binding` of the stage group.
    pub fn layout(&self, checked: &Checked, binding: u32) -> LevelsLayout {
        let name = |e: EffectId| checked.effects[e.index()].name.clone();
        let values = self.values.iter().map(|&(e, offset)| NeighbourValue { name: name(e), offset, wave: 0 }).collect();
        let block = checked
            .effects
            .iter()
            .map(|e| match e.rate {
                Rate::Coarse => e.block.unwrap_or(DYNAMIC_INNER_BLOCK),
                Rate::Fine | Rate::Out => 1,
            })
            .collect();
        LevelsLayout {
            outer: crate::layout::interface_layout(&self.outer.checked, &self.outer.interface),
            values: NeighbourLayout { binding, words: self.words, effects: values },
            inner: crate::layout::interface_layout(&self.inner.checked, &self.inner.interface),
            block,
        }
    }
}
