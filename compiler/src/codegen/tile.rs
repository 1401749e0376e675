//! The block modes' tile kernel (`tile_main`, [`KernelKind::Tile`]): one
//! workgroup shades one screen tile end to end, in one dispatch per frame.
//!
//! It is the block coarse kernel and the block fine kernel in one module,
//! with the coarse-to-fine interface in workgroup memory instead of a
//! record texture:
//!
//! 1. the neighbour values (layout `neighbours`: the coarse effects the
//!    samples' derivatives read at other samples) of every sample the
//!    tile's samples take differences with, into workgroup memory;
//! 2. the tile's samples and the next tile's first row and column (layout
//!    `tile`): their coarse effects, evaluated once each, with derivatives
//!    reading the values of step 1, then their refine flags and records,
//!    into workgroup memory;
//! 3. the tile's pixels, as the fine kernel shades them, with the corners'
//!    records read from workgroup memory.
//!
//! A position is a coarse sample in the first two phases and a pixel in the
//! third, and the helpers of both sets of positions share their names
//! (`mrsl_grid`, `mrsl_load_<input>`, `mrsl_eval_<effect>`, ...). So the
//! coarse part is written by the coarse kernel's writer and renamed into a
//! namespace of its own ([`names::coarse_part_name`]): every function and
//! structure it defines, and every use of them in it. Whatever both parts
//! only use (bindings, user functions, constants, workgroup memory) is
//! declared once by the fine part.

use super::effects::Evaluation;
use super::names::{
    self, BACKGROUND, CONTROL, FIRST, GRID, GROUP_TILE, IS_RECORD, LANE, NEIGHBOUR_SLOT, NEIGHBOUR_SLOTS, Name, OWNED,
    POS, RECORD_SLOT, RECORD_SLOTS, REFINE_MASK, SLOT, STATS, SURFACE_TILES, TILE_BACKGROUND, TILE_ORIGIN, TILE_PIXEL,
    TILE_PIXELS, TILE_SAMPLE, WORKGROUP, WORKGROUP_NEIGHBOUR_FLAGS, WORKGROUP_NEIGHBOURS, WORKGROUP_RECORDS,
    WORKGROUP_STATS,
};
use super::writer::cut;
use super::{Inputs, Writer};
use crate::check::EffectId;
use mrsl_abi::geometry::{FINE_WORKGROUP, TILE, TILE_LANES};
use mrsl_abi::plan::{BindingType, ResourceId};
use mrsl_abi::{GROUP_STAGE, KernelKind, KernelRef, entry};
use std::collections::BTreeSet;

impl Writer<'_, '_, '_> {
    /// Whether this writer writes the tile kernel's coarse part (the
    /// coarse family's writer) rather than its module (the fine family's).
    pub(super) fn writes_coarse_part(&self) -> bool {
        self.file == KernelKind::Tile && self.kind == KernelKind::Coarse
    }

    /// In the tile kernel's bindings: its tile's constants, its workgroup
    /// memory (records, neighbour values) and where a sample sits in it.
    pub(super) fn tile_memory(&mut self) {
        let tile = self.i.layout.tile;
        let stride = self.i.interface.stride.max(1);
        let words = self.i.layout.neighbours.words;
        let record_slots = tile.record_side().pow(2);
        let neighbour_slots = tile.neighbour_side().pow(2);
        let [head, tail] = cut(include_str!("templates/tile_memory.wgsl"), &["NEIGHBOURS"]);
        let values: &super::writer::Values = &[
            ("SAMPLES", &tile.samples),
            ("RING", &tile.ring),
            ("RECORD_SLOTS", &record_slots),
            ("NEIGHBOUR_SLOTS", &neighbour_slots),
            ("RECORD_WORDS", &(stride * record_slots)),
        ];
        self.template(0, head, values);
        if words > 0 {
            let ty = format!("array<u32, {}>", words * neighbour_slots);
            self.line(0, format!("var<workgroup> {WORKGROUP_NEIGHBOURS}: {ty};"));
        }
        if crate::neighbours::tile_keeps_flags(self.i.layout) {
            let flag_words = self.i.interface.flag_words * record_slots;
            self.line(0, "// The refine flags of the neighbour values that refine, as the neighbour phase");
            let at = format!("`w * {RECORD_SLOTS} + s`");
            self.line(0, format!("// decided them at the records' samples: word w of record slot s at {at}."));
            self.line(0, format!("var<workgroup> {WORKGROUP_NEIGHBOUR_FLAGS}: array<u32, {flag_words}>;"));
        }
        if self.has_background() {
            let groups = (tile.side(self.block) / TILE).pow(2);
            self.line(
                0,
                format!("// Per {TILE}x{TILE} tile of pixels: nonzero where a pixel is not background (or refinement"),
            );
            self.line(0, "// is forced); a tile that is wholly background is shaded as such.");
            self.line(0, format!("var<workgroup> {SURFACE_TILES}: array<atomic<u32>, {groups}>;"));
        }
        self.template(0, tail, values);
        if crate::neighbours::tile_keeps_flags(self.i.layout) {
            self.template(0, include_str!("templates/tile_flags.wgsl"), &[]);
        }
    }

    /// The tile kernel's stage group, declared binding by binding from the
    /// plan's `PassBinding`s (`crate::plan::stage_bindings`, which the
    /// runtimes bind by): the statistics, the refine mask and the outputs;
    /// then its workgroup memory.
    pub(super) fn tile_stage_group(&mut self) {
        let l = self.i.layout;
        let kernel = KernelRef::new(KernelKind::Tile, Some(self.block));
        for b in crate::plan::stage_bindings(l, kernel) {
            let (name, ty, what) = match (b.resource, b.ty) {
                (ResourceId::Statistics, BindingType::Buffer { read_only: false }) => (
                    STATS.to_string(),
                    "array<atomic<u32>>".to_string(),
                    "The statistics counters (layout `stats`).".to_string(),
                ),
                (ResourceId::RefineMask, BindingType::StorageTexture { format }) => (
                    REFINE_MASK.to_string(),
                    format!("texture_storage_2d<{format}, write>"),
                    "Per pixel: .x bit k = coarse effect k evaluated per pixel.".to_string(),
                ),
                (ResourceId::Output { index }, BindingType::StorageTexture { format }) => (
                    Name::Out.of(&l.outputs[index].name),
                    format!("texture_storage_2d<{format}, write>"),
                    format!("Output `{}`.", l.outputs[index].name),
                ),
                (resource, ty) => unreachable!("the tile kernel binds no {resource:?} as {ty:?}"),
            };
            let space = if matches!(b.ty, BindingType::Buffer { .. }) { "<storage, read_write>" } else { "" };
            self.line(0, format!("// {what}"));
            self.line(0, format!("@group({GROUP_STAGE}) @binding({}) var{space} {name}: {ty};", b.binding));
        }
        if self.counts_stats() {
            let counters = self.workgroup_counters();
            self.line(0, format!("var<workgroup> {WORKGROUP_STATS}: array<atomic<u32>, {counters}>;"));
        }
        self.tile_memory();
    }

    /// The tile kernel's record word `word` of the sample at slot `slot` (WGSL).
    pub(super) fn tile_record_word(word: u32, slot: &str) -> String {
        format!("{WORKGROUP_RECORDS}[{word}u * {RECORD_SLOTS} + {slot}]")
    }

    /// The tile kernel's neighbour-value word `word` of sample `sample` (WGSL, in the coarse part).
    pub(super) fn tile_neighbour_word(word: u32, sample: &str) -> String {
        format!("{WORKGROUP_NEIGHBOURS}[{word}u * {NEIGHBOUR_SLOTS} + {NEIGHBOUR_SLOT}({sample})]")
    }

    /// The neighbour values' word `word` stored at the sample the coarse part's
    /// `mrsl_tile_neighbours` evaluates (a statement).
    pub(super) fn tile_neighbour_store(word: u32, value: &str) -> String {
        format!("{WORKGROUP_NEIGHBOURS}[{word}u * {NEIGHBOUR_SLOTS} + {SLOT}] = {value};")
    }

    /// The coarse part's entry points, as functions of the sample they
    /// evaluate: `mrsl_tile_neighbours<wave>` per wave (none without
    /// neighbour values) and `mrsl_tile_sample`.
    pub(super) fn tile_phases(&mut self) {
        if self.stores_neighbours() {
            for wave in 0..self.neighbour_waves() {
                let [head, tail] = cut(include_str!("templates/tile_neighbours.wgsl"), &["BODY"]);
                let values: &super::writer::Values = &[("WAVE", &wave), ("NAME", &names::tile_neighbours_wave(wave))];
                self.template(0, head, values);
                self.tile_neighbour_wave(wave);
                self.template(0, tail, values);
            }
        }
        self.coarse_main(include_str!("templates/tile_sample.wgsl"));
    }

    /// How many waves the tile kernel's neighbour phase takes ([`mrsl_abi::NeighbourValue::wave`]).
    pub(super) fn neighbour_waves(&self) -> u32 {
        self.i.layout.neighbours.effects.iter().map(|v| v.wave + 1).max().unwrap_or(0)
    }

    /// The body of wave `wave` of the neighbour phase at sample `mrsl_pos`:
    /// the wave's neighbour values and what they read, in dependency order,
    /// each evaluated once (an earlier wave's values read back), then
    /// stored. One that refines is evaluated with its flag at the records'
    /// samples, where the tile's samples read it back instead of
    /// evaluating it again, and for its value alone elsewhere.
    fn tile_neighbour_wave(&mut self, wave: u32) {
        let c = self.checked();
        let values = self.neighbour_values();
        let waves: Vec<u32> = self.i.layout.neighbours.effects.iter().map(|v| v.wave).collect();
        let wave_of = |e: EffectId| values.iter().position(|&(v, _)| v == e).map(|k| waves[k]);
        let in_wave: Vec<(EffectId, u32)> =
            values.iter().zip(&waves).filter(|&(_, &w)| w == wave).map(|(&v, _)| v).collect();
        let needed: BTreeSet<EffectId> = in_wave.iter().flat_map(|&(e, _)| self.i.graph.closure(e, c)).collect();
        if wave == 0 && crate::neighbours::tile_keeps_flags(self.i.layout) {
            self.line(1, format!("if ({IS_RECORD}({POS})) {{"));
            for w in 0..self.i.interface.flag_words {
                self.line(2, format!("{} = 0u;", Self::neighbour_flag_word(w, &format!("{RECORD_SLOT}({POS})"))));
            }
            self.line(1, "}");
        }
        for x in self.i.graph.order.clone().into_iter().filter(|x| needed.contains(x)) {
            let name = self.effect_name(x);
            match (wave_of(x), self.i.interface.refine_bit[x.index()]) {
                (Some(w), _) if w < wave => {
                    self.line(1, format!("let {name} = {}({POS});", Name::At.of(&c.effects[x.index()].name)));
                }
                (Some(_), Some(k)) => self.flagged_neighbour_value(x, k),
                _ => self.evaluate(x, 1, "let ", Evaluation::ValueOnly),
            }
        }
        for (e, offset) in in_wave {
            self.store_neighbour_words(1, POS, e, offset);
        }
    }

    /// Neighbour value `e`, with refine bit `bit`, at sample `mrsl_pos` of
    /// the neighbour phase: at a record's sample with its flag, which is
    /// kept, elsewhere for its value alone.
    fn flagged_neighbour_value(&mut self, e: EffectId, bit: u32) {
        let info = &self.checked().effects[e.index()];
        let (name, flag) = (self.effect_name(e), Name::RefineFlag.of(&info.name));
        let (word, mask) = super::words::bit(bit);
        self.line(1, format!("var {name}: {};", info.ty.wgsl()));
        self.line(1, format!("if ({IS_RECORD}({POS})) {{"));
        self.evaluate(e, 2, "", Evaluation::Kernel);
        let kept = Self::neighbour_flag_word(word, &format!("{RECORD_SLOT}({POS})"));
        self.line(2, format!("if ({flag}) {{ {kept} |= {mask}u; }}"));
        self.line(1, "} else {");
        self.evaluate(e, 2, "", Evaluation::ValueOnly);
        self.line(1, "}");
    }

    /// Flag word `word` kept beside the neighbour values for record slot `slot` (WGSL).
    pub(super) fn neighbour_flag_word(word: u32, slot: &str) -> String {
        format!("{WORKGROUP_NEIGHBOUR_FLAGS}[{word}u * {RECORD_SLOTS} + {slot}]")
    }

    /// In the tile's sample phase, neighbour value `e` and its refine flag
    /// (where it has one), read back from the neighbour phase.
    pub(super) fn kept_neighbour_value(&mut self, e: EffectId) {
        let info = &self.checked().effects[e.index()];
        let name = self.effect_name(e);
        self.line(1, format!("let {name} = {}({POS});", Name::At.of(&info.name)));
        if let Some(k) = self.i.interface.refine_bit[e.index()] {
            let (word, mask) = super::words::bit(k);
            let flag = Name::RefineFlag.of(&info.name);
            self.line(1, format!("let {flag} = ({} & {mask}u) != 0u;", Self::neighbour_flag_word(word, SLOT)));
        }
    }

    /// The condition under which the coarse part counts a background sample.
    pub(super) fn owned_background(&self) -> String {
        format!("{OWNED} && {BACKGROUND}({POS})")
    }

    /// The coarse part's record words stored into the workgroup's records.
    pub(super) fn tile_record_stores(&mut self) {
        for w in 0..self.i.interface.stride {
            let store = format!("{} = {};", Self::tile_record_word(w, SLOT), names::Name::RecordWord.of(w));
            self.line(1, store);
        }
    }

    /// Where the fine part's corners read word `word` of corner sample `at` (WGSL).
    pub(super) fn tile_corner_word(word: u32, at: &str) -> String {
        Self::tile_record_word(word, &format!("{RECORD_SLOT}({at})"))
    }

    /// The tile kernel's entry point and what only it needs: the coarse part,
    /// the pixels of one [`TILE`]² tile for one group of lanes
    /// (`mrsl_tile_pixels`), and `tile_main`.
    pub(super) fn tile_entry(&mut self, pixels: impl FnOnce(&mut Self)) {
        let coarse = coarse_part(self.i, self.block);
        self.code.push_str(&coarse);
        let what = format!("{TILE}x{TILE} tile `{WORKGROUP}` for lane `{LANE}` of a group of {FINE_WORKGROUP}");
        self.line(0, format!("// The pixels of {what}."));
        pixels(self);
        self.tile_background_function();
        let tile = self.i.layout.tile;
        let side = tile.side(self.block);
        let per_side = side / TILE;
        let [head, neighbours, samples, barrier, tail] =
            cut(include_str!("templates/tile_main.wgsl"), &["NEIGHBOURS", "SAMPLES", "SURFACE", "PIXELS"]);
        let values: &super::writer::Values = &[
            ("ENTRY", &entry::TILE),
            ("SIDE", &side),
            ("TILE", &TILE),
            ("GROUP", &FINE_WORKGROUP),
            ("GROUPS", &(per_side * per_side)),
            ("PER_SIDE", &per_side),
            ("LANES", &TILE_LANES),
            ("GRID", &names::coarse_part_name(GRID)),
            ("NEIGHBOUR_SIDE", &tile.neighbour_side()),
            ("RECORD_SIDE", &tile.record_side()),
            ("TILE_SAMPLE", &names::coarse_part_name(TILE_SAMPLE)),
        ];
        self.template(0, head, values);
        if self.i.layout.neighbours.words > 0 {
            let waves = self.neighbour_waves();
            if waves > 1 {
                self.line(
                    1,
                    format!("// The neighbour values in {waves} waves, a barrier after each: a wave's refine"),
                );
                self.line(1, "// flags take differences of an earlier wave's values at the neighbouring samples.");
            }
            for wave in 0..waves {
                let function = names::coarse_part_name(&names::tile_neighbours_wave(wave));
                let mut values = values.to_vec();
                values.push(("TILE_NEIGHBOURS", &function));
                self.template(0, neighbours, &values);
            }
        }
        self.template(0, samples, values);
        self.surface_tiles(side);
        self.template(0, barrier, values);
        self.template(0, tail, values);
        // Each group of lanes takes every `groups_at_once`-th tile of TILE² pixels.
        let (groups, groups_at_once) = (per_side * per_side, TILE_LANES / FINE_WORKGROUP);
        for first in (0..groups).step_by(groups_at_once as usize) {
            let group = format!("{LANE} / {FINE_WORKGROUP}u + {first}u");
            let g = GROUP_TILE;
            let tile = format!("{WORKGROUP}.xy * {per_side}u + vec2<u32>({g} % {per_side}u, {g} / {per_side}u)");
            let call = format!("{TILE_PIXELS}({tile}, {LANE} % {FINE_WORKGROUP}u, {g});");
            self.line(1, "{");
            self.line(2, format!("let {g} = {group};"));
            if first + groups_at_once > groups {
                self.line(2, format!("if ({g} < {groups}u) {{ {call} }}"));
            } else {
                self.line(2, call);
            }
            self.line(1, "}");
        }
        if self.counts_stats() {
            self.flush_workgroup_stats(TILE_LANES);
        }
        self.line(0, "}");
    }

    /// The opening lines of `mrsl_tile_pixels`: a tile wholly background
    /// (with a background rule) is shaded as such, the rest resolve.
    pub(super) fn tile_pixels_head(&mut self) {
        self.line(0, format!("fn {TILE_PIXELS}({WORKGROUP}: vec2<u32>, {LANE}: u32, {GROUP_TILE}: u32) {{"));
        if self.has_background() {
            self.line(1, format!("if (atomicLoad(&{SURFACE_TILES}[{GROUP_TILE}]) == 0u) {{"));
            self.line(2, format!("{TILE_BACKGROUND}({WORKGROUP}, {LANE});"));
            self.line(2, "return;");
            self.line(1, "}");
        }
        self.line(1, format!("let {FIRST} = {TILE_PIXEL}({WORKGROUP}, {LANE});"));
    }

    /// `mrsl_tile_background`: the pixels of a wholly background tile of
    /// [`TILE`]² pixels for one lane, as the fine kernel's `fine_background`
    /// shades them (with a background rule).
    fn tile_background_function(&mut self) {
        if !self.has_background() {
            return;
        }
        let what = format!("{TILE}x{TILE} tile `{TILE_ORIGIN}`, wholly background, for lane `{LANE}`");
        self.line(0, format!("// The pixels of {what}: its coarse effects read as zero."));
        self.line(0, format!("fn {TILE_BACKGROUND}({TILE_ORIGIN}: vec2<u32>, {LANE}: u32) {{"));
        self.background_pixels();
        self.line(0, "}");
        self.line(0, "");
    }

    /// In `tile_main`, before the barrier after its samples: which of the
    /// tile's [`TILE`]² tiles have a pixel that is not background (every one
    /// where refinement is forced).
    fn surface_tiles(&mut self, side: u32) {
        if !self.has_background() {
            return;
        }
        let per_side = side / TILE;
        self.line(1, "// Which of the tile's 8x8 tiles have a pixel that is not background.");
        self.line(1, format!("for (var p = {LANE}; p < {}u; p += {TILE_LANES}u) {{", side * side));
        self.line(
            2,
            format!("let at = vec2<i32>({WORKGROUP}.xy) * {side} + vec2<i32>(i32(p % {side}u), i32(p / {side}u));"),
        );
        let surface = format!("{CONTROL}.force_refine != 0u || !{BACKGROUND}(at)");
        self.line(2, format!("if (all(at < vec2<i32>({CONTROL}.size)) && ({surface})) {{"));
        let group = format!("(p / {side}u / {TILE}u) * {per_side}u + (p % {side}u) / {TILE}u");
        self.line(3, format!("atomicOr(&{SURFACE_TILES}[{group}], 1u);"));
        self.line(2, "}");
        self.line(1, "}");
    }
}

/// The coarse part of the tile kernel over `inputs` at block size `block`:
/// the coarse kernel's functions and phases, renamed ([`names::rename_into_coarse_part`]).
fn coarse_part(inputs: &Inputs, block: u32) -> String {
    let mut w = Writer::new(inputs, KernelKind::Coarse, block);
    w.file = KernelKind::Tile;
    w.line(0, "// ---- The coarse part: positions are coarse samples ----");
    w.line(0, "");
    w.coarse_part();
    w.line(0, "// ---- The fine part: positions are pixels ----");
    w.line(0, "");
    names::rename_into_coarse_part(&w.code.into_string())
}
