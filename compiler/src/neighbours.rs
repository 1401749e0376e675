//! The neighbour values ([`NeighbourLayout`]): the coarse effects whose
//! values the block modes' derivatives read at the neighbouring samples,
//! evaluated once per sample before the samples that take the differences;
//! the steps ("waves") in which the tile kernel evaluates them; and how often
//! each kernel evaluates each coarse effect's body per sample
//! ([`mrsl_abi::EffectLayout::sample_evaluations`]).

use crate::check::{Checked, EffectId};
use crate::deriv::DerivInfo;
use crate::graph::EffectGraph;
use crate::interface::Interface;
use crate::syntax::ast::Rate;
use mrsl_abi::{Layout, NeighbourLayout, NeighbourValue};
use std::collections::BTreeSet;

/// The coarse effects the block coarse kernel's derivatives read at
/// neighbouring samples (the operands of derivative sites in live coarse
/// effects), with their word offsets and waves, when evaluating them reads
/// no effect at a neighbour in turn: then a first entry point can store them
/// at every sample and the derivatives read them. Otherwise none.
pub fn layout(
    checked: &Checked,
    graph: &EffectGraph,
    deriv: &DerivInfo,
    interface: &Interface,
    binding: u32,
) -> NeighbourLayout {
    let coarse_live = |e: EffectId| graph.live[e.index()] && checked.effects[e.index()].rate == Rate::Coarse;
    let stored: BTreeSet<EffectId> = deriv
        .sites
        .iter()
        .filter(|site| coarse_live(site.effect))
        .flat_map(|site| site.effects.iter().copied())
        .filter(|e| graph.live[e.index()])
        .collect();
    let evaluated: BTreeSet<EffectId> = stored.iter().flat_map(|&e| graph.closure(e, checked)).collect();
    // Only the derivatives a value needs run at a neighbour (`DerivSite::decides_only`).
    let nested = deriv
        .sites
        .iter()
        .any(|site| evaluated.contains(&site.effect) && !site.effects.is_empty() && !site.decides_only);
    let mut words = 0;
    let mut effects = vec![];
    if !nested {
        let waves = waves(checked, graph, deriv, interface, &stored, &evaluated);
        for e in graph.order.iter().filter(|e| stored.contains(e)) {
            let info = &checked.effects[e.index()];
            effects.push(NeighbourValue { name: info.name.clone(), offset: words, wave: waves[e.index()] });
            words += info.ty.components();
        }
    }
    NeighbourLayout { binding, words, effects }
}

/// The tile kernel's wave of every effect its neighbour phase evaluates
/// (`evaluated`: the neighbour values and what they read; 0 for the rest).
/// An effect is evaluated no earlier than what it reads; a neighbour value
/// whose refine flag the tile keeps (it has a refine bit) one wave after the
/// neighbour values its flag's derivatives read at the neighbouring samples,
/// which must all be in workgroup memory by then. Every derivative in a
/// neighbour value's body that reads an effect decides its flag only
/// ([`layout`] stores none otherwise).
fn waves(
    checked: &Checked,
    graph: &EffectGraph,
    deriv: &DerivInfo,
    interface: &Interface,
    stored: &BTreeSet<EffectId>,
    evaluated: &BTreeSet<EffectId>,
) -> Vec<u32> {
    let mut wave = vec![0u32; checked.effects.len()];
    for &e in graph.order.iter().filter(|e| evaluated.contains(e)) {
        let after_reads = checked.effects[e.index()].deps.iter().map(|(d, _)| wave[d.index()]).max();
        let keeps_flag = stored.contains(&e) && interface.refine_bit[e.index()].is_some();
        let after_differences = deriv
            .sites
            .iter()
            .filter(|site| keeps_flag && site.effect == e)
            .flat_map(|site| site.effects.iter().map(|f| wave[f.index()] + 1))
            .max();
        wave[e.index()] = after_reads.into_iter().chain(after_differences).max().unwrap_or(0);
    }
    wave
}

/// Whether the tile kernel keeps refine flags beside its neighbour values:
/// where a neighbour value has a refine bit. The flags are words of the
/// record's flag layout, one set per record slot of the tile.
pub fn tile_keeps_flags(layout: &Layout) -> bool {
    layout.neighbours.effects.iter().any(|v| layout.effects.iter().any(|e| e.name == v.name && e.refine_bit.is_some()))
}

/// How often the block modes' kernels evaluate a live coarse effect's body
/// per coarse sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleEvaluations {
    /// The tile kernel (the block modes on a GPU).
    pub tile: u32,
    /// The two-pass coarse kernel (the block modes on a CPU).
    pub coarse_kernel: u32,
}

/// [`SampleEvaluations`] of every effect (`None` for one that is not a
/// live coarse effect), given the neighbour values.
pub fn sample_evaluations(
    checked: &Checked,
    graph: &EffectGraph,
    deriv: &DerivInfo,
    neighbours: &NeighbourLayout,
) -> Vec<Option<SampleEvaluations>> {
    let n = checked.effects.len();
    let coarse = |e: EffectId| graph.live[e.index()] && checked.effects[e.index()].rate == Rate::Coarse;
    let id = |name: &str| EffectId(checked.effects.iter().position(|e| e.name == name).expect("an effect") as u32);
    let waves: Vec<(EffectId, u32)> = neighbours.effects.iter().map(|v| (id(&v.name), v.wave)).collect();
    let stored: BTreeSet<EffectId> = waves.iter().map(|&(e, _)| e).collect();
    let mut tile = vec![0u32; n];
    let mut two_pass = vec![0u32; n];
    let once = |e: EffectId, value_only: bool| 1 + prefix_runs(deriv, e, value_only);
    // The two-pass kernel's neighbour pass evaluates the values and what they read, each once.
    for e in stored.iter().flat_map(|&e| graph.closure(e, checked)).collect::<BTreeSet<_>>() {
        two_pass[e.index()] += once(e, true);
    }
    // Each of the tile's waves evaluates its values and what they read,
    // except the values of earlier waves, which it reads back.
    for wave in 0..=waves.iter().map(|&(_, w)| w).max().unwrap_or(0) {
        let in_wave = waves.iter().filter(|&&(_, w)| w == wave).map(|&(e, _)| e);
        let needed: BTreeSet<EffectId> = in_wave.flat_map(|e| graph.closure(e, checked)).collect();
        for x in needed {
            if !waves.iter().any(|&(s, w)| s == x && w < wave) {
                // A value that refines runs whole, with its flag, at the tile's samples.
                let with_flag = waves.contains(&(x, wave)) && checked.effects[x.index()].has_refine;
                tile[x.index()] += once(x, !with_flag);
            }
        }
    }
    let in_place = neighbours.words == 0;
    for e in (0..n as u32).map(EffectId).filter(|&e| coarse(e)) {
        let info = &checked.effects[e.index()];
        // The two-pass kernel reads a stored value back unless its flag is needed.
        if !stored.contains(&e) || info.has_refine {
            two_pass[e.index()] += once(e, false);
            at_neighbours(checked, graph, deriv, e, false, 1, in_place, &mut two_pass);
        }
        // The tile kernel reads a stored value and its flag back.
        if !stored.contains(&e) {
            tile[e.index()] += once(e, false);
            at_neighbours(checked, graph, deriv, e, false, 1, in_place, &mut tile);
        }
    }
    (0..n)
        .map(|i| coarse(EffectId(i as u32)).then_some(SampleEvaluations { tile: tile[i], coarse_kernel: two_pass[i] }))
        .collect()
}

/// The partial evaluations of `e`'s body that one evaluation of it makes at
/// neighbouring samples: per derivative site with a prefix
/// ([`crate::deriv::DerivSite::prefix`]), one per position of its difference
/// (`ddx`, `ddy`: one; `fwidth`, `sample`: two). With `value_only`, only
/// the sites a value needs.
fn prefix_runs(deriv: &DerivInfo, e: EffectId, value_only: bool) -> u32 {
    deriv
        .sites
        .iter()
        .filter(|s| s.effect == e && s.prefix.is_some() && !(value_only && s.decides_only))
        .map(|s| positions(s.builtin))
        .sum()
}

/// The positions a derivative evaluates its operand at, besides its own.
fn positions(builtin: crate::builtins::Builtin) -> u32 {
    match builtin.plain_derivative() {
        crate::builtins::Builtin::Ddx | crate::builtins::Builtin::Ddy => 1,
        _ => 2,
    }
}

/// Adds the evaluations the derivatives in `e`'s body make at neighbouring
/// samples, `times` over, when they evaluate there (`in_place`): the effects
/// each operand reads and what those read, at one position per `ddx` or
/// `ddy`, two per `fwidth` or `sample`; and so on for the derivatives their
/// values take. With `value_only`, only the derivatives a value needs.
#[allow(clippy::too_many_arguments, reason = "one recursion over the same facts")]
fn at_neighbours(
    checked: &Checked,
    graph: &EffectGraph,
    deriv: &DerivInfo,
    e: EffectId,
    value_only: bool,
    times: u32,
    in_place: bool,
    count: &mut [u32],
) {
    if !in_place {
        return;
    }
    for site in deriv.sites.iter().filter(|s| s.effect == e && !(value_only && s.decides_only)) {
        let positions = positions(site.builtin);
        for &read in &site.effects {
            for x in graph.closure(read, checked) {
                count[x.index()] += times * positions * (1 + prefix_runs(deriv, x, true));
                at_neighbours(checked, graph, deriv, x, true, times * positions, in_place, count);
            }
        }
    }
}
