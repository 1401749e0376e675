//! The block kernels. The coarse kernel shades one coarse sample per B x B
//! block corner and writes its interface record; the fine kernel resolves,
//! per pixel, the four samples around it and resamples or re-evaluates each
//! coarse effect; the reference kernel evaluates everything per pixel. The
//! dynamic mode's kernels are the coarse and fine ones over two levels of
//! blocks; what only they add is in [`super::dynamic`]. What the fine
//! kernels of every family share (levels, resolvers as data, the refine
//! decisions) is in [`super::fine`]; the rate-image mode's coarse kernel
//! reuses this one's body ([`Writer::coarse_main`]).

use super::effects::{Evaluation, Key};
use super::fine::{CORNER_SAMPLES, Corners, LANES, Level, Resolver};
use super::names::{
    BACKGROUND, BLOCK_STRUCT, CORNERS_STRUCT, GID, INTERFACE, LEVEL_VALUES, NEIGHBOURS, Name, PIXEL, POS, RECORD,
    SAMPLES, STATS, STRIDE,
};
use super::words::{pack_words, test_bit, unpack_with};
use super::writer::{cut, fill};
use super::{ViewLevel, Writer};
use crate::check::{EffectId, InputId};
use crate::layout;
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::FINE_PIXELS_PER_LANE;
use std::collections::BTreeSet;

/// The corners of a block, in the order of `MrslBlock::corners`, and the
/// pixels their keys are loaded at (in `mrsl_resolve` and `mrsl_corners`).
const CORNERS: [&str; 4] = ["k00", "k10", "k01", "k11"];
const CORNER_PIXELS: [&str; 4] = ["p0", "vec2<i32>(p1.x, p0.y)", "vec2<i32>(p0.x, p1.y)", "p1"];
/// The corners' record texels in `mrsl_corners`, in the same order (`r00_<layer>`, ...).
const TEXELS: [&str; 4] = ["r00", "r10", "r01", "r11"];

/// The number of coarse samples along each axis of a `block` grid over an
/// image of `size`, as WGSL: the rule of [`mrsl_abi::geometry::sample_grid`].
pub(super) fn sample_grid(block: u32) -> String {
    format!("(size + vec2<i32>({})) / {block} + vec2<i32>(1)", block as i32 - 2)
}

/// The statements that place `pos` in its block of a `block` grid: `size`,
/// the sample grid `n`, the corner samples `i0`/`i1` and their pixels
/// `p0`/`p1` (in `mrsl_resolve` and `mrsl_corners`).
fn block_geometry(block: u32) -> String {
    let text = fill(include_str!("templates/block_geometry.wgsl"), &[("GRID", &sample_grid(block)), ("BLOCK", &block)]);
    text.trim_end().to_string()
}

/// Tests of `key` between corner `k00_<key>` and the corners `k10_`, `k01_`,
/// `k11_` (each name after `prefix`): whether the block's own corners disagree.
pub(super) fn corners_differ(key: &Key, prefix: &str) -> Vec<String> {
    let name = key.name;
    ["k10", "k01", "k11"]
        .iter()
        .map(|corner| key.differs(&format!("{prefix}k00_{name}"), &format!("{prefix}{corner}_{name}")))
        .collect()
}

impl Writer<'_, '_, '_> {
    /// The interface of the block coarse kernel (the record texture,
    /// written) and fine kernels (read), and what else they read.
    pub(super) fn interface_bindings(&mut self) {
        let l = self.i.layout;
        let records = if self.kind == KernelKind::Coarse {
            include_str!("templates/records_write.wgsl")
        } else {
            include_str!("templates/records_read.wgsl")
        };
        self.template(0, records, &[("GROUP", &l.interface.group), ("BINDING", &l.interface.binding)]);
        if self.stores_neighbours() {
            self.template(
                0,
                include_str!("templates/neighbours_binding.wgsl"),
                &[("GROUP", &l.interface.group), ("BINDING", &l.neighbours.binding)],
            );
        }
        if self.kind == KernelKind::DynamicFine {
            self.inner_interface_binding();
        }
        self.level_values_binding();
    }

    /// The multi-rate mode's stored `coarse(4)` values (layout
    /// `levels.values`): written by the resolve pass, read by the 2x2
    /// level and the pixels; nothing in the other kernels. A texture with a
    /// layer per word rather than a storage buffer, for the reason
    /// `InterfaceLayout` gives: llvmpipe loads a buffer word lane by lane.
    fn level_values_binding(&mut self) {
        let (ViewLevel::Outer { words, .. } | ViewLevel::Inner { words, .. }) = self.i.level else { return };
        // The resolve and fine passes hold the refine-mask word too (`plan::level_values_layers`).
        let layers = if self.file == KernelKind::MultiCoarse { words } else { self.level_values_layers() };
        if layers == 0 || self.file == KernelKind::MultiCoarse && matches!(self.i.level, ViewLevel::Outer { .. }) {
            return;
        }
        let binding = self.i.layout.levels.as_ref().expect("the multi-rate mode has levels").values.binding;
        let outer = mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK;
        let mask = if layers > words { ", then the resolve pass's refine-mask word" } else { "" };
        self.line(0, format!("// The coarse({outer}) values per pixel, a layer per word ({words}){mask}."));
        let group = self.i.layout.interface.group;
        let ty = "texture_storage_2d_array<r32uint, read_write>";
        self.line(0, format!("@group({group}) @binding({binding}) var {LEVEL_VALUES}: {ty};"));
        self.line(0, "");
    }

    /// The layers of the multi-rate mode's stored values ([`crate::plan::level_values_layers`]).
    pub(super) fn level_values_layers(&self) -> u32 {
        crate::plan::level_values_layers(self.i.layout)
    }

    /// The refine-mask bits of the multi-rate mode's 4x4 level's effects
    /// (the live `coarse(4)` effects among the first 32 counters).
    pub(super) fn outer_effect_bits(&self) -> u32 {
        let Some(levels) = &self.i.layout.levels else { return 0 };
        let c = self.checked();
        let outer = |e: &EffectId| levels.block[e.index()] == mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK;
        let bits =
            self.i.counters.iter().enumerate().filter(|(k, e)| *k < 32 && outer(e) && c.effects.len() > e.index());
        bits.fold(0u32, |mask, (k, _)| mask | (1u32 << k))
    }

    /// `mrsl_eval_<effect>` of an effect the inner view reads from the
    /// stored values: its value at the position's pixel, as the resolve pass stored it.
    pub(super) fn loaded_function(&mut self, e: EffectId) {
        let ViewLevel::Inner { values, words, .. } = self.i.level else { return };
        let info = &self.checked().effects[e.index()];
        let signature = self.eval_signature(e, false);
        let Some(&(_, offset)) = values.iter().find(|(v, _)| *v == e) else {
            // Read only by other coarse(4) effects, themselves loaded: never called.
            self.line(0, format!("// `{}` is read only at the 4x4 level.", info.name));
            self.line(0, format!("{signature} {{ return {}(); }}", info.ty.wgsl()));
            self.line(0, "");
            return;
        };
        self.line(0, format!("// `{}` as the resolve pass stored it at the position's pixel.", info.name));
        self.line(0, format!("{signature} {{"));
        debug_assert!(offset + info.ty.components() <= words);
        self.line(1, format!("let p = {PIXEL}({POS});"));
        let value = unpack_with(&info.ty, |k| format!("textureLoad({LEVEL_VALUES}, p, {}).x", offset + k));
        self.line(1, format!("return {value};"));
        self.line(0, "}");
        self.line(0, "");
    }

    /// Whether this is the multi-rate mode's 4x4 level, which does not
    /// count background samples: the mode counts those of its 2x2 level.
    pub(super) fn is_outer_level(&self) -> bool {
        self.file == KernelKind::MultiCoarse && self.block == mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK
    }

    /// Whether the kernel binds the statistics for the background samples
    /// alone: the block and rate-image coarse kernels, with a background rule.
    pub(super) fn counts_background_samples(&self) -> bool {
        matches!(self.kind, KernelKind::Coarse | KernelKind::RateCoarse)
            && self.has_background()
            && !self.is_outer_level()
    }

    /// Whether the kernel writes its records as texels of the record
    /// texture (the block coarse kernel) rather than as buffer words.
    fn writes_record_texels(&self) -> bool {
        self.kind == KernelKind::Coarse
    }

    /// The statement storing `value` as word `word` of this sample's record:
    /// into the word's local (flushed to the record texture at the end of
    /// the kernel) or into the interface buffer.
    fn record_word_store(&self, word: u32, value: &str) -> String {
        if self.writes_record_texels() {
            format!("{} = {value};", Name::RecordWord.of(word))
        } else {
            format!("{INTERFACE}[{RECORD} + {word}u] = {value};")
        }
    }

    // ---- Coarse kernel ----------------------------------------------------------

    /// Whether this is the block coarse kernel with neighbour values
    /// (layout `neighbours`): `coarse_neighbours` stores them at every
    /// sample, and `mrsl_at_<effect>` reads them.
    pub(super) fn stores_neighbours(&self) -> bool {
        // The multi-rate mode's coarse kernels evaluate derivatives' neighbours in place.
        (self.file == KernelKind::Coarse || self.writes_coarse_part()) && self.i.layout.neighbours.words > 0
    }

    /// The effects of the neighbour values, in layout order, with their word offsets.
    pub(super) fn neighbour_values(&self) -> Vec<(EffectId, u32)> {
        let c = self.checked();
        let id = |name: &str| {
            let k = c.effects.iter().position(|e| e.name == name).expect("the layout names effects of the program");
            EffectId(k as u32)
        };
        self.i.layout.neighbours.effects.iter().map(|v| (id(&v.name), v.offset)).collect()
    }

    /// `coarse_neighbours`, the block coarse kernel's first entry point:
    /// each neighbour value evaluated at the sample (for its value alone,
    /// as a neighbour evaluation computes it) and stored. Empty without them.
    fn neighbours_entry(&mut self) {
        let [x, y, z] = self.kind.workgroup_size();
        if !self.stores_neighbours() {
            self.line(0, "// No neighbour values (layout `neighbours`): the runtime does not dispatch this.");
            self.line(0, format!("@compute @workgroup_size({x}, {y}, {z})"));
            self.line(0, format!("fn {}() {{}}", mrsl_abi::entry::COARSE_NEIGHBOURS));
            self.line(0, "");
            return;
        }
        let [head, tail] = cut(include_str!("templates/coarse_main.wgsl"), &["BODY"]);
        let values: &super::writer::Values = &[
            ("WORKGROUP", &format!("{x}, {y}, {z}")),
            ("RECORD", &""),
            ("ENTRY", &mrsl_abi::entry::COARSE_NEIGHBOURS),
        ];
        self.template(0, head, values);
        self.store_neighbour_values(1, POS);
        self.template(0, tail, &[]);
        self.line(0, "");
    }

    /// Effect `e` as the neighbour values hold it at texel `texel` (WGSL):
    /// its words, unpacked, from the layers at its offset.
    pub(super) fn neighbour_value(&self, e: EffectId, texel: &str) -> String {
        let (_, offset) = self.neighbour_values().into_iter().find(|&(v, _)| v == e).expect("a stored effect");
        let ty = &self.checked().effects[e.index()].ty;
        if self.writes_coarse_part() {
            return unpack_with(ty, |j| Self::tile_neighbour_word(offset + j, texel));
        }
        unpack_with(ty, |j| format!("textureLoad({NEIGHBOURS}, {texel}, {}).x", offset + j))
    }

    /// The neighbour values evaluated at `mrsl_pos` (for their values alone,
    /// as a neighbour evaluation computes them) and stored at texel `texel`
    /// of `mrsl_neighbours`, a layer per word: the body of `coarse_neighbours`
    /// and of the hierarchical kernel's `hier_level0_values`.
    pub(super) fn store_neighbour_values(&mut self, indent: usize, texel: &str) {
        let c = self.checked();
        let stored = self.neighbour_values();
        // The stored effects and what they read, each evaluated once, in dependency order.
        let needed: BTreeSet<EffectId> = stored.iter().flat_map(|&(e, _)| self.i.graph.closure(e, c)).collect();
        let chain: Vec<EffectId> = self.i.graph.order.iter().copied().filter(|e| needed.contains(e)).collect();
        self.effect_chain(&chain, indent, Evaluation::ValueOnly);
        for (e, offset) in stored {
            self.store_neighbour_words(indent, texel, e, offset);
        }
    }

    /// Neighbour value `e`, computed into its local, stored from word
    /// `offset` at texel `texel` (in the tile kernel, at its slot).
    pub(super) fn store_neighbour_words(&mut self, indent: usize, texel: &str, e: EffectId, offset: u32) {
        let info = &self.checked().effects[e.index()];
        for (j, word) in pack_words(&self.effect_name(e), &info.ty).iter().enumerate() {
            let layer = offset + j as u32;
            let store = if self.writes_coarse_part() {
                Self::tile_neighbour_store(layer, word)
            } else {
                format!("textureStore({NEIGHBOURS}, {texel}, {layer}, vec4<u32>({word}, 0u, 0u, 0u));")
            };
            self.line(indent, store);
        }
    }

    /// The entry points of the block modes' coarse kernel and of the dynamic
    /// mode's second level.
    pub(super) fn coarse_entry(&mut self) {
        if self.kind == KernelKind::DynamicCoarse {
            self.parent_refined();
        }
        if self.file == KernelKind::Coarse {
            self.neighbours_entry();
        }
        self.coarse_main(include_str!("templates/coarse_main.wgsl"));
    }

    /// The main entry point of a coarse kernel, from `main` (a template
    /// with a `BODY` hole, after which the sample is at `mrsl_pos`): the
    /// coarse effects evaluated, then the sample's record written.
    pub(super) fn coarse_main(&mut self, main: &str) {
        let [x, y, z] = self.kind.workgroup_size();
        let [head, tail] = cut(main, &["BODY"]);
        // Where the sample's record starts in a buffer; the record texture is addressed by `mrsl_pos`.
        let record = if self.writes_record_texels() {
            String::new()
        } else {
            format!("\n    let {RECORD} = ({GID}.y * u32({SAMPLES}.x) + {GID}.x) * {STRIDE};")
        };
        self.template(
            0,
            head,
            &[
                ("WORKGROUP", &format!("{x}, {y}, {z}")),
                ("RECORD", &record),
                ("ENTRY", &self.file.main_entry_point()),
                ("WORK_GROUP", &x),
                ("MAX_X", &mrsl_abi::geometry::RATE_ARGS_MAX_X),
            ],
        );
        if self.kind == KernelKind::DynamicCoarse {
            self.dynamic_coarse_gate();
        }
        if self.writes_record_texels() {
            // Words are gathered in locals and stored a texel at a time; a word no
            // effect writes here (a shared slot's other effect) is stored as 0.
            for w in 0..self.i.interface.stride {
                self.line(1, format!("var {} = 0u;", Name::RecordWord.of(w)));
            }
        }
        if let Some((_, samples)) = self.i.layout.background_counters().filter(|_| !self.is_outer_level()) {
            let on = super::pixel::statistics_enabled();
            let background =
                if self.writes_coarse_part() { self.owned_background() } else { format!("{BACKGROUND}({POS})") };
            self.line(1, format!("if ({on} && {background}) {{ atomicAdd(&{STATS}[{samples}], 1u); }}"));
        }
        self.coarse_values();
        self.record_flags();
        self.record_slots();
        if self.writes_coarse_part() {
            self.tile_record_stores();
        } else if self.writes_record_texels() {
            self.record_texels();
        }
        self.template(0, tail, &[]);
    }

    /// Every live coarse effect at the sample, in dependency order.
    fn coarse_values(&mut self) {
        let c = self.checked();
        let stored: Vec<EffectId> = if self.stores_neighbours() {
            self.neighbour_values().into_iter().map(|(e, _)| e).collect()
        } else {
            vec![]
        };
        for e in self.coarse_live() {
            let info = &c.effects[e.index()];
            self.line(1, format!("// coarse effect `{}`", info.name));
            if stored.contains(&e) && self.writes_coarse_part() {
                // The tile's neighbour phase kept its value here, and its flag.
                self.kept_neighbour_value(e);
            } else if stored.contains(&e) && !info.has_refine {
                // Its value here is what `coarse_neighbours` stored here: the same evaluation.
                let name = self.effect_name(e);
                self.line(1, format!("let {name} = {}({POS});", Name::At.of(&info.name)));
            } else {
                self.effect_chain(&[e], 1, Evaluation::Kernel);
            }
        }
    }

    /// The sample's refine flags, into the first words of its record.
    fn record_flags(&mut self) {
        let flag_words = self.i.interface.flag_words;
        if flag_words == 0 {
            return;
        }
        self.template(0, include_str!("templates/refine_flags.wgsl"), &[]);
        self.declare_flag_words(flag_words);
        for e in self.coarse_live() {
            self.set_refine_flag(e, 1);
        }
        for w in 0..flag_words {
            let store = self.record_word_store(w, &Name::FlagWord.of(w));
            self.line(1, store);
        }
    }

    /// The passed values, each into its slot of the record; a shared slot
    /// holds whichever effect this sample's own flags say is passed.
    fn record_slots(&mut self) {
        let c = self.checked();
        for (k, slot) in self.i.interface.slots.iter().enumerate() {
            let names: Vec<&str> = slot.effects.iter().map(|e| c.effects[e.index()].name.as_str()).collect();
            self.line(
                1,
                format!("// slot {k}: words {}..{} ({})", slot.offset, slot.offset + slot.size, names.join(", ")),
            );
            for &e in &slot.effects {
                let words = pack_words(&self.effect_name(e), &c.effects[e.index()].ty);
                let writes: Vec<String> =
                    words.iter().enumerate().map(|(j, w)| self.record_word_store(slot.offset + j as u32, w)).collect();
                if slot.effects.len() > 1 {
                    let cond = self.store_condition(e, &|bit| test_bit(Name::FlagWord.prefix(), bit));
                    self.line(1, format!("if ({cond}) {{"));
                    for wline in writes {
                        self.line(2, wline);
                    }
                    self.line(1, "}");
                } else {
                    for wline in writes {
                        self.line(1, wline);
                    }
                }
            }
        }
    }

    /// The record's word locals stored into the record texture, four words a texel.
    fn record_texels(&mut self) {
        let stride = self.i.interface.stride;
        for layer in 0..stride.div_ceil(4) {
            let words: Vec<String> = (4 * layer..4 * layer + 4)
                .map(|w| if w < stride { Name::RecordWord.of(w) } else { "0u".to_string() })
                .collect();
            self.line(1, format!("textureStore({INTERFACE}, {POS}, {layer}, vec4<u32>({}));", words.join(", ")));
        }
    }

    /// The pass condition of `e` as WGSL, over flag bits rendered by `bit`.
    pub(super) fn store_condition(&self, e: EffectId, bit: &dyn Fn(u32) -> String) -> String {
        let iface = self.i.interface;
        let cond = iface.conditions[e.index()].as_ref().expect("passed effects have a condition");
        let mut any = vec![];
        if cond.fine_user {
            any.push("true".to_string());
        }
        for u in &cond.refining_users {
            any.push(bit(iface.refine_bit[u.index()].expect("refining users have a bit")));
        }
        let any = if any.is_empty() { "false".to_string() } else { any.join(" || ") };
        match iface.refine_bit[e.index()] {
            Some(b) if cond.self_refines => format!("!{} && ({any})", bit(b)),
            _ => format!("({any})"),
        }
    }

    // ---- Fine kernel ------------------------------------------------------------

    /// `MrslBlock` and the resolvers, getters and resamplers of the fine kernel's levels.
    pub(super) fn fine_support(&mut self) {
        if self.coarse_live().is_empty() {
            return;
        }
        let block_struct = include_str!("templates/block_struct.wgsl");
        self.block_struct(block_struct, |w| {
            for (s, keys) in w.edge_sets().iter().enumerate() {
                let names: Vec<&str> = keys.iter().map(|k| w.checked().inputs[k.index()].name.as_str()).collect();
                w.line(1, format!("weights{s}: vec4<f32>, // the corners on the pixel's side of {}", names.join(", ")));
            }
        });
        if self.preloads_corners() {
            self.corners_function();
        }
        if self.kind == KernelKind::DynamicFine {
            self.any_refined(self.mask_words());
            self.fine_level(&Level::DYNAMIC_OUTER);
            self.fine_level(&Level::DYNAMIC_INNER);
        } else {
            self.fine_level(&Level::own(self.block));
        }
    }

    /// `MrslCorners` and `mrsl_corners`: the keys and record words of a block's four coarse samples.
    fn corners_function(&mut self) {
        let stride = self.i.interface.stride;
        let keys = self.keys_of(&self.coarse_live());
        let [head, middle, tail] = cut(include_str!("templates/corners.wgsl"), &["FIELDS", "LOADS"]);
        self.template(0, head, &[]);
        for key in &keys {
            for corner in CORNERS {
                self.line(1, format!("{corner}_{}: {},", key.name, key.ty));
            }
        }
        for w in 0..stride {
            self.line(1, format!("w{w}: vec4<u32>,"));
        }
        if keys.is_empty() && stride == 0 {
            self.line(1, "none: u32, // a WGSL structure has at least one member");
        }
        let geometry = block_geometry(self.block);
        let values: &super::writer::Values = &[("GEOMETRY", &geometry)];
        self.template(0, middle, values);
        for key in &keys {
            let name = key.name;
            for (corner, at) in CORNERS.iter().zip(CORNER_PIXELS) {
                self.line(1, format!("c.{corner}_{name} = {};", key.load(at)));
            }
        }
        // A texel holds four words of a record: one load per corner and texel.
        let texels = ["i0", "vec2<i32>(i1.x, i0.y)", "vec2<i32>(i0.x, i1.y)", "i1"];
        if self.file == KernelKind::Tile {
            // The tile kernel's records are in workgroup memory, a word at a time.
            for w in 0..stride {
                let words: Vec<String> = texels.iter().map(|at| Self::tile_corner_word(w, at)).collect();
                self.line(1, format!("c.w{w} = vec4<u32>({});", words.join(", ")));
            }
        }
        for layer in 0..stride.div_ceil(4).min(if self.file == KernelKind::Tile { 0 } else { u32::MAX }) {
            for (corner, at) in TEXELS.iter().zip(texels) {
                self.line(1, format!("let {corner}_{layer} = textureLoad({INTERFACE}, {at}, {layer}, 0);"));
            }
            for w in 4 * layer..(4 * layer + 4).min(stride) {
                let lane = LANES[(w % 4) as usize];
                let words: Vec<String> = TEXELS.iter().map(|corner| format!("{corner}_{layer}.{lane}")).collect();
                self.line(1, format!("c.w{w} = vec4<u32>({});", words.join(", ")));
            }
        }
        self.template(0, tail, values);
    }

    /// The distinct sets of discontinuity keys that the live coarse effects
    /// read (`EffectGraph::keys`), each non-empty: `MrslBlock::weights<s>`
    /// holds the resampling weights of the effects that read set `s`.
    pub(super) fn edge_sets(&self) -> Vec<Vec<InputId>> {
        let sets: BTreeSet<Vec<InputId>> = self
            .coarse_live()
            .into_iter()
            .map(|e| self.i.graph.keys[e.index()].clone())
            .filter(|keys| !keys.is_empty())
            .collect();
        sets.into_iter().collect()
    }

    /// The index in [`Self::edge_sets`] of the keys coarse effect `e` reads, if it reads any.
    fn edge_set_of(&self, e: EffectId) -> Option<usize> {
        let keys = &self.i.graph.keys[e.index()];
        self.edge_sets().iter().position(|set| set == keys)
    }

    /// In `mrsl_resolve`, after the keys' `side_<key>`: for each key set the
    /// `coarse` effects read, the corners on the pixel's side of all of them
    /// (`side<s>`) and their bilinear weights renormalised (`b.weights<s>`,
    /// exactly `b.weights` where every corner is on the pixel's side, so
    /// that a block without an edge blends as before). `sum<s>` is zero
    /// where no corner with a weight is on the pixel's side: the effects are
    /// then evaluated per pixel ([`Self::edge_discontinuity`]).
    fn edge_weights(&mut self, coarse: &[EffectId]) {
        let c = self.checked();
        let used: BTreeSet<usize> = coarse.iter().filter_map(|&e| self.edge_set_of(e)).collect();
        for (s, keys) in self.edge_sets().iter().enumerate() {
            if !used.contains(&s) {
                continue;
            }
            let sides: Vec<String> = keys.iter().map(|k| format!("side_{}", c.inputs[k.index()].name)).collect();
            let names: Vec<&str> = keys.iter().map(|k| c.inputs[k.index()].name.as_str()).collect();
            self.template(
                0,
                include_str!("templates/edge_weights.wgsl"),
                &[("SET", &s), ("KEYS", &names.join(", ")), ("SIDES", &sides.join(" & "))],
            );
        }
    }

    /// `disc || ...`: true where the fine kernel evaluates coarse effect `e`
    /// per pixel because of a discontinuity: forced refinement, or an edge of
    /// a key `e` reads with no corner on the pixel's side to resample from
    /// (any corner across it for an effect resampled from the nearest corner,
    /// which cannot be renormalised, or whose value reads a derivative, which
    /// at a corner may have been taken across the edge).
    fn edge_discontinuity(&self, e: EffectId) -> String {
        match self.edge_set_of(e) {
            None => "disc".to_string(),
            Some(s) if layout::uses_nearest(self.checked(), e) || self.value_reads_derivatives(e) => {
                format!("disc || !all(side{s})")
            }
            Some(s) => format!("disc || torn{s}"),
        }
    }

    /// The resampling weights of coarse effect `e`: those of its key set's
    /// corners on the pixel's side, or of all four.
    fn edge_weights_of(&self, e: EffectId) -> String {
        match self.edge_set_of(e) {
            Some(s) => format!("b.weights{s}"),
            None => "b.weights".to_string(),
        }
    }

    /// `mrsl_resolve{suffix}` of a block level: where a pixel takes its
    /// coarse values from at the level, and which of `r.coarse` it
    /// evaluates per pixel. A neighbour function's resolver decides only
    /// the coarse effects its evaluation reads and the users their decisions
    /// depend on ([`Writer::neighbour_decisions`]), so that a derivative
    /// does not decide every coarse effect of the program again at each
    /// neighbour; their decisions are those of the full resolver.
    pub(super) fn resolve_function(&mut self, r: &Resolver) {
        let [head, corners, refined] = cut(include_str!("templates/resolve.wgsl"), &["CORNERS", "REFINED"]);
        let level = r.level;
        let params = match (level.parent, r.corners) {
            (true, _) => format!("pos: vec2<i32>, parent: {BLOCK_STRUCT}"),
            (false, Corners::Preloaded) => format!("pos: vec2<i32>, c: {CORNERS_STRUCT}"),
            (false, Corners::Loaded) => "pos: vec2<i32>".to_string(),
        };
        if level.parent {
            self.inner_level_note(level.block);
        }
        let geometry = block_geometry(level.block);
        self.template(0, head, &[("SUFFIX", &r.name), ("PARAMS", &params), ("GEOMETRY", &geometry)]);
        if level.parent {
            self.stale_corners(level.buffer, level.stride(self.i.interface));
        }
        for key in self.keys_of(&r.coarse) {
            self.key_sides(r, &key);
        }
        self.edge_weights(&r.coarse);
        self.corner_flag_words(r);
        self.template(0, corners, &[]);
        self.refine_decisions(r, CORNER_SAMPLES.len(), &|w, e| w.edge_discontinuity(e));
        self.background_decision();
        self.template(0, refined, &[]);
    }

    /// In a block resolver: `key` at the pixel and at the corners, and which
    /// corners are on the pixel's side of it.
    fn key_sides(&mut self, r: &Resolver, key: &Key) {
        let name = key.name;
        let side: Vec<String> =
            CORNERS.iter().map(|corner| key.matches(&format!("k_{name}"), &format!("{corner}_{name}"))).collect();
        let at: Vec<String> = CORNERS
            .iter()
            .zip(CORNER_PIXELS)
            .map(|(corner, pixel)| match r.corners {
                Corners::Preloaded => format!("c.{corner}_{name}"),
                Corners::Loaded => key.load(pixel),
            })
            .collect();
        self.template(
            0,
            include_str!("templates/resolve_key.wgsl"),
            &[
                ("NAME", &name),
                ("LOAD", &key.loader()),
                ("K00", &at[0]),
                ("K10", &at[1]),
                ("K01", &at[2]),
                ("K11", &at[3]),
                ("SIDE", &side.join(", ")),
            ],
        );
    }

    /// `mrsl_resolve{suffix}` and the getters and resamplers of one block level of coarse samples.
    fn fine_level(&mut self, level: &Level) {
        let r = self.resolver(level, None);
        self.resolve_function(&r);
        for s in self.resamplers(level, &|w, e| w.edge_weights_of(e)) {
            if r.corners == Corners::Loaded {
                self.resampler_template(include_str!("templates/resample.wgsl"), &s.values(), &s.wgsl_type);
                continue;
            }
            let corner = |lane: &str| unpack_with(s.ty, |k| format!("c.w{}.{lane}", s.offset + k));
            let (v0, v1, v2, v3) = (corner("x"), corner("y"), corner("z"), corner("w"));
            let ty = s.ty.wgsl();
            let values: &super::writer::Values = &[
                ("SUFFIX", &level.suffix),
                ("NAME", &s.name),
                ("TYPE", &ty),
                ("V0", &v0),
                ("V1", &v1),
                ("V2", &v2),
                ("V3", &v3),
                ("FILTER", &s.filter),
                ("VALUE", &s.value),
            ];
            self.resampler_template(include_str!("templates/resample_corners.wgsl"), values, &ty);
        }
    }

    /// Entry point of the block and dynamic fine kernels and of the reference kernel.
    pub(super) fn pixel_entry(&mut self) {
        if self.file == KernelKind::Tile {
            self.lane_functions();
            self.tile_pixel_blocks(self.block, FINE_PIXELS_PER_LANE);
            return self.tile_entry(|w| {
                w.tile_pixels_head();
                w.fine_lanes();
                w.line(0, "}");
                w.line(0, "");
            });
        }
        if self.compacts() {
            self.tile_pixel_blocks(self.block, 1);
            self.tile_list_entries();
            return self.compacted_fine_entry();
        }
        match self.kind {
            KernelKind::Fine | KernelKind::DynamicFine => {
                self.lane_functions();
                self.tile_pixel_blocks(self.block, FINE_PIXELS_PER_LANE);
            }
            // The reference kernel has no blocks; it lays its tiles out in 2x2 ones.
            _ => self.tile_pixel_blocks(2, 1),
        }
        self.tile_list_entries();
        self.fine_main();
    }
}
