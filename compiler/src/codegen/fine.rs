//! What the fine kernels of every family share (the block modes', the
//! dynamic mode's and the rate-image mode's): the levels of coarse samples
//! they read, the resolver of a level (`mrsl_resolve{suffix}`: where a pixel
//! takes its coarse values from and which coarse effects it re-evaluates) as
//! data that the family's writer of it reads, the `MrslBlock` structure, the
//! refine decisions, the resamplers' getters and blends, and the per-pixel
//! prologue that counts re-evaluations. Where the families differ (a block's
//! four corners, possibly preloaded; a rate cell's eight border samples) is
//! in [`super::block`] and [`super::rate`].

use super::Writer;
use super::effects::Evaluation;
use super::names::{
    BACKGROUND, BLOCK, CONTROL, CORNERS, INNER_BLOCK, INTERFACE, IS_REFINED, LAST_BLOCK, LEVEL_VALUES, LOAD_CORNERS,
    Name, POS,
};
use super::pixel::Scope;
use super::words::{bit, test_bit, unpack_words};
use super::writer::cut;
use crate::check::EffectId;
use crate::interface::Interface;
use crate::layout;
use crate::syntax::ast::Rate;
use crate::types::Type;
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::DYNAMIC_TAG_WORDS;
use std::collections::{BTreeSet, HashMap};

/// The components of a `vec4`, in the order of the corners they hold.
pub(super) const LANES: [&str; 4] = ["x", "y", "z", "w"];

/// One level of coarse samples as a fine kernel reads it.
pub(super) struct Level {
    /// Suffix of the generated functions (`mrsl_resolve{suffix}`).
    pub(super) suffix: &'static str,
    pub(super) block: u32,
    pub(super) buffer: &'static str,
    /// Refines only within the parent level's refined effects (dynamic mode);
    /// its records carry a validity tag.
    pub(super) parent: bool,
}

impl Level {
    /// The only level of a kernel with one: the coarse kernel's records, in `mrsl_interface`.
    pub(super) const fn own(block: u32) -> Level {
        Level { suffix: "", block, buffer: INTERFACE, parent: false }
    }

    /// The words of one sample's record at this level (the validity tag included).
    pub(super) fn stride(&self, iface: &Interface) -> u32 {
        if self.parent { iface.stride + DYNAMIC_TAG_WORDS } else { iface.stride }
    }

    /// Word `w` of the record of `sample` (a WGSL `u32`), read from the level's buffer.
    pub(super) fn record_word(&self, iface: &Interface, sample: &str, w: u32) -> String {
        format!("{}[{sample} * {}u + {w}u]", self.buffer, self.stride(iface))
    }
}

impl Writer<'_, '_, '_> {
    /// `mrsl_resolve` of the kernel's own (first) level.
    pub(super) fn own_level_resolver(&self) -> String {
        Name::Resolve.of(Level::own(self.block).suffix)
    }

    /// `mrsl_resample<level>_<effect>` of effect `name` at the kernel's own
    /// level, or (`inner`) at the dynamic mode's inner one.
    pub(super) fn level_resampler(&self, inner: bool, name: &str) -> String {
        let level = if inner { &Level::DYNAMIC_INNER } else { &Level::own(self.block) };
        Name::Resample.within(level.suffix, name)
    }
}

/// Where a resolver finds the corners' keys and record words.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Corners {
    /// Loaded once per lane by `mrsl_corners` and passed in (`c: MrslCorners`).
    Preloaded,
    /// Loaded by the resolver itself.
    Loaded,
}

/// The decisions a neighbour function's resolvers make, under a name of its
/// effect's ([`Writer::neighbour_resolvers`]).
pub(super) struct Neighbour<'a> {
    pub(super) effect: &'a str,
    pub(super) decisions: &'a BTreeSet<EffectId>,
}

/// One resolver to write: `mrsl_resolve{name}` at `level`, deciding `coarse`.
pub(super) struct Resolver<'l> {
    pub(super) level: &'l Level,
    /// After `mrsl_resolve`: the level's suffix, then `_<effect>` for a neighbour function's.
    pub(super) name: String,
    /// The coarse effects it decides, in dependency order: every live one,
    /// or a neighbour function's (and their decisions are those of the full resolver).
    pub(super) coarse: Vec<EffectId>,
    /// The flag words their decisions read.
    pub(super) words: Vec<u32>,
    pub(super) corners: Corners,
}

/// The samples of a block's four corners in a resolver, as `MrslBlock::corners` holds them.
pub(super) const CORNER_SAMPLES: [&str; 4] = ["b.corners.x", "b.corners.y", "b.corners.z", "b.corners.w"];

/// What a resampler template of one coarse effect is filled with.
pub(super) struct Resampler<'c> {
    pub(super) effect: EffectId,
    /// The level's suffix (`mrsl_resample{suffix}_<effect>`).
    suffix: &'static str,
    pub(super) name: &'c str,
    pub(super) ty: &'c Type,
    /// The first word of the effect's slot in a record.
    pub(super) offset: u32,
    pub(super) wgsl_type: String,
    stride: u32,
    unpack: String,
    /// How the corners' values `v0`..`v3` are blended: `bilinear` or `nearest corner`.
    pub(super) filter: &'static str,
    pub(super) value: String,
}

impl Resampler<'_> {
    /// The values of `resample.wgsl` and `rate_resample.wgsl`.
    pub(super) fn values(&self) -> [(&'static str, &dyn std::fmt::Display); 8] {
        [
            ("SUFFIX", &self.suffix),
            ("NAME", &self.name),
            ("TYPE", &self.wgsl_type),
            ("STRIDE", &self.stride),
            ("OFFSET", &self.offset),
            ("UNPACK", &self.unpack),
            ("FILTER", &self.filter),
            ("VALUE", &self.value),
        ]
    }
}

impl<'b> Writer<'_, '_, 'b> {
    /// The resolver of `level` that decides every live coarse effect, or
    /// with `only` a neighbour function's.
    pub(super) fn resolver<'l>(&self, level: &'l Level, only: Option<&Neighbour>) -> Resolver<'l> {
        let coarse: Vec<EffectId> =
            self.coarse_live().into_iter().filter(|e| only.is_none_or(|n| n.decisions.contains(e))).collect();
        let (name, words) = match only {
            None => (level.suffix.to_string(), (0..self.i.interface.flag_words).collect()),
            Some(n) => (format!("{}_{}", level.suffix, n.effect), self.flag_words_read(&coarse).into_iter().collect()),
        };
        let corners = if self.preloads_corners() && !level.parent { Corners::Preloaded } else { Corners::Loaded };
        Resolver { level, name, coarse, words, corners }
    }

    /// The resolvers of the kernel's levels, as its family writes them;
    /// with `only`, a neighbour function's.
    pub(super) fn resolvers(&mut self, only: Option<&Neighbour>) {
        match self.kind {
            KernelKind::DynamicFine => {
                for level in [Level::DYNAMIC_OUTER, Level::DYNAMIC_INNER] {
                    let r = self.resolver(&level, only);
                    self.resolve_function(&r);
                }
            }
            KernelKind::RateFine => {
                let level = Level::own(self.block);
                let r = self.resolver(&level, only);
                self.rate_resolve_function(&r);
            }
            _ => {
                let level = Level::own(self.block);
                let r = self.resolver(&level, only);
                self.resolve_function(&r);
            }
        }
    }

    /// The number of `refined<w>` words of `MrslBlock`: a bit per live coarse effect.
    pub(super) fn mask_words(&self) -> u32 {
        (self.i.counters.len() as u32).div_ceil(32)
    }

    /// `MrslBlock` from `template` (the family's fields, then `fields`
    /// writes the program's, then the refined words) and `mrsl_is_refined`.
    pub(super) fn block_struct(&mut self, template: &str, fields: impl FnOnce(&mut Self)) {
        let mask_words = self.mask_words();
        let [head, tail] = cut(template, &["REFINED_WORDS"]);
        self.template(0, head, &[]);
        // Separate words, not an array: llvmpipe spills dynamically indexed
        // arrays in structs to memory, which made every lookup a memory access.
        fields(self);
        if self.has_background() {
            self.line(1, "background: bool, // nothing was drawn at the pixel: its coarse effects read as zero");
        }
        for w in 0..mask_words {
            self.line(1, format!("refined{w}: u32, // bit k: coarse effect 32 * {w} + k is evaluated per pixel"));
        }
        let mut word = "b.refined0".to_string();
        for w in 1..mask_words {
            word = format!("select({word}, b.refined{w}, k >= {}u)", 32 * w);
        }
        self.template(0, tail, &[("WORD", &word)]);
    }

    /// Whether the kernel's resolvers and resamplers of its first level
    /// take the block's corners preloaded (`MrslCorners`): the block modes'
    /// fine kernels and the dynamic fine kernel (its 4x4 level), whose lanes
    /// shade [`mrsl_abi::geometry::FINE_PIXELS_PER_LANE`] pixels of one block.
    pub(super) fn preloads_corners(&self) -> bool {
        matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine)
    }

    /// `let f<ci>_<w>`: the flag words `r.words` of the four corners,
    /// from the preloaded corners or the level's buffer.
    pub(super) fn corner_flag_words(&mut self, r: &Resolver) {
        for (ci, sample) in CORNER_SAMPLES.iter().enumerate() {
            for &w in &r.words {
                let word = match r.corners {
                    Corners::Preloaded => format!("c.w{w}.{}", LANES[ci]),
                    Corners::Loaded => r.level.record_word(self.i.interface, sample, w),
                };
                self.line(1, format!("let f{ci}_{w} = {word};"));
            }
        }
    }

    /// The refine decisions of a resolver, users before what they use:
    /// `mrsl_r<k>` per coarse effect it decides, set in `b.refined<w>`. A
    /// decision reads the flag words `f<ci>_<w>` of the `samples` samples
    /// the resolver read, and begins with `discontinuity` (`disc || ...`,
    /// the family's test of the keys).
    pub(super) fn refine_decisions(
        &mut self,
        r: &Resolver,
        samples: usize,
        discontinuity: &dyn Fn(&Self, EffectId) -> String,
    ) {
        let iface = self.i.interface;
        for &e in r.coarse.iter().rev() {
            let k = self.coarse_index[&e];
            let mut terms = vec![discontinuity(self, e)];
            if let Some(b) = iface.refine_bit[e.index()] {
                let (word, mask) = bit(b);
                let words: Vec<String> = (0..samples).map(|ci| format!("f{ci}_{word}")).collect();
                terms.push(format!("((({}) & {mask}u) != 0u)", words.join(" | ")));
            }
            let needed = self.needed_coarsely(e);
            if !iface.is_passed(e) {
                terms.push(format!("({needed})"));
            } else if iface.is_shared(e) {
                let misses: Vec<String> = (0..samples)
                    .map(|ci| format!("!({})", self.store_condition(e, &|b| test_bit(&format!("f{ci}_"), b))))
                    .collect();
                terms.push(format!("(({needed}) && ({}))", misses.join(" || ")));
            }
            let value = if r.level.parent {
                format!("{IS_REFINED}(parent, {k}u) && ({})", terms.join(" || "))
            } else {
                terms.join(" || ")
            };
            let (word, mask) = bit(k);
            let refined = Name::Refined.of(k);
            self.line(1, format!("let {refined} = {value}; // `{}`", self.checked().effects[e.index()].name));
            self.line(1, format!("if ({refined}) {{ b.refined{word} |= {mask}u; }}"));
        }
    }

    /// In a resolver, after the refine decisions: the background rule. Where
    /// nothing was drawn (and refinement is not forced, where every effect is
    /// evaluated and reads as zero as it does in the reference), the pixel
    /// re-evaluates nothing and its resamplers return zero.
    pub(super) fn background_decision(&mut self) {
        if !self.has_background() {
            return;
        }
        self.line(1, format!("b.background = {BACKGROUND}(pos) && {CONTROL}.force_refine == 0u;"));
        let clear: Vec<String> = (0..self.mask_words()).map(|w| format!("b.refined{w} = 0u;")).collect();
        self.line(1, format!("if (b.background) {{ {} }}", clear.join(" ")));
    }

    /// A resampler from `template`, whose `{{#GUARD}}` hole, after the
    /// signature, returns zero at a background pixel (the background rule).
    pub(super) fn resampler_template(&mut self, template: &str, values: &super::writer::Values, ty: &str) {
        let [head, tail] = cut(template, &["GUARD"]);
        self.template(0, head, values);
        if self.has_background() {
            self.line(1, format!("if (b.background) {{ return {ty}(); }}"));
        }
        self.template(0, tail, values);
    }

    /// Whether coarse effect `e` is needed coarsely, as WGSL over the
    /// decisions `mrsl_r<k>` of its users: some live user runs per pixel here.
    fn needed_coarsely(&self, e: EffectId) -> String {
        let c = self.checked();
        let mut needed = vec![];
        for &u in &self.i.graph.users[e.index()] {
            if !self.i.graph.live[u.index()] {
                continue;
            }
            match c.effects[u.index()].rate {
                Rate::Coarse => needed.push(Name::Refined.of(self.coarse_index[&u])),
                _ => needed.push("true".into()),
            }
        }
        needed.sort();
        needed.dedup();
        if needed.is_empty() { "false".to_string() } else { needed.join(" || ") }
    }

    /// The flag words the decisions of `effects` read: their own refine
    /// bits, and for a shared slot the bits of its pass condition.
    fn flag_words_read(&self, effects: &[EffectId]) -> BTreeSet<u32> {
        let iface = self.i.interface;
        let mut words = BTreeSet::new();
        for &e in effects {
            let mut bits: Vec<u32> = iface.refine_bit[e.index()].into_iter().collect();
            if iface.is_passed(e) && iface.is_shared(e) {
                let cond = iface.conditions[e.index()].as_ref().expect("passed effects have a condition");
                bits.extend(cond.refining_users.iter().filter_map(|u| iface.refine_bit[u.index()]));
            }
            words.extend(bits.into_iter().map(|b| bit(b).0));
        }
        words
    }

    /// The resamplers of the passed coarse effects at `level`, blending
    /// bilinearly with the weights `weights` gives for an effect (an
    /// `MrslBlock` field), or from the nearest corner.
    pub(super) fn resamplers(&self, level: &Level, weights: &dyn Fn(&Self, EffectId) -> String) -> Vec<Resampler<'b>> {
        let c = self.checked();
        let iface = self.i.interface;
        let mut resamplers = vec![];
        for e in self.coarse_live() {
            let Some(slot) = iface.slot_of[e.index()].map(|s| &iface.slots[s]) else {
                continue;
            };
            let info = &c.effects[e.index()];
            let (filter, value) = if layout::uses_nearest(c, e) {
                // `select` takes no matrix: a matrix goes through `mrsl_select_m<N>`.
                let select = match info.ty {
                    Type::Matrix(n) => Name::SelectMatrix.of(n),
                    _ => "select".to_string(),
                };
                (
                    "nearest corner",
                    format!(
                        "{select}({select}(v0, v1, b.nearest == 1u), {select}(v2, v3, b.nearest == 3u), b.nearest >= 2u)"
                    ),
                )
            } else {
                let w = weights(self, e);
                ("bilinear", format!("v0 * {w}.x + v1 * {w}.y + v2 * {w}.z + v3 * {w}.w"))
            };
            resamplers.push(Resampler {
                effect: e,
                suffix: level.suffix,
                name: &info.name,
                ty: &info.ty,
                offset: slot.offset,
                wgsl_type: info.ty.wgsl(),
                stride: level.stride(iface),
                unpack: unpack_words(&info.ty, level.buffer),
                filter,
                value,
            });
        }
        resamplers
    }

    /// The resolvers of the neighbour function of effect `e`, which
    /// evaluates `chain` (in a fine kernel): `mrsl_resolve_<e>`, and in the
    /// dynamic fine kernel `mrsl_resolve2_<e>`, unless an earlier neighbour
    /// function's decide the same effects, or they decide every coarse
    /// effect (then the kernel's own resolvers serve). Returns the suffix of
    /// the resolvers to call: `_<name>` or empty.
    pub(super) fn neighbour_resolvers(
        &mut self,
        e: EffectId,
        chain: &[EffectId],
        written: &mut HashMap<BTreeSet<EffectId>, String>,
    ) -> String {
        let decisions = self.neighbour_decisions(chain);
        if decisions.len() == self.coarse_live().len() {
            return String::new();
        }
        if let Some(suffix) = written.get(&decisions) {
            return suffix.clone();
        }
        let name = &self.checked().effects[e.index()].name;
        self.line(0, format!("// Where neighbour evaluations of `{name}` take their coarse values from."));
        self.resolvers(Some(&Neighbour { effect: name, decisions: &decisions }));
        let suffix = format!("_{name}");
        written.insert(decisions, suffix.clone());
        suffix
    }

    /// The coarse effects whose decisions a neighbour evaluation of `chain`
    /// needs: its coarse effects, and, where a decision reads its users'
    /// (an effect not passed, or in a shared slot: rule 4 of
    /// docs/language.md, section 8.3), those users, transitively.
    pub(super) fn neighbour_decisions(&self, chain: &[EffectId]) -> BTreeSet<EffectId> {
        let c = self.checked();
        let iface = self.i.interface;
        let mut set: BTreeSet<EffectId> =
            chain.iter().copied().filter(|e| c.effects[e.index()].rate == Rate::Coarse).collect();
        let mut stack: Vec<EffectId> = set.iter().copied().collect();
        while let Some(e) = stack.pop() {
            if iface.is_passed(e) && !iface.is_shared(e) {
                continue;
            }
            for &u in &self.i.graph.users[e.index()] {
                if self.i.graph.live[u.index()] && c.effects[u.index()].rate == Rate::Coarse && set.insert(u) {
                    stack.push(u);
                }
            }
        }
        set
    }

    /// Declares `mrsl_b` (and in the dynamic mode `mrsl_b2`) for the pixel at
    /// `mrsl_pos` in the fine kernels; nothing elsewhere. `name` is the suffix
    /// of a neighbour function's own resolvers (`mrsl_resolve_<effect>`), or empty.
    pub(super) fn resolve_preamble(&mut self, indent: usize, name: &str) {
        // The first level's (in the dynamic mode the outer level's) resolver.
        let resolve = Name::Resolve.of(format!("{}{name}", Level::own(self.block).suffix));
        if self.preloads_corners() {
            // Where the entry point loaded its lane's corners, it resolved its
            // pixels too ([`Writer::effect_major_pixels`]); a position resolved
            // here (a neighbour function's, a compacted pixel's) loads its own.
            self.line(indent, format!("let {CORNERS} = {LOAD_CORNERS}({POS});"));
            self.line(indent, format!("let {BLOCK} = {resolve}({POS}, {CORNERS});"));
        } else if self.kind.is_fine() {
            self.line(indent, format!("let {BLOCK} = {resolve}({POS});"));
        }
        if self.kind == KernelKind::DynamicFine {
            self.resolve_inner(indent, name, [POS, BLOCK, INNER_BLOCK]);
        }
    }

    /// A coarse effect in a fine kernel: evaluated where it is refined,
    /// resampled elsewhere (when it is passed).
    pub(super) fn resolved_coarse_value(&mut self, e: EffectId, indent: usize, how: Evaluation) {
        let info = &self.checked().effects[e.index()];
        let (index, name) = (self.coarse_index[&e], self.effect_name(e));
        self.line(indent, format!("var {name}: {};", info.ty.wgsl()));
        if self.kind == KernelKind::DynamicFine {
            return self.dynamic_coarse_value(e, indent, how);
        }
        self.line(indent, format!("if ({IS_REFINED}({BLOCK}, {index}u)) {{"));
        self.evaluate(e, indent + 1, "", how);
        if self.i.interface.is_passed(e) {
            self.line(indent, "} else {");
            let resample = Name::Resample.within(Level::own(self.block).suffix, &info.name);
            let corners = if self.preloads_corners() { format!(", {CORNERS}") } else { String::new() };
            self.line(indent + 1, format!("{name} = {resample}({BLOCK}{corners});"));
        }
        self.line(indent, "}");
    }

    /// The fine kernels' `main` after `mrsl_tile_pixel`: the pixel's
    /// prologue resolves it (where the entry point has not: [`Scope`]) and, with
    /// statistics on, writes the refine mask and counts the coarse effects
    /// it re-evaluates; then the effects (see [`Writer::pixel_main`]).
    pub(super) fn fine_main(&mut self) {
        self.pixel_main(|w, scope| w.fine_prologue(scope), |w, e, indent| w.fine_coarse_value(e, indent));
    }

    /// The work of [`Self::fine_main`]'s lanes without its entry point (the
    /// tile kernel's `mrsl_tile_pixels`).
    pub(super) fn fine_lanes(&mut self) {
        self.pixel_lanes(&mut |w, scope| w.fine_prologue(scope), &mut |w, e, indent| w.fine_coarse_value(e, indent));
    }

    /// The refine mask's `.x` word at the pixel, from block `last`. In the
    /// multi-rate mode the resolve pass keeps its word (the 4x4 level's
    /// effects) in the stored values' last layer, and the fine pass takes
    /// those effects' bits from it: its own block only says they were loaded.
    fn level_mask_word(&mut self, last: &str) -> String {
        let refined = format!("{last}.refined0");
        if !matches!(self.file, KernelKind::MultiResolve | KernelKind::MultiFine) || self.level_values_layers() == 0 {
            return refined;
        }
        let layer = self.level_values_layers() - 1;
        if self.file == KernelKind::MultiResolve {
            self.line(3, format!("textureStore({LEVEL_VALUES}, {POS}, {layer}, vec4<u32>({refined}, 0u, 0u, 0u));"));
            return refined;
        }
        let outer = self.outer_effect_bits();
        format!("(({refined} & ~{outer}u) | (textureLoad({LEVEL_VALUES}, {POS}, {layer}).x & {outer}u))")
    }

    fn fine_coarse_value(&mut self, e: EffectId, indent: usize) {
        self.effect_chain(&[e], indent, Evaluation::Kernel);
    }

    /// A fine pixel's refine mask and statistics, where the kernel counts them.
    fn fine_prologue(&mut self, scope: Scope) {
        if !self.counts_stats() {
            return;
        }
        let w = self;
        if scope == Scope::Position {
            w.resolve_preamble(2, "");
        }
        // `mrsl_last` holds the innermost level: effects refined there are evaluated per pixel.
        let (last, from_inner) = if w.kind == KernelKind::DynamicFine {
            (INNER_BLOCK, format!("{BLOCK}.refined0 & ~{INNER_BLOCK}.refined0"))
        } else {
            (BLOCK, "0u".to_string())
        };
        w.statistics_on(2);
        let mask_y = w.mask_y(last, &from_inner);
        let mask_x = w.level_mask_word(last);
        let values: &super::writer::Values = &[("LAST", &last), ("MASK_X", &mask_x), ("FROM_INNER", &mask_y)];
        w.template(3, include_str!("templates/rate.wgsl"), values);
        // (A loaded effect is counted where the resolve pass evaluated it.)
        let counted: Vec<EffectId> = w.coarse_live().into_iter().filter(|&e| !w.is_loaded(e)).collect();
        for e in counted {
            let k = w.coarse_index[&e] as usize;
            w.count_refined(k, &format!("{IS_REFINED}({LAST_BLOCK}, {k}u)"));
        }
        // The multi-rate mode counts its background pixels once, in its last pass.
        if w.file != KernelKind::MultiResolve {
            w.count_background(LAST_BLOCK);
        }
        w.line(2, "}");
    }
}
