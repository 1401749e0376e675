//! The block kernels. The coarse kernel shades one coarse sample per B x B
//! block corner and writes its interface record; the fine kernel resolves,
//! per pixel, the four samples around it and resamples or re-evaluates each
//! coarse effect; the reference kernel evaluates everything per pixel. The
//! dynamic mode's kernels are the coarse and fine ones over two levels of
//! blocks; what only they add is in [`super::dynamic`].

use super::Writer;
use super::effects::Key;
use super::words::{bit, pack_words, test_bit, unpack_with, unpack_words};
use super::writer::{cut, fill};
use crate::check::{EffectId, InputId};
use crate::layout;
use crate::syntax::ast::Rate;
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::{DYNAMIC_TAG_WORDS, FINE_PIXELS_PER_LANE};
use std::collections::{BTreeSet, HashMap};

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
    /// The interface of the coarse (written) and fine (read) kernels: the
    /// block modes' record texture, or the rate-image mode's buffer.
    pub(super) fn interface_bindings(&mut self) {
        let l = self.i.layout;
        let values: &super::writer::Values = &[("GROUP", &l.interface.group), ("BINDING", &l.interface.binding)];
        match self.kind {
            KernelKind::Coarse => self.template(0, include_str!("templates/records_write.wgsl"), values),
            KernelKind::Fine | KernelKind::DynamicFine => {
                self.template(0, include_str!("templates/records_read.wgsl"), values)
            }
            _ => {
                let access = if self.kind == KernelKind::RateCoarse { "read_write" } else { "read" };
                let values: &super::writer::Values =
                    &[("GROUP", &l.interface.group), ("BINDING", &l.interface.binding), ("ACCESS", &access)];
                self.template(0, include_str!("templates/interface.wgsl"), values)
            }
        }
        if self.stores_neighbours() {
            let l = self.i.layout;
            self.template(
                0,
                include_str!("templates/neighbours_binding.wgsl"),
                &[("GROUP", &l.interface.group), ("BINDING", &l.neighbours.binding)],
            );
        }
        if self.kind == KernelKind::DynamicFine {
            self.inner_interface_binding();
        }
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
            format!("mrsl_w{word} = {value};")
        } else {
            format!("mrsl_interface[mrsl_rec + {word}u] = {value};")
        }
    }

    // ---- Coarse kernel ----------------------------------------------------------

    /// Whether this is the block coarse kernel with neighbour values
    /// (layout `neighbours`): `coarse_neighbours` stores them at every
    /// sample, and `mrsl_at_<effect>` reads them.
    pub(super) fn stores_neighbours(&self) -> bool {
        self.kind == KernelKind::Coarse && self.i.layout.neighbours.words > 0
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
        let c = self.checked();
        let stored = self.neighbour_values();
        // The stored effects and what they read, each evaluated once, in dependency order.
        let needed: BTreeSet<EffectId> = stored.iter().flat_map(|&(e, _)| self.i.graph.closure(e, c)).collect();
        let chain: Vec<EffectId> = self.i.graph.order.iter().copied().filter(|e| needed.contains(e)).collect();
        self.value_only = true;
        self.effect_chain(&chain, 1);
        self.value_only = false;
        for (e, offset) in stored {
            let info = &c.effects[e.index()];
            for (j, word) in pack_words(&self.effect_name(e), &info.ty).iter().enumerate() {
                let layer = offset + j as u32;
                self.line(
                    1,
                    format!("textureStore(mrsl_neighbours, mrsl_pos, {layer}, vec4<u32>({word}, 0u, 0u, 0u));"),
                );
            }
        }
        self.template(0, tail, &[]);
        self.line(0, "");
    }

    pub(super) fn coarse_entry(&mut self) {
        if self.kind == KernelKind::DynamicCoarse {
            self.parent_refined();
        }
        if self.kind == KernelKind::Coarse {
            self.neighbours_entry();
        }
        let c = self.checked();
        let iface = self.i.interface;
        let [x, y, z] = self.kind.workgroup_size();
        let main = if self.kind == KernelKind::RateCoarse {
            include_str!("templates/rate_coarse_main.wgsl")
        } else {
            include_str!("templates/coarse_main.wgsl")
        };
        let [head, tail] = cut(main, &["BODY"]);
        // Where the sample's record starts in a buffer; the record texture is addressed by `mrsl_pos`.
        let record = if self.writes_record_texels() {
            String::new()
        } else {
            "\n    let mrsl_rec = (mrsl_gid.y * u32(mrsl_n.x) + mrsl_gid.x) * MRSL_STRIDE;".to_string()
        };
        self.template(
            0,
            head,
            &[
                ("WORKGROUP", &format!("{x}, {y}, {z}")),
                ("RECORD", &record),
                ("ENTRY", &self.kind.main_entry_point()),
                ("WORK_GROUP", &x),
                ("MAX_X", &mrsl_abi::geometry::RATE_ARGS_MAX_X),
            ],
        );
        if self.kind == KernelKind::DynamicCoarse {
            self.dynamic_coarse_gate();
        }
        let stride = iface.stride;
        if self.writes_record_texels() {
            // Words are gathered in locals and stored a texel at a time; a word no
            // effect writes here (a shared slot's other effect) is stored as 0.
            for w in 0..stride {
                self.line(1, format!("var mrsl_w{w} = 0u;"));
            }
        }
        let coarse = self.coarse_live();
        let stored: Vec<EffectId> = if self.stores_neighbours() {
            self.neighbour_values().into_iter().map(|(e, _)| e).collect()
        } else {
            vec![]
        };
        for &e in &coarse {
            let info = &c.effects[e.index()];
            self.line(1, format!("// coarse effect `{}`", info.name));
            if stored.contains(&e) && !info.has_refine {
                // Its value here is what `coarse_neighbours` stored here: the same evaluation.
                let name = self.effect_name(e);
                self.line(1, format!("let {name} = mrsl_at_{}(mrsl_pos);", info.name));
            } else {
                self.effect_chain(&[e], 1);
            }
        }
        if iface.flag_words > 0 {
            self.template(0, include_str!("templates/refine_flags.wgsl"), &[]);
            self.declare_flag_words(iface.flag_words);
            for &e in &coarse {
                self.set_refine_flag(e, 1);
            }
            for w in 0..iface.flag_words {
                let store = self.record_word_store(w, &format!("mrsl_flags{w}"));
                self.line(1, store);
            }
        }
        for (k, slot) in iface.slots.iter().enumerate() {
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
                    // A shared slot holds whichever effect this sample's own flags say is passed.
                    let cond = self.store_condition(e, &|bit| test_bit("mrsl_flags", bit));
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
        if self.writes_record_texels() {
            for layer in 0..stride.div_ceil(4) {
                let words: Vec<String> = (4 * layer..4 * layer + 4)
                    .map(|w| if w < stride { format!("mrsl_w{w}") } else { "0u".to_string() })
                    .collect();
                self.line(
                    1,
                    format!("textureStore(mrsl_interface, mrsl_pos, {layer}, vec4<u32>({}));", words.join(", ")),
                );
            }
        }
        self.template(0, tail, &[]);
    }

    /// The pass condition of `e` as WGSL, over flag bits rendered by `bit`.
    fn store_condition(&self, e: EffectId, bit: &dyn Fn(u32) -> String) -> String {
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
        let coarse = self.coarse_live();
        if coarse.is_empty() {
            return;
        }
        let mask_words = (coarse.len() as u32).div_ceil(32);
        let rate = self.kind == KernelKind::RateFine;
        let block_struct = if rate {
            include_str!("templates/rate_block_struct.wgsl")
        } else {
            include_str!("templates/block_struct.wgsl")
        };
        let [head, tail] = cut(block_struct, &["REFINED_WORDS"]);
        self.template(0, head, &[]);
        // Separate words, not an array: llvmpipe spills dynamically indexed
        // arrays in structs to memory, which made every lookup a memory access.
        if !rate {
            for (s, keys) in self.edge_sets().iter().enumerate() {
                let names: Vec<&str> = keys.iter().map(|k| self.checked().inputs[k.index()].name.as_str()).collect();
                self.line(
                    1,
                    format!("weights{s}: vec4<f32>, // the corners on the pixel's side of {}", names.join(", ")),
                );
            }
        }
        for w in 0..mask_words {
            self.line(1, format!("refined{w}: u32, // bit k: coarse effect 32 * {w} + k is evaluated per pixel"));
        }
        let mut word = "b.refined0".to_string();
        for w in 1..mask_words {
            word = format!("select({word}, b.refined{w}, k >= {}u)", 32 * w);
        }
        self.template(0, tail, &[("WORD", &word)]);
        if self.preloads_corners() {
            self.corners_function();
        }
        if self.kind == KernelKind::DynamicFine {
            self.any_refined(mask_words);
            self.fine_level(&Level::DYNAMIC_OUTER);
            self.fine_level(&Level::DYNAMIC_INNER);
        } else {
            self.fine_level(&Level { suffix: "", block: self.block, buffer: "mrsl_interface", parent: false });
        }
    }

    /// Whether the kernel's resolvers and resamplers of its first level
    /// take the block's corners preloaded (`MrslCorners`): the block modes'
    /// fine kernels and the dynamic fine kernel (its 4x4 level), whose lanes
    /// shade [`FINE_PIXELS_PER_LANE`] pixels of one block.
    pub(super) fn preloads_corners(&self) -> bool {
        matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine)
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
                self.line(1, format!("c.{corner}_{name} = mrsl_load_{name}({at});"));
            }
        }
        // A texel holds four words of a record: one load per corner and texel.
        let texels = ["i0", "vec2<i32>(i1.x, i0.y)", "vec2<i32>(i0.x, i1.y)", "i1"];
        for layer in 0..stride.div_ceil(4) {
            for (corner, at) in TEXELS.iter().zip(texels) {
                self.line(1, format!("let {corner}_{layer} = textureLoad(mrsl_interface, {at}, {layer}, 0);"));
            }
            for w in 4 * layer..(4 * layer + 4).min(stride) {
                let lane = ["x", "y", "z", "w"][(w % 4) as usize];
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

    /// `mrsl_resolve{suffix}`: where a pixel takes its coarse values from at
    /// one level, and which coarse effects it evaluates per pixel. With
    /// `only`, `mrsl_resolve{suffix}_<effect>` for the neighbour function of
    /// that effect: the same function deciding only the given effects (the
    /// coarse effects the neighbour evaluation reads, and the users their
    /// decisions depend on, [`Writer::neighbour_decisions`]), so that a
    /// derivative does not decide every coarse effect of the program again
    /// at each neighbour. Their decisions are those of the full function.
    pub(super) fn resolve_function(&mut self, level: &Level, only: Option<(&str, &BTreeSet<EffectId>)>) {
        let c = self.checked();
        let coarse: Vec<EffectId> =
            self.coarse_live().into_iter().filter(|e| only.is_none_or(|(_, set)| set.contains(e))).collect();
        let iface = self.i.interface;
        let (sfx, bk, buf) = (level.suffix, level.block, level.buffer);
        let stride = if level.parent { iface.stride + DYNAMIC_TAG_WORDS } else { iface.stride };
        // The samples a pixel resamples from: a block's four corners, or in the
        // rate-image mode each corner's two border samples.
        let rate = self.kind == KernelKind::RateFine;
        let samples: &[&str] = if rate {
            &[
                "b.corners.x",
                "b.corners.y",
                "b.corners.z",
                "b.corners.w",
                "b.others.x",
                "b.others.y",
                "b.others.z",
                "b.others.w",
            ]
        } else {
            &["b.corners.x", "b.corners.y", "b.corners.z", "b.corners.w"]
        };
        let resolve =
            if rate { include_str!("templates/rate_resolve.wgsl") } else { include_str!("templates/resolve.wgsl") };
        let [head, corners, refined] = cut(resolve, &["CORNERS", "REFINED"]);
        let preloaded = self.preloads_corners() && !level.parent;
        let params = if level.parent {
            self.inner_level_note(bk);
            "pos: vec2<i32>, parent: MrslBlock"
        } else if preloaded {
            "pos: vec2<i32>, c: MrslCorners"
        } else {
            "pos: vec2<i32>"
        };
        let name = match only {
            Some((effect, _)) => format!("{sfx}_{effect}"),
            None => sfx.to_string(),
        };
        let geometry = block_geometry(bk);
        self.template(0, head, &[("SUFFIX", &name), ("PARAMS", &params), ("GEOMETRY", &geometry)]);
        if level.parent {
            self.stale_corners(buf, stride);
        }
        for key in self.keys_of(&coarse) {
            let name = key.name;
            if rate {
                let mut tests: Vec<String> =
                    (0..8).map(|s| key.differs(&format!("k_{name}"), &format!("k{s}_{name}"))).collect();
                tests.extend((1..4).map(|s| key.differs(&format!("k0_{name}"), &format!("k{s}_{name}"))));
                self.template(
                    0,
                    include_str!("templates/rate_resolve_key.wgsl"),
                    &[("NAME", &name), ("TESTS", &tests.join(" || "))],
                );
                continue;
            }
            // Which corners are on the pixel's side of the key.
            let side: Vec<String> =
                CORNERS.iter().map(|corner| key.matches(&format!("k_{name}"), &format!("{corner}_{name}"))).collect();
            let at: Vec<String> = CORNERS
                .iter()
                .zip(CORNER_PIXELS)
                .map(
                    |(corner, pixel)| {
                        if preloaded { format!("c.{corner}_{name}") } else { format!("mrsl_load_{name}({pixel})") }
                    },
                )
                .collect();
            self.template(
                0,
                include_str!("templates/resolve_key.wgsl"),
                &[
                    ("NAME", &name),
                    ("K00", &at[0]),
                    ("K10", &at[1]),
                    ("K01", &at[2]),
                    ("K11", &at[3]),
                    ("SIDE", &side.join(", ")),
                ],
            );
        }
        if !rate {
            self.edge_weights(&coarse);
        }
        let words: Vec<u32> = match only {
            None => (0..iface.flag_words).collect(),
            Some(_) => self.flag_words_read(&coarse).into_iter().collect(),
        };
        for (ci, sample) in samples.iter().enumerate().take(4) {
            for &w in &words {
                let word = if preloaded {
                    format!("c.w{w}.{}", ["x", "y", "z", "w"][ci])
                } else {
                    format!("{buf}[{sample} * {stride}u + {w}u]")
                };
                self.line(1, format!("let f{ci}_{w} = {word};"));
            }
        }
        if rate && !words.is_empty() {
            // The second border samples' flags, read only where a corner blends two.
            for ci in 4..8 {
                for &w in &words {
                    self.line(1, format!("var f{ci}_{w} = f{}_{w};", ci - 4));
                }
            }
            self.line(1, "if (blended) {");
            for (ci, sample) in samples.iter().enumerate().skip(4) {
                for &w in &words {
                    self.line(2, format!("f{ci}_{w} = {buf}[{sample} * {stride}u + {w}u];"));
                }
            }
            self.line(1, "}");
        }
        self.template(0, corners, &[]);
        for &e in coarse.iter().rev() {
            let info = &c.effects[e.index()];
            let k = self.coarse_index[&e];
            let mut terms = vec![if rate { self.discontinuity(e) } else { self.edge_discontinuity(e) }];
            if let Some(b) = iface.refine_bit[e.index()] {
                let (word, mask) = bit(b);
                let words: Vec<String> = (0..samples.len()).map(|ci| format!("f{ci}_{word}")).collect();
                terms.push(format!("((({}) & {mask}u) != 0u)", words.join(" | ")));
            }
            // Needed coarsely: some live user runs per pixel here.
            let mut needed = vec![];
            for &u in &self.i.graph.users[e.index()] {
                if !self.i.graph.live[u.index()] {
                    continue;
                }
                match c.effects[u.index()].rate {
                    Rate::Coarse => needed.push(format!("mrsl_r{}", self.coarse_index[&u])),
                    _ => needed.push("true".into()),
                }
            }
            needed.sort();
            needed.dedup();
            let needed = if needed.is_empty() { "false".to_string() } else { needed.join(" || ") };
            if !iface.is_passed(e) {
                terms.push(format!("({needed})"));
            } else if iface.is_shared(e) {
                let misses: Vec<String> = (0..samples.len())
                    .map(|ci| format!("!({})", self.store_condition(e, &|b| test_bit(&format!("f{ci}_"), b))))
                    .collect();
                terms.push(format!("(({needed}) && ({}))", misses.join(" || ")));
            }
            let value = if level.parent {
                format!("mrsl_is_refined(parent, {k}u) && ({})", terms.join(" || "))
            } else {
                terms.join(" || ")
            };
            let (word, mask) = bit(k);
            self.line(1, format!("let mrsl_r{k} = {value}; // `{}`", info.name));
            self.line(1, format!("if (mrsl_r{k}) {{ b.refined{word} |= {mask}u; }}"));
        }
        self.template(0, refined, &[]);
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
        if self.kind == KernelKind::DynamicFine {
            self.resolve_function(&Level::DYNAMIC_OUTER, Some((name, &decisions)));
            self.resolve_function(&Level::DYNAMIC_INNER, Some((name, &decisions)));
        } else {
            let level = Level { suffix: "", block: self.block, buffer: "mrsl_interface", parent: false };
            self.resolve_function(&level, Some((name, &decisions)));
        }
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

    /// `mrsl_resolve{suffix}` and the getters and resamplers of one level of coarse samples.
    fn fine_level(&mut self, level: &Level) {
        self.resolve_function(level, None);
        let c = self.checked();
        let coarse = self.coarse_live();
        let iface = self.i.interface;
        let (sfx, buf) = (level.suffix, level.buffer);
        let stride = if level.parent { iface.stride + DYNAMIC_TAG_WORDS } else { iface.stride };
        for &e in &coarse {
            let Some(slot) = iface.slot_of[e.index()].map(|s| &iface.slots[s]) else {
                continue;
            };
            let info = &c.effects[e.index()];
            let (filter, value) = if layout::uses_nearest(c, e) {
                // `select` takes no matrix: a matrix goes through `mrsl_select_m<N>`.
                let select = match info.ty {
                    crate::types::Type::Matrix(n) => format!("mrsl_select_m{n}"),
                    _ => "select".to_string(),
                };
                (
                    "nearest corner",
                    format!(
                        "{select}({select}(v0, v1, b.nearest == 1u), {select}(v2, v3, b.nearest == 3u), b.nearest >= 2u)"
                    ),
                )
            } else {
                let weights = match self.edge_set_of(e) {
                    Some(s) if self.kind != KernelKind::RateFine => format!("b.weights{s}"),
                    _ => "b.weights".to_string(),
                };
                ("bilinear", format!("v0 * {weights}.x + v1 * {weights}.y + v2 * {weights}.z + v3 * {weights}.w"))
            };
            let values: &super::writer::Values = &[
                ("SUFFIX", &sfx),
                ("NAME", &info.name),
                ("TYPE", &info.ty.wgsl()),
                ("STRIDE", &stride),
                ("OFFSET", &slot.offset),
                ("UNPACK", &unpack_words(&info.ty, buf)),
                ("FILTER", &filter),
                ("VALUE", &value),
            ];
            if self.preloads_corners() && !level.parent {
                let corner = |lane: &str| unpack_with(&info.ty, |k| format!("c.w{}.{lane}", slot.offset + k));
                let (v0, v1, v2, v3) = (corner("x"), corner("y"), corner("z"), corner("w"));
                let values: &super::writer::Values = &[
                    ("NAME", &info.name),
                    ("TYPE", &info.ty.wgsl()),
                    ("V0", &v0),
                    ("V1", &v1),
                    ("V2", &v2),
                    ("V3", &v3),
                    ("FILTER", &filter),
                    ("VALUE", &value),
                ];
                self.template(0, include_str!("templates/resample_corners.wgsl"), values);
                continue;
            }
            if self.kind != KernelKind::RateFine {
                self.template(0, include_str!("templates/resample.wgsl"), values);
                continue;
            }
            // The rate-image mode: a corner on a border may blend two border samples.
            let [head, tail] = cut(include_str!("templates/rate_resample.wgsl"), &["CORNERS"]);
            self.template(0, head, values);
            let get = format!("mrsl_get{sfx}_{}", info.name);
            for (k, lane) in ["x", "y", "z", "w"].iter().enumerate() {
                self.line(1, format!("var v{k} = {get}(b.corners.{lane});"));
                if layout::uses_nearest(c, e) {
                    self.line(1, format!("if (b.lerps.{lane} >= 0.5) {{ v{k} = {get}(b.others.{lane}); }}"));
                } else {
                    self.line(
                        1,
                        format!(
                            "if (b.lerps.{lane} != 0.0) {{ v{k} = v{k} * (1.0 - b.lerps.{lane}) + {get}(b.others.{lane}) * b.lerps.{lane}; }}"
                        ),
                    );
                }
            }
            self.template(0, tail, values);
        }
    }

    /// Declares `mrsl_b` (and in the dynamic mode `mrsl_b2`) for the pixel at
    /// `mrsl_pos` in the fine kernels; nothing elsewhere. `name` is the suffix
    /// of a neighbour function's own resolvers (`mrsl_resolve_<effect>`), or empty.
    pub(super) fn resolve_preamble(&mut self, indent: usize, name: &str) {
        if self.pixels_resolved {
            return;
        }
        if self.preloads_corners() {
            // The entry point loads its lane's corners once; elsewhere each position loads its own.
            if !self.corners_loaded {
                self.line(indent, "let mrsl_c = mrsl_corners(mrsl_pos);");
            }
            self.line(indent, format!("let mrsl_b = mrsl_resolve{name}(mrsl_pos, mrsl_c);"));
        } else if self.kind.is_fine() {
            self.line(indent, format!("let mrsl_b = mrsl_resolve{name}(mrsl_pos);"));
        }
        if self.kind == KernelKind::DynamicFine {
            self.resolve_inner(indent, name, ["mrsl_pos", "mrsl_b", "mrsl_b2"]);
        }
    }

    /// A coarse effect in a fine kernel: evaluated where it is refined,
    /// resampled elsewhere (when it is passed).
    pub(super) fn resolved_coarse_value(&mut self, e: EffectId, indent: usize) {
        let info = &self.checked().effects[e.index()];
        let (index, name) = (self.coarse_index[&e], self.effect_name(e));
        self.line(indent, format!("var {name}: {};", info.ty.wgsl()));
        if self.kind == KernelKind::DynamicFine {
            return self.dynamic_coarse_value(e, indent);
        }
        self.line(indent, format!("if (mrsl_is_refined(mrsl_b, {index}u)) {{"));
        self.evaluate(e, indent + 1, "");
        if self.i.interface.is_passed(e) {
            self.line(indent, "} else {");
            let corners = if self.preloads_corners() { ", mrsl_c" } else { "" };
            self.line(indent + 1, format!("{name} = mrsl_resample_{}(mrsl_b{corners});", info.name));
        }
        self.line(indent, "}");
    }

    /// Entry point of the fine and reference kernels.
    pub(super) fn pixel_entry(&mut self) {
        // The reference kernel has no blocks; it lays its tiles out in 2x2 ones.
        // The rate-image mode's cells are at most 4x4: 4x4 blocks keep a cell's pixels on neighbouring lanes.
        if self.compacts() {
            self.tile_pixel_blocks(self.block, 1);
            return self.compacted_fine_entry();
        }
        match self.kind {
            KernelKind::Fine | KernelKind::DynamicFine => self.tile_pixel_blocks(self.block, FINE_PIXELS_PER_LANE),
            KernelKind::RateFine => self.tile_pixel_blocks(4, 1),
            _ => self.tile_pixel_blocks(2, 1),
        }
        let counted = self.counts_stats();
        let coarse = self.coarse_live().len();
        self.pixel_main(
            |w| {
                if !counted {
                    return;
                }
                w.resolve_preamble(2, "");
                // `mrsl_last` holds the innermost level: effects refined there are evaluated per pixel.
                let (last, from_inner) = if w.kind == KernelKind::DynamicFine {
                    ("mrsl_b2", "mrsl_b.refined0 & ~mrsl_b2.refined0")
                } else {
                    ("mrsl_b", "0u")
                };
                w.statistics_on(2);
                w.template(3, include_str!("templates/rate.wgsl"), &[("LAST", &last), ("FROM_INNER", &from_inner)]);
                for k in 0..coarse {
                    w.count_refined(k, &format!("mrsl_is_refined(mrsl_last, {k}u)"));
                }
                w.line(2, "}");
            },
            |w, e, indent| w.effect_chain(&[e], indent),
        );
    }
}
