//! WGSL code generation: the compute kernels a checked program compiles to.
//!
//! Each [`KernelKind`] is one WGSL module; its entry points, their workgroup
//! sizes and the dispatch geometry are the `mrsl_abi` contract, which the
//! runtime dispatches by. What each kernel does:
//!
//! - **coarse** (`coarse_main`, per block size B): one invocation per coarse
//!   sample (every B-th pixel, plus the last row and column). It evaluates
//!   the coarse effects, collects their `refine` flags and writes the
//!   sample's interface record (flag words, then the passed values).
//! - **fine** (`fine_main`, per B): one invocation per pixel. It resolves
//!   the four samples around the pixel and decides per coarse effect whether
//!   to re-evaluate it (a corner flagged it, a discontinuity key differs, or
//!   a shared slot holds another effect) or to resample the passed values;
//!   then it evaluates fine effects and stores the outputs, and counts
//!   re-evaluations in the statistics and the refine mask.
//! - **reference** (`reference_main`): every effect per pixel, what a fully
//!   refined image must equal.
//! - **dynamic coarse** (`dynamic_coarse_main`): the dynamic mode's second
//!   level. The ordinary 4x4 coarse kernel is the first; this one shades 2x2
//!   samples only inside 4x4 blocks that refined, tagging their records fresh.
//! - **dynamic fine** (`dynamic_fine_main`): per pixel, a coarse value from
//!   the 4x4 level, else from the 2x2 level, else evaluated.
//! - **hierarchical** (`hier_*`, DACS): level 0 shades every 4th pixel; each
//!   of four finer levels classifies its pixels (interpolate the previous
//!   levels' neighbours, or shade), compacts the ones to shade into a work
//!   list and shades it with an indirect dispatch; `hier_final` evaluates
//!   the fine effects and outputs per pixel from the per-pixel records.
//! - **checkerboard** (`cb_shade`, `cb_final`): the coarse effects are shaded
//!   in half the 2x2 quads and reconstructed in the others from the
//!   edge-adjacent quads; the final pass is the hierarchical one's.
//!
//! All kernels share the per-effect functions (`mrsl_eval_<effect>`), so an
//! effect computes the same value wherever it runs. They differ in what a
//! position is (a coarse sample or a pixel), in how an effect's value at
//! another position is obtained (`mrsl_at_<effect>`, for derivatives) and in
//! their entry points. See docs/language.md, "What the kernels do".
//!
//! The modules, from shared to specific: [`writer`] (the text, and fixed WGSL
//! from `templates/*.wgsl`), [`names`] (every generated name, and the tests
//! that hold the writers and templates to them), [`body`] (user statements
//! and expressions), [`words`] (values as `u32` words), [`effects`] (what
//! every kernel declares: bindings, loaders, effect functions, derivatives,
//! key tests), [`pixel`] (per-pixel entry points), [`fine`] (what the fine
//! kernels of every family share: levels, resolvers as data, refine
//! decisions, resamplers), then one module per kernel family: [`block`]
//! (coarse, fine, reference), [`compact`] (the block fine kernel's compacted
//! entry point), [`dynamic`], [`rate`] (the rate-image mode's coarse and fine
//! kernels), [`records`] (what the hierarchical and checkerboard modes
//! share), [`hierarchical`] and [`checkerboard`].

mod block;
mod body;
mod checkerboard;
mod compact;
mod dynamic;
mod effects;
mod fine;
mod hierarchical;
mod level_derivatives;
mod names;
mod pixel;
mod rate;
mod records;
mod tile;
mod tiles;
mod words;
mod writer;

use crate::check::{Checked, EffectId, FunctionId};
use crate::deriv::DerivInfo;
use crate::graph::EffectGraph;
use crate::interface::Interface;
use crate::syntax::ast::Rate;
use body::{Mode, wgsl_ident};
use mrsl_abi::geometry::{
    DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK, DYNAMIC_TAG_WORDS, FINE_PIXELS_PER_LANE, HIERARCHICAL_LEVEL0,
};
use mrsl_abi::{KernelKind, Layout};
use std::cell::RefCell;
use std::collections::HashMap;
use writer::{Code, Values};

/// Everything the writer reads.
pub(crate) struct Inputs<'a, 'b> {
    pub checked: &'b Checked<'a>,
    pub graph: &'b EffectGraph,
    pub interface: &'b Interface,
    pub deriv: &'b DerivInfo<'a>,
    pub layout: &'b Layout,
    pub file_name: &'b str,
    /// `Options::compact`.
    pub compact: bool,
    pub source: &'b str,
    /// What the kernels of one compile share: build it once with
    /// [`Cache::new`] and write every kernel with the same inputs.
    pub cache: Cache,
    /// The live coarse effects of the program in dependency order, which
    /// number them for refine masks and statistics counters in every view.
    pub counters: Vec<EffectId>,
    /// The multi-rate mode's level this view of the program is
    /// (`crate::rates`), with what its resolve pass stores per pixel.
    pub level: ViewLevel<'b>,
}

/// Which program the inputs hold: the program itself, or a level of the
/// multi-rate mode ([`crate::rates`]).
#[derive(Clone, Copy)]
pub(crate) enum ViewLevel<'b> {
    Program,
    /// The `coarse(4)` effects alone are coarse; the resolve pass stores `values`.
    Outer {
        values: &'b [(EffectId, u32)],
        words: u32,
    },
    /// The `coarse(4)` effects, `loaded`, are read from `values`.
    Inner {
        values: &'b [(EffectId, u32)],
        words: u32,
        loaded: &'b [bool],
    },
}

/// The live coarse effects of `checked` in dependency order ([`Inputs::counters`]).
pub(crate) fn counters(checked: &Checked, graph: &EffectGraph) -> Vec<EffectId> {
    graph.order.iter().copied().filter(|e| checked.effects[e.index()].rate == Rate::Coarse).collect()
}

/// What the kernels of one compile share, computed once: the text of the
/// functions every kernel that has them writes identically (effect,
/// value-only and user functions, derivative helpers), written by the first
/// kernel that needs each.
pub(crate) struct Cache {
    pieces: RefCell<HashMap<Piece, String>>,
}

/// A function whose text is the same in every kernel, or in every kernel
/// of one [`Derivatives`] kind.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Piece {
    /// `mrsl_eval_<effect>`, or (`true`) `mrsl_val_<effect>`: their derivative calls differ by kind.
    Effect(EffectId, bool, Derivatives),
    /// `mrsl_d<k>`, `mrsl_ddx_<k>` and `mrsl_ddy_<k>`.
    Derivative(usize, Derivatives),
    Function(FunctionId),
}

/// How a kernel's derivative helpers get the operand at the position
/// itself ([`Writer::reuses_operand_here`]).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Derivatives {
    /// From the caller, always.
    Here,
    /// From the caller, always; and the differences of `ddx_surface`,
    /// `ddy_surface` and `fwidth_surface` never span one of the effect's
    /// discontinuity keys where the sample on the other side does not (the
    /// kernels over coarse samples, docs/language.md section 9).
    HereOnSurface,
    /// From the caller where the operand reads no effect (the checkerboard kernel).
    HereWithoutEffects,
    /// From the caller, always; and at levels 1 to 3 a predicate's derivative
    /// of an operand that reads coarse effects is taken from the level's
    /// neighbours, their effects read from their records (the hierarchical
    /// kernel, docs/language.md section 9; [`Writer::takes_level_differences`]).
    HereOrLevelNeighbours,
}

impl Cache {
    pub(crate) fn new() -> Cache {
        Cache { pieces: RefCell::default() }
    }
}

/// Writes one kernel. `block` is the coarse block size (ignored by the reference kernel).
pub(crate) fn write_string(inputs: &Inputs, kind: KernelKind, block: u32) -> String {
    // The multi-rate kernels are the block kernels over a view of the program.
    // The tile kernel is the fine kernel's module, with the coarse kernel's
    // functions written into it (`tile`).
    let family = match kind {
        KernelKind::MultiCoarse => KernelKind::Coarse,
        KernelKind::MultiResolve | KernelKind::MultiFine | KernelKind::Tile => KernelKind::Fine,
        other => other,
    };
    let mut w = Writer::new(inputs, family, if kind == KernelKind::Reference { 1 } else { block });
    w.file = kind;
    w.module();
    w.code.into_string()
}

/// The state of writing one kernel; every module adds its part with an `impl Writer`.
struct Writer<'i, 'a, 'b> {
    i: &'i Inputs<'a, 'b>,
    /// The family of kernel written: a multi-rate kernel is written as the
    /// block kernel of its family (`file`).
    kind: KernelKind,
    /// The kernel itself: its entry point and header.
    file: KernelKind,
    block: u32,
    code: Code,
    /// Live coarse effects, numbered for refine masks, statistics counters and records.
    coarse_index: HashMap<EffectId, u32>,
}

impl<'i, 'a, 'b> Writer<'i, 'a, 'b> {
    fn new(i: &'i Inputs<'a, 'b>, kind: KernelKind, block: u32) -> Self {
        let coarse_index = i.counters.iter().enumerate().map(|(k, e)| (*e, k as u32)).collect();
        Writer { i, kind, file: kind, block, code: Code::default(), coarse_index }
    }

    fn checked(&self) -> &'b Checked<'a> {
        self.i.checked
    }

    /// Writes `piece` as `write` writes it, or, when an earlier kernel of
    /// this compile wrote it, the same text again.
    fn cached(&mut self, piece: Piece, write: impl FnOnce(&mut Self)) {
        if let Some(text) = self.i.cache.pieces.borrow().get(&piece) {
            self.code.push_str(text);
            return;
        }
        let outer = std::mem::take(&mut self.code);
        write(self);
        let text = std::mem::replace(&mut self.code, outer).into_string();
        self.code.push_str(&text);
        self.i.cache.pieces.borrow_mut().insert(piece, text);
    }

    fn line(&mut self, indent: usize, text: impl AsRef<str>) {
        self.code.line(indent, text);
    }

    /// Writes a template (see [`writer`]) `indent` levels deeper than it stands in its file.
    fn template(&mut self, indent: usize, template: &str, values: &Values) {
        self.code.template(indent, template, values);
    }

    fn effect_name(&self, e: EffectId) -> String {
        wgsl_ident(&self.checked().effects[e.index()].name)
    }

    /// The live coarse effects in dependency order (numbered by `coarse_index`).
    fn coarse_live(&self) -> Vec<EffectId> {
        self.i.graph.order.iter().copied().filter(|e| self.checked().effects[e.index()].rate == Rate::Coarse).collect()
    }

    /// Whether `e` is read from the stored values of the multi-rate
    /// mode's resolve pass (the inner view's `coarse(4)` effects).
    fn is_loaded(&self, e: EffectId) -> bool {
        matches!(self.i.level, ViewLevel::Inner { loaded, .. } if loaded[e.index()])
    }

    /// Effects this kernel computes: the coarse kernels only coarse ones.
    fn kernel_effects(&self) -> Vec<EffectId> {
        let c = self.checked();
        self.i
            .graph
            .order
            .iter()
            .copied()
            .filter(|e| !self.kind.is_coarse() || c.effects[e.index()].rate == Rate::Coarse)
            .collect()
    }

    fn module(&mut self) {
        let c = self.checked();
        let (file, block) = (self.i.file_name, self.block);
        self.template(
            0,
            include_str!("templates/header.wgsl"),
            &[
                ("VERSION", &env!("CARGO_PKG_VERSION")),
                ("FILE", &file),
                ("WHAT", &describe(self.file, block)),
                ("BLOCK", &block),
            ],
        );
        if self.kind != KernelKind::Reference {
            // The dynamic mode's second level carries a validity tag after each record.
            let extra = if self.kind == KernelKind::DynamicCoarse { DYNAMIC_TAG_WORDS } else { 0 };
            self.line(0, format!("const {}: u32 = {}u;", names::STRIDE, self.i.interface.stride + extra));
        }
        self.line(0, "");
        self.bindings();
        for (k, info) in c.consts.iter().enumerate() {
            let decl = c.const_decl(crate::check::ConstId(k as u32));
            let value = self.expr(&decl.value, Mode::Body);
            self.line(0, format!("const {}: {} = {};", wgsl_ident(&info.name), info.ty.wgsl(), value));
        }
        if !c.consts.is_empty() {
            self.line(0, "");
        }
        self.matrix_selects();
        self.position_helpers();
        self.input_loaders();
        self.key_functions();
        for k in 0..c.functions.len() {
            let f = FunctionId(k as u32);
            self.cached(Piece::Function(f), |w| w.function(f));
        }
        self.effect_functions();
        match self.kind {
            KernelKind::Coarse | KernelKind::DynamicCoarse | KernelKind::MultiCoarse => self.coarse_entry(),
            KernelKind::Fine | KernelKind::DynamicFine | KernelKind::MultiResolve | KernelKind::MultiFine => {
                self.fine_support();
                self.pixel_entry();
            }
            KernelKind::Tile => unreachable!("the tile kernel is written by the fine family's writer"),
            KernelKind::Reference => self.pixel_entry(),
            KernelKind::Hierarchical => self.hierarchical_entries(),
            KernelKind::Checkerboard => self.checkerboard_entries(),
            KernelKind::RateCoarse => self.rate_coarse_entries(),
            KernelKind::RateFine => {
                self.rate_tiles();
                self.rate_fine_support();
                self.rate_fine_entry();
            }
        }
    }
}

impl Writer<'_, '_, '_> {
    /// The packed dependencies, every effect function this kernel calls,
    /// the derivative helpers and the functions of effects at other positions.
    fn effect_functions(&mut self) {
        let c = self.checked();
        self.args_structs();
        let value_only = self.value_only_effects();
        let keeps_flags = self.keeps_refine_flags();
        for e in self.kernel_effects() {
            // A kernel that discards refine flags never calls `mrsl_eval_` of an effect that can refine.
            if self.is_loaded(e) {
                self.loaded_function(e);
            } else if keeps_flags || !c.effects[e.index()].has_refine {
                self.cached(Piece::Effect(e, false, self.derivatives()), |w| w.eval_function(e, false));
            }
            if value_only.contains(&e) {
                self.cached(Piece::Effect(e, true, self.derivatives()), |w| w.eval_function(e, true));
            }
        }
        self.derivative_helpers();
        self.neighbour_functions();
    }

    /// The tile kernel's coarse part ([`tile`]): what the coarse kernel's
    /// module holds but its bindings, constants and user functions (which
    /// the tile kernel declares once), with its entry points as functions.
    fn coarse_part(&mut self) {
        self.matrix_selects();
        self.position_helpers();
        self.input_loaders();
        self.key_functions();
        self.effect_functions();
        self.tile_phases();
    }
}

/// What a kernel is, for its header comment.
fn describe(kind: KernelKind, block: u32) -> String {
    let (outer, inner) = (DYNAMIC_OUTER_BLOCK, DYNAMIC_INNER_BLOCK);
    match kind {
        KernelKind::Coarse => format!("coarse kernel, {block}x{block} blocks: one invocation per coarse sample"),
        KernelKind::Fine => {
            format!("fine kernel, {block}x{block} blocks: one invocation per {FINE_PIXELS_PER_LANE} pixels of a block")
        }
        KernelKind::Reference => "reference kernel: every effect per pixel".to_string(),
        KernelKind::Tile => format!(
            "tile kernel, {block}x{block} blocks: a workgroup per tile shades its coarse samples, then its pixels"
        ),
        KernelKind::DynamicCoarse => format!(
            "dynamic mode, second level: one invocation per {inner}x{inner} coarse sample inside refined {outer}x{outer} blocks"
        ),
        KernelKind::DynamicFine => {
            format!("dynamic mode, fine kernel: {outer}x{outer}, then {inner}x{inner}, then per pixel")
        }
        KernelKind::Hierarchical => format!(
            "hierarchical (DACS) mode: every {}th pixel, then four levels interpolated or shaded",
            HIERARCHICAL_LEVEL0.step
        ),
        KernelKind::Checkerboard => {
            "checkerboard baseline: half the 2x2 quads shaded, the rest reconstructed".to_string()
        }
        KernelKind::RateCoarse => {
            "rate-image mode, coarse part: the samples each tile's rate needs, listed, then shaded".to_string()
        }
        KernelKind::RateFine => {
            "rate-image mode, per pixel: resampled at the tile's rate, refined, then fine effects".to_string()
        }
        KernelKind::MultiCoarse if block == outer => {
            format!("multi-rate mode, {block}x{block} level: one invocation per coarse sample, coarse({block}) effects")
        }
        KernelKind::MultiCoarse => format!(
            "multi-rate mode, {block}x{block} level: one invocation per coarse sample, the coarse effects but coarse({outer})"
        ),
        KernelKind::MultiResolve => {
            format!("multi-rate mode: coarse({outer}) effects resolved per pixel from {block}x{block} samples, stored")
        }
        KernelKind::MultiFine => {
            format!("multi-rate mode, fine kernel, {block}x{block} blocks: coarse({outer}) values as stored")
        }
    }
}
