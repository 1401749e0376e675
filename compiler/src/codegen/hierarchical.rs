//! The hierarchical (DACS) kernel: one module with every entry point of the
//! mode, in dispatch order. Level 0 shades its lattice of pixels. Each
//! classified level then decides, per pixel of its lattice and per coarse
//! effect, whether the mean of its previous-level neighbours on its side of
//! every key the effect reads is good enough (at least two of them, no
//! refine flag among them, a small variance relative to their values) or
//! the pixel must be shaded; pixels to shade are compacted into the level's work
//! list, whose count the `hier_args_*` entry point turns into the indirect
//! dispatch of `hier_shade_*`. A pixel's outputs are written where its
//! record is complete, by the invocation that completed it (`mrsl_finish`:
//! level 0 and the shading entry points after shading it, the
//! classification where it interpolated every effect, and at a background
//! pixel), from the values that invocation holds, so no pass reads the
//! records again. In a program with a background rule, `hier_tiles` first
//! lists the 32x32 tiles as surface or background tiles: level 0 and the
//! classifications are dispatched over the surface tiles only, and
//! `hier_background` writes the background tiles' outputs (on llvmpipe a
//! lane pays for its whole entry point whatever its branches say, so a sky
//! pixel is spared the classification only by being left out of its
//! dispatch). The lattices, tiles, work-list capacities and queue layout
//! are the runtime's too: they come from `mrsl_abi::geometry`.

use super::Writer;
use super::effects::Evaluation;
use super::names::{
    CONTROL, COUNT, LANE, LEVEL, LOAD_RECORD, LOCAL_ID, NEIGHBOUR_RECORDS, Name, PIXEL_RECORD, POS, PUT_MASKS,
    PUT_RECORD, RECORD_TYPE, SET_WORD, SHADE, SHADE_LAST, TILE_ARGS, TILE_INVOCATION, WORD, WORKGROUP,
};
use super::records::{axis_neighbours, diagonal_neighbours, neighbours, record_word};
use super::words::bit;
use super::writer::cut;
use crate::check::EffectId;
use crate::types::{Scalar, Type};
use mrsl_abi::entry;
use mrsl_abi::geometry::{
    self, BACKGROUND_TILE_WORKGROUPS, COARSE_WORKGROUP, HIERARCHICAL_LEVEL0, HIERARCHICAL_LEVELS, HIERARCHICAL_TILE,
    HIERARCHICAL_TILE_COUNTS, Lattice, QUEUE_WORDS_PER_LEVEL, WORK_LIST_WORKGROUP,
};
use std::fmt::Display;
use std::ops::RangeInclusive;

/// How a classified level (1 to 4, dispatched over [`HIERARCHICAL_LEVELS`])
/// picks its pixels and the neighbours it interpolates from.
struct Classified {
    what: &'static str,
    neighbours: [(i32, i32); 4],
}

fn classified_levels() -> [Classified; 4] {
    [
        Classified {
            what: "every 4th pixel offset by (2, 2), from its diagonal neighbours at distance 2",
            neighbours: diagonal_neighbours(2),
        },
        Classified {
            what: "the remaining pixels of the 2-grid, from axis neighbours at distance 2",
            neighbours: axis_neighbours(2),
        },
        Classified { what: "odd pixels, from diagonal neighbours at distance 1", neighbours: diagonal_neighbours(1) },
        Classified { what: "the rest, from axis neighbours at distance 1", neighbours: axis_neighbours(1) },
    ]
}

/// The levels whose shading evaluates predicates (`mrsl_shade`): 0 to 3,
/// every level but the last, which shades values alone.
pub(super) const LEVELS_WITH_PREDICATES: RangeInclusive<usize> = 0..=HIERARCHICAL_LEVELS.len() - 1;

/// The neighbours of a pixel of level `level` in opposite pairs (0, 1) and
/// (2, 3): at level 0 its lattice's neighbours along the axes, at the
/// classified levels (1 to 4) those it interpolates from.
pub(super) fn level_neighbours(level: usize) -> [(i32, i32); 4] {
    match level {
        0 => axis_neighbours(HIERARCHICAL_LEVEL0.step as i32),
        _ => classified_levels()[level - 1].neighbours,
    }
}

/// The pixel of invocation `gid.xy`, as WGSL: lattice point `gid.xy`, or
/// with `odd_only` point (2 gid.x + (gid.y + 1) mod 2, gid.y) (see [`Lattice`]).
fn lattice_pixel(lattice: Lattice) -> String {
    let point = match lattice.odd_only {
        false => "vec2<i32>(gid.xy)",
        true => "vec2<i32>(i32(2u * gid.x + ((gid.y + 1u) & 1u)), i32(gid.y))",
    };
    let scaled = match lattice.step {
        1 => point.to_string(),
        step => format!("{point} * {step}"),
    };
    match lattice.start {
        0 => scaled,
        start => format!("vec2<i32>({start}) + {scaled}"),
    }
}

/// The workgroup size of the entry points dispatched over a lattice (see
/// [`Lattice::workgroups`]).
fn lattice_workgroup() -> String {
    format!("{COARSE_WORKGROUP}, {COARSE_WORKGROUP}, 1")
}

impl Writer<'_, '_, '_> {
    /// The records, the work lists, the per-level queue counters and (in a
    /// group of their own) the indirect dispatch arguments.
    pub(super) fn hierarchical_bindings(&mut self) {
        let l = self.i.layout;
        let h = &l.hierarchical;
        self.record_binding(
            "Hierarchical mode: per pixel record (flags, evaluated-mask, values), work lists, queues.",
            h.packed,
        );
        if self.stores_level0_values() {
            self.template(
                0,
                include_str!("templates/neighbours_binding.wgsl"),
                &[("GROUP", &l.interface.group), ("BINDING", &l.neighbours.binding)],
            );
        }
        self.template(
            0,
            include_str!("templates/hierarchical_queues.wgsl"),
            &[
                ("GROUP", &l.interface.group),
                ("WORK_BINDING", &h.work_binding),
                ("QUEUE_BINDING", &h.queue_binding),
                ("ARGS_GROUP", &h.args_group),
                ("ARGS_BINDING", &mrsl_abi::BINDING_ARGS),
            ],
        );
    }

    /// Every entry point, in dispatch order, after the helpers they share.
    pub(super) fn hierarchical_entries(&mut self) {
        if self.packed() {
            self.packed_record_helpers();
        } else {
            self.record_helpers();
        }
        self.pixel_values();
        self.level_derivative_helpers();
        self.finish_function();
        self.work_lists();
        self.tile_lists();
        self.shade_function(false);
        self.shade_function(true);
        self.level0_values_entry();
        self.level0();
        self.classify_function();
        let says_level = self.says_level();
        for (index, (lattice, level)) in HIERARCHICAL_LEVELS.iter().zip(classified_levels()).enumerate() {
            // The level's words in the queue (its count first) and in the
            // indirect arguments (x, y, z).
            let queue = (index as u32 + 1) * QUEUE_WORDS_PER_LEVEL;
            let neighbours = neighbours(level.neighbours);
            let (params, invocation, valid) = self.level_invocation(*lattice);
            // The last level's flags are read by no later classification.
            let shade = if index + 1 == HIERARCHICAL_LEVELS.len() { SHADE_LAST } else { SHADE };
            let values: &super::writer::Values = &[
                ("SHADE_PIXEL", &shade),
                ("PARAMS", &params),
                ("VALID", &valid),
                ("LEVEL", &(index + 1)),
                ("WHAT", &level.what),
                ("CLASSIFY_WORKGROUP", &lattice_workgroup()),
                ("CLASSIFY", &entry::HIER_CLASSIFY[index]),
                ("PIXEL", &lattice_pixel(*lattice)),
                ("NEIGHBOURS", &neighbours),
                ("ARGS", &entry::HIER_ARGS[index]),
                ("QUEUE", &queue),
                ("ARGS_X", &queue),
                ("ARGS_Y", &(queue + 1)),
                ("ARGS_Z", &(queue + 2)),
                ("WORK_GROUP_LESS_1", &(WORK_LIST_WORKGROUP - 1)),
                ("WORK_GROUP", &WORK_LIST_WORKGROUP),
                ("SHADE", &entry::HIER_SHADE[index]),
            ];
            let [head, classify, shade, shade_pixel, end] = cut(
                include_str!("templates/level.wgsl"),
                &["INVOCATION", "FLUSH_CLASSIFY", "SET_LEVEL", "FLUSH_SHADE"],
            );
            self.template(0, head, values);
            if let Some(line) = &invocation {
                self.line(1, line);
            }
            self.template(0, classify, values);
            self.flush_finished(COARSE_WORKGROUP * COARSE_WORKGROUP);
            self.template(0, shade, values);
            if says_level && LEVELS_WITH_PREDICATES.contains(&(index + 1)) {
                self.line(2, format!("{LEVEL} = {}u;", index + 1));
            }
            self.template(0, shade_pixel, values);
            self.flush_finished(WORK_LIST_WORKGROUP);
            self.template(0, end, values);
        }
        self.background_tiles();
    }

    /// Whether the records are packed four words to a texel
    /// (`Options::packed_records`): then every invocation loads the records
    /// it reads whole, once, and stores its pixel's record whole, once.
    pub(super) fn packed(&self) -> bool {
        self.i.layout.hierarchical.packed
    }

    /// The line that stores pixel `pos`'s record (packed) from `flags` and
    /// `masks` and its `mrsl_pv_*` values, or its flag and mask words (a
    /// texel per word; its values were stored one by one).
    fn store_record(&mut self, pos: &str, flags: &[String], masks: &[String]) {
        if self.packed() {
            let words: String = flags.iter().chain(masks).map(|w| format!(", {w}")).collect();
            self.line(1, format!("{PUT_RECORD}({pos}{words});"));
        } else {
            for (w, word) in flags.iter().chain(masks).enumerate() {
                self.line(1, format!("{SET_WORD}({pos}, {w}u, {word});"));
            }
        }
    }

    /// Lines storing pixel `p`'s mask words `masks` alone (the flag and value
    /// words of a packed record's texels that hold them become zero).
    fn store_masks(&mut self, indent: usize, masks: &[String]) {
        if self.packed() {
            let words: String = masks.iter().map(|w| format!(", {w}")).collect();
            self.line(indent, format!("{PUT_MASKS}(p{words});"));
        } else {
            let first = self.i.layout.hierarchical.flag_words;
            for (w, mask) in masks.iter().enumerate() {
                self.line(indent, format!("{SET_WORD}(p, {}u, {mask});", first + w as u32));
            }
        }
    }

    /// Whether level 0 and the classifications run over the surface tiles
    /// only: in a program with a background rule.
    fn tiled(&self) -> bool {
        self.has_background()
    }

    /// How an entry point over `lattice` finds its invocation: its
    /// parameters, the line that computes `gid` from the surface tile list
    /// (tiled), and the test that it has one (a prefix of the image test).
    fn level_invocation(&self, lattice: Lattice) -> (String, Option<String>, &'static str) {
        if !self.tiled() {
            let params =
                format!("@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) {LANE}: u32");
            return (params, None, "");
        }
        let params = format!(
            "@builtin(workgroup_id) {WORKGROUP}: vec3<u32>, @builtin(local_invocation_id) {LOCAL_ID}: vec3<u32>, \
             @builtin(local_invocation_index) {LANE}: u32"
        );
        let (x, y) = lattice.workgroups_per_tile();
        let surface = HIERARCHICAL_TILE_COUNTS[0];
        let line =
            format!("let gid = {TILE_INVOCATION}({WORKGROUP}.xy, {LOCAL_ID}.xy, vec2<u32>({x}u, {y}u), {surface}u);");
        (params, Some(line), "gid.x != 0xffffffffu && ")
    }

    /// The tile lists' helpers and `hier_tiles` and `hier_tile_args`
    /// (empty, and not dispatched, without a background rule).
    fn tile_lists(&mut self) {
        if !self.tiled() {
            self.line(0, "// No background rule: the plan dispatches every level over its whole lattice and");
            self.line(0, "// none of these.");
            for name in [entry::HIER_TILES, entry::HIER_TILE_ARGS] {
                self.line(0, "@compute @workgroup_size(1, 1, 1)");
                self.line(0, format!("fn {name}() {{}}"));
            }
            self.line(0, "");
            return;
        }
        let last = HIERARCHICAL_LEVELS[HIERARCHICAL_LEVELS.len() - 1];
        let count = |axis: &str| format!("{COUNT}({}u, {}u, {axis})", last.start, last.step);
        let last_points = format!("{} * {}", count("w"), count("h"));
        let [surface, background] = HIERARCHICAL_TILE_COUNTS;
        let values: &super::writer::Values = &[
            ("TILE", &HIERARCHICAL_TILE),
            ("LAST_LEVEL", &HIERARCHICAL_LEVELS.len()),
            ("LAST_POINTS", &last_points),
            ("LANES", &COARSE_WORKGROUP),
            ("STEP", &HIERARCHICAL_LEVEL0.step),
            ("TILES_ENTRY", &entry::HIER_TILES),
            ("ARGS_ENTRY", &entry::HIER_TILE_ARGS),
            ("SURFACE", &surface),
            ("BACKGROUND", &background),
        ];
        let [head, end] = cut(include_str!("templates/hierarchical_tiles.wgsl"), &["DISPATCHES"]);
        self.template(0, head, values);
        let word = |offset: u64| offset / 4;
        for (level, lattice) in std::iter::once(HIERARCHICAL_LEVEL0).chain(HIERARCHICAL_LEVELS).enumerate() {
            let (x, y) = lattice.workgroups_per_tile();
            let at = word(geometry::level_tile_args_offset(level as u32));
            self.line(1, format!("{TILE_ARGS}({at}u, surface, {}u);", x * y));
        }
        let (x, y) = BACKGROUND_TILE_WORKGROUPS;
        let at = word(geometry::background_tile_args_offset());
        self.line(1, format!("{TILE_ARGS}({at}u, background, {}u);", x * y));
        self.template(0, end, values);
    }

    /// `hier_background`: the pixels of the background tiles, one per lane,
    /// their records cleared and their coarse effects zero (the background
    /// rule), then their outputs. Without a background rule, empty.
    fn background_tiles(&mut self) {
        let lanes = COARSE_WORKGROUP * COARSE_WORKGROUP;
        if !self.tiled() {
            self.line(0, "// No background rule: not dispatched.");
            self.line(0, format!("@compute @workgroup_size({WORK_LIST_WORKGROUP}, 1, 1)"));
            self.line(0, format!("fn {}() {{}}", entry::HIER_BACKGROUND));
            self.line(0, "");
            return;
        }
        assert_eq!(lanes, WORK_LIST_WORKGROUP, "a background workgroup is one 8x8 block of a tile");
        let (x, y) = BACKGROUND_TILE_WORKGROUPS;
        let values: &super::writer::Values = &[
            ("WORK_GROUP", &WORK_LIST_WORKGROUP),
            ("ENTRY", &entry::HIER_BACKGROUND),
            ("LANES", &COARSE_WORKGROUP),
            ("PER_X", &x),
            ("PER_Y", &y),
            ("LIST", &HIERARCHICAL_TILE_COUNTS[1]),
        ];
        let [head, clear, end] = cut(include_str!("templates/hierarchical_background.wgsl"), &["CLEAR", "FLUSH"]);
        self.template(0, head, values);
        self.clear_record(2);
        self.background_known_at(2, "p");
        self.template(0, clear, values);
        self.flush_finished(lanes);
        self.template(0, end, values);
    }

    /// `var<private> mrsl_pv_<effect>`: the values of the coarse effects at
    /// the invocation's pixel as it stored them in the record, which
    /// [`Self::finish_function`] reads instead of the record.
    fn pixel_values(&mut self) {
        let c = self.checked();
        for e in self.coarse_live() {
            let info = &c.effects[e.index()];
            self.line(0, format!("var<private> {}: {};", Name::PixelValue.of(&info.name), info.ty.wgsl()));
        }
    }

    /// `mrsl_finish(mrsl_pos)`: the pixel's outputs, once its record is
    /// complete: the statistics (its refine mask and counts: the evaluated
    /// bits of the record), then its fine effects and outputs with the
    /// coarse values of `mrsl_pv_*`.
    fn finish_function(&mut self) {
        let coarse = self.coarse_live().len();
        let [head, statistics, body] = cut(include_str!("templates/finish.wgsl"), &["STATISTICS", "BODY"]);
        self.template(0, head, &[]);
        if self.counts_stats() {
            let [open, store, end] = cut(include_str!("templates/finish_statistics.wgsl"), &["MASKS", "COUNTS"]);
            let background = self.background_here(POS);
            let mask_y =
                if self.has_background() { format!("select(0u, 0xffffffffu, {background})") } else { "0u".into() };
            let mask_x = Name::PixelMask.of(0);
            let values: &super::writer::Values =
                &[("STATISTICS_ON", &super::pixel::statistics_enabled()), ("MASK_X", &mask_x), ("MASK_Y", &mask_y)];
            self.template(0, open, values);
            self.load_pixel_masks(2);
            self.template(0, store, values);
            for k in 0..coarse {
                let (word, mask) = bit(k as u32);
                let evaluated = format!("({} & {mask}u) != 0u", Name::PixelMask.of(word));
                self.count_refined_at(2, k, &evaluated);
            }
            if self.has_background() {
                self.count_refined_at(2, coarse, &background);
            }
            self.template(0, end, &[]);
        }
        self.template(0, statistics, &[]);
        let mut prologue = |_: &mut Self, _| {};
        let mut coarse_value = |w: &mut Self, e: EffectId, indent: usize| {
            let name = &w.checked().effects[e.index()].name;
            w.line(indent, format!("let {} = {};", w.effect_name(e), Name::PixelValue.of(name)));
        };
        self.pixel_body(1, &mut prologue, &mut coarse_value);
        self.template(0, body, &[]);
    }

    /// Where the background rule makes pixel `p` background (refinement not
    /// forced): its record holds no evaluated bit, every coarse
    /// effect's value is zero for `mrsl_finish`, and the function returns
    /// with `returns`; so it is neither shaded nor interpolated.
    fn background_pixel(&mut self, indent: usize, returns: &str) {
        if !self.has_background() {
            return;
        }
        self.line(indent, format!("if ({}) {{", self.background_here("p")));
        self.clear_record(indent + 1);
        self.line(indent + 1, returns);
        self.line(indent, "}");
    }

    /// Background pixel `p`: no evaluated bit in its record's mask words
    /// (which `mrsl_finish` counts from) and every coarse effect zero for
    /// `mrsl_finish`. Its other words are left as they are: a neighbour that
    /// is not background is across the background channel's key from it, so
    /// never uses its values or flags, and one that is background reads no
    /// neighbour.
    fn clear_record(&mut self, indent: usize) {
        let c = self.checked();
        let zeros = vec!["0u".to_string(); self.i.layout.hierarchical.mask_words as usize];
        self.store_masks(indent, &zeros);
        for e in self.coarse_live() {
            let info = &c.effects[e.index()];
            self.line(indent, format!("{} = {}();", Name::PixelValue.of(&info.name), info.ty.wgsl()));
        }
    }

    /// The end of an entry point that finishes pixels: its workgroup's
    /// statistics added up, where the kernel counts them.
    fn flush_finished(&mut self, lanes: u32) {
        if self.counts_stats() {
            self.flush_workgroup_stats(lanes);
        }
    }

    /// `mrsl_count` and `mrsl_work_offset`: where each level's work list
    /// starts, the lists lying one after another with their lattices' sizes.
    fn work_lists(&mut self) {
        let [head, tail] = cut(include_str!("templates/work_lists.wgsl"), &["LEVEL_SIZES"]);
        self.template(0, head, &[]);
        let last = HIERARCHICAL_LEVELS.len();
        for (index, l) in HIERARCHICAL_LEVELS[..last - 1].iter().enumerate() {
            let count = |axis: &str| format!("{COUNT}({}u, {}u, {axis})", l.start, l.step);
            self.line(1, format!("let c{} = {} * {};", index + 1, count("w"), count("h")));
        }
        let mut offset = "0u".to_string();
        for level in 2..=last {
            let before: Vec<String> = (1..level).map(|j| format!("c{j}")).collect();
            offset = format!("select({offset}, {}, level >= {level}u)", before.join(" + "));
        }
        self.template(0, tail, &[("OFFSET", &offset)]);
    }

    /// `mrsl_shade(pos)`: evaluates the coarse effects the pixel's mask names
    /// (reading the others from the records) and stores their values and
    /// refine flags. With `last`, `mrsl_shade_last(pos)` for the last level,
    /// whose flags no classification reads: the effects are evaluated for
    /// their values alone (`mrsl_val_<effect>`, without what only decides a
    /// flag, such as a predicate's derivatives), and the flags stored are 0.
    /// The values are the same computation either way.
    fn shade_function(&mut self, last: bool) {
        let c = self.checked();
        let flag_words = self.i.layout.hierarchical.flag_words;
        let [head, force, end] = cut(include_str!("templates/shade.wgsl"), &["FLAG_WORDS", "EFFECTS"]);
        let (name, what) = if last { (SHADE_LAST, " (their refine flags 0)") } else { (SHADE, " and refine flags") };
        self.template(0, head, &[("NAME", &name), ("WHAT", &what)]);
        self.declare_flag_words(flag_words);
        let own = if self.packed() {
            self.line(1, format!("let {PIXEL_RECORD} = {LOAD_RECORD}({POS});"));
            self.load_masks_from(1, PIXEL_RECORD);
            PIXEL_RECORD
        } else {
            self.load_pixel_masks(1);
            POS
        };
        if !last {
            self.template(0, force, &[]);
        }
        let [evaluate, put, flag, read] =
            cut(include_str!("templates/shade_effect.wgsl"), &["EVALUATE", "PUT", "FLAG"]);
        // The stored effects without a refine flag (an effect with one is
        // evaluated for its flag).
        let level0_values: Vec<EffectId> = match self.stores_level0_values() {
            true => {
                let stored = self.neighbour_values().into_iter().map(|(e, _)| e);
                stored.filter(|e| !c.effects[e.index()].has_refine).collect()
            }
            false => vec![],
        };
        for e in self.coarse_live() {
            let info = &c.effects[e.index()];
            let (mask_word, mask) = bit(self.coarse_index[&e]);
            let var = self.effect_name(e);
            let ty = info.ty.wgsl();
            let values: [(&str, &dyn Display); 6] = [
                ("VAR", &var),
                ("TYPE", &ty),
                ("MASK_WORD", &mask_word),
                ("MASK", &mask),
                ("NAME", &info.name),
                ("OWN", &own),
            ];
            self.template(1, evaluate, &values);
            if !last && level0_values.contains(&e) {
                // Level 0 reads what `hier_level0_values` evaluated here: the same value.
                self.line(2, format!("if ({LEVEL} == 0u) {{"));
                self.line(3, format!("{var} = {};", self.level0_value(e)));
                self.line(2, "} else {");
                self.evaluate(e, 3, "", Evaluation::Kernel);
                self.line(2, "}");
            } else {
                self.evaluate(e, 2, "", if last { Evaluation::ValueOnly } else { Evaluation::Kernel });
            }
            self.template(1, put, &values);
            if !self.packed() {
                self.line(2, format!("{}({POS}, {var});", Name::RecordPut.of(&info.name)));
            }
            self.template(1, flag, &values);
            if !last {
                self.set_refine_flag(e, 2);
            }
            self.template(1, read, &values);
        }
        let flags: Vec<String> = (0..flag_words).map(|w| Name::FlagWord.of(w)).collect();
        // Word records keep the mask words the level stored; a packed record is stored whole.
        let mask_words = if self.packed() { self.i.layout.hierarchical.mask_words } else { 0 };
        let masks: Vec<String> = (0..mask_words).map(|w| Name::PixelMask.of(w)).collect();
        self.store_record(POS, &flags, &masks);
        self.template(0, end, &[]);
    }

    /// `hier_level0_values`: the layout's neighbour values (the coarse
    /// effects derivatives read elsewhere) evaluated at every pixel of level
    /// 0's lattice, for their values alone, and stored a texel per lattice
    /// point, before level 0 is shaded. Empty, and not dispatched, where the
    /// program has none.
    fn level0_values_entry(&mut self) {
        if !self.stores_level0_values() {
            self.line(0, "// No neighbour values (layout `neighbours`): the plan does not dispatch this.");
            self.line(0, "@compute @workgroup_size(1, 1, 1)");
            self.line(0, format!("fn {}() {{}}", entry::HIER_LEVEL0_VALUES));
            self.line(0, "");
            return;
        }
        let [head, values_here, end] = cut(include_str!("templates/level0_values.wgsl"), &["INVOCATION", "VALUES"]);
        let (params, invocation, valid) = self.level_invocation(HIERARCHICAL_LEVEL0);
        let values: &super::writer::Values = &[
            ("PARAMS", &params),
            ("VALID", &valid),
            ("WORKGROUP", &lattice_workgroup()),
            ("ENTRY", &entry::HIER_LEVEL0_VALUES),
            ("PIXEL", &lattice_pixel(HIERARCHICAL_LEVEL0)),
        ];
        self.template(0, head, values);
        if let Some(line) = &invocation {
            self.line(1, line);
        }
        self.template(0, values_here, values);
        self.store_neighbour_values(2, &format!("{POS} / {}", HIERARCHICAL_LEVEL0.step));
        self.template(0, end, values);
    }

    /// Level 0: every pixel of its lattice is shaded.
    fn level0(&mut self) {
        let coarse = self.coarse_live().len() as u32;
        let [head, entry, body, end] = cut(include_str!("templates/level0.wgsl"), &["MASKS", "INVOCATION", "FLUSH"]);
        let (params, invocation, valid) = self.level_invocation(HIERARCHICAL_LEVEL0);
        let values: &super::writer::Values = &[
            ("PARAMS", &params),
            ("VALID", &valid),
            ("STEP", &HIERARCHICAL_LEVEL0.step),
            ("WORKGROUP", &lattice_workgroup()),
            ("ENTRY", &entry::HIER_LEVEL0),
            ("PIXEL", &lattice_pixel(HIERARCHICAL_LEVEL0)),
        ];
        self.template(0, head, values);
        self.background_pixel(1, "return;");
        let masks: Vec<String> = (0..self.i.layout.hierarchical.mask_words)
            .map(|w| {
                let bits = coarse.saturating_sub(w * 32).min(32);
                let mask = if bits == 32 { u32::MAX } else { (1u32 << bits) - 1 };
                format!("{mask}u")
            })
            .collect();
        self.store_masks(1, &masks);
        self.template(0, entry, values);
        if let Some(line) = &invocation {
            self.line(1, line);
        }
        self.template(0, body, values);
        self.flush_finished(COARSE_WORKGROUP * COARSE_WORKGROUP);
        self.template(0, end, values);
    }

    /// `mrsl_classify(p, n, level)`: per coarse effect, interpolate pixel `p`
    /// from its neighbours `n` or mark it to be shaded; queue it if any is.
    /// Each effect's test is a function of its own (`mrsl_classify_<effect>`,
    /// written first), which `mrsl_classify` calls in effect order.
    fn classify_function(&mut self) {
        let mw = self.i.layout.hierarchical.mask_words;
        let fw = self.i.layout.hierarchical.flag_words;
        self.template(0, include_str!("templates/classify_effects.wgsl"), &[]);
        let calls: Vec<String> = self.coarse_live().into_iter().map(|e| self.classify_effect(e)).collect();
        let [head, keys, effects, end] =
            cut(include_str!("templates/classify.wgsl"), &["BACKGROUND", "KEYS", "EFFECTS"]);
        self.template(0, head, &[]);
        self.background_pixel(1, "return true;");
        self.template(0, keys, &[]);
        for key in self.keys_of(&self.coarse_live()) {
            let name = key.name;
            let differs = key.differs(&format!("k_{name}"), &key.load("q[k]"));
            let values: &super::writer::Values = &[("NAME", &name), ("LOAD", &key.loader()), ("DIFFERS", &differs)];
            self.template(0, include_str!("templates/classify_key.wgsl"), values);
        }
        self.template(0, effects, &[]);
        for w in 0..mw {
            self.line(1, format!("var mask{w} = 0u;"));
        }
        if self.packed() {
            let loads: Vec<String> = (0..4).map(|j| format!("{LOAD_RECORD}(q[{j}])")).collect();
            let records = format!("array<{RECORD_TYPE}, 4>({})", loads.join(", "));
            self.line(1, format!("let {NEIGHBOUR_RECORDS} = {records};"));
        }
        self.neighbour_flag_words();
        for call in &calls {
            self.line(1, call);
        }
        let flags = vec!["0u".to_string(); fw as usize];
        let masks: Vec<String> = (0..mw).map(|w| format!("mask{w}")).collect();
        self.store_record("p", &flags, &masks);
        let any: Vec<String> = (0..mw).map(|w| format!("mask{w}")).collect();
        self.template(0, end, &[("ANY_MASK", &any.join(" | ")), ("QUEUE_WORDS", &QUEUE_WORDS_PER_LEVEL)]);
    }

    /// Writes `mrsl_classify_<effect>` for coarse effect `e` and returns the
    /// line of `mrsl_classify` that calls it. Its parameters are what the
    /// test reads of `mrsl_classify`'s locals: the pixel, the neighbours (or
    /// their packed records), which are inside the image and across each key
    /// the effect reads, whether refinement is forced, the neighbours' flag
    /// word holding its refine bit, and the mask word its bit is set in.
    fn classify_effect(&mut self, e: EffectId) -> String {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let (word, mask) = bit(self.coarse_index[&e]);
        let from = if self.packed() { NEIGHBOUR_RECORDS } else { "q" };
        let from_type = if self.packed() { RECORD_TYPE } else { "vec2<i32>" };
        let mut params = vec![("p", "vec2<i32>".to_string()), (from, format!("array<{from_type}, 4>"))];
        params.push(("inside", "array<bool, 4>".into()));
        let mut args: Vec<String> = params.iter().map(|(name, _)| name.to_string()).collect();
        let keys: Vec<String> =
            self.i.graph.keys[e.index()].iter().map(|i| format!("across_{}", c.inputs[i.index()].name)).collect();
        let on_side: String = keys.iter().map(|across| format!(" && !{across}[k]")).collect();
        let flag = self.i.interface.refine_bit[e.index()].map(bit);
        let flags = flag.map(|(w, _)| Name::NeighbourFlags.of(w));
        let mask_word = format!("mask{word}");
        let mut typed: Vec<String> = params.iter().map(|(name, ty)| format!("{name}: {ty}")).collect();
        for across in &keys {
            typed.push(format!("{across}: array<bool, 4>"));
            args.push(across.clone());
        }
        typed.push("force: bool".into());
        args.push("force".into());
        if let Some(flags) = &flags {
            typed.push(format!("{flags}: array<u32, 4>"));
            args.push(flags.clone());
        }
        typed.push(format!("{mask_word}: ptr<function, u32>"));
        args.push(format!("&{mask_word}"));
        let [head_effect, tests_effect, tail_effect] =
            cut(include_str!("templates/classify_effect.wgsl"), &["TESTS", "PUT"]);
        let params = typed.join(", ");
        let head: &super::writer::Values =
            &[("NAME", &info.name), ("ON_SIDE", &on_side), ("FROM", &from), ("PARAMS", &params), ("WORD", &word)];
        self.template(0, head_effect, head);
        // `disc` first: the ablation's edits find the test by it.
        let mut need = vec!["disc".to_string()];
        if let Some((word, mask)) = flag {
            // The program's own predicate, as evaluated at the neighbours.
            self.template(0, include_str!("templates/classify_flagged.wgsl"), &[("WORD", &word), ("MASK", &mask)]);
            need.push("flagged".into());
        }
        let value = self.value_test(&info.ty, &mut need);
        let values: &super::writer::Values =
            &[("NEED", &need.join(" || ")), ("WORD", &word), ("MASK", &mask), ("NAME", &info.name), ("VALUE", &value)];
        self.template(0, tests_effect, values);
        if !self.packed() {
            self.line(2, format!("{}(p, {value});", Name::RecordPut.of(&info.name)));
        }
        self.template(0, tail_effect, values);
        self.line(0, "");
        format!("{}({});", Name::Classify.of(&info.name), args.join(", "))
    }

    /// The classification's test of an effect of type `ty` beyond `disc`
    /// and `flagged`, pushed onto `need` (its lines written before it), and
    /// the value the pixel stores where no test holds.
    fn value_test(&mut self, ty: &Type, need: &mut Vec<String>) -> &'static str {
        let interpolable = matches!(ty, Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _));
        if interpolable {
            let zero = format!("{}(0.0)", ty.wgsl());
            let w = |j: usize| format!("select({zero}, v{j}, ok[{j}])");
            self.line(1, format!("let mean = ({} + {} + {} + {}) / total;", w(0), w(1), w(2), w(3)));
            let dev = |j: usize| format!("select({zero}, (v{j} - mean) * (v{j} - mean), ok[{j}])");
            self.line(1, format!("let variance = ({} + {} + {} + {}) / total;", dev(0), dev(1), dev(2), dev(3)));
            // The variance relative to the values' size (the largest
            // square among the neighbours), so one similarity holds for
            // a distance of hundreds of units and a colour of 0.01.
            let sq = |j: usize| format!("select({zero}, v{j} * v{j}, ok[{j}])");
            self.line(1, format!("let scale = max(max({}, {}), max({}, {}));", sq(0), sq(1), sq(2), sq(3)));
            let spread = |v: &str| match ty.components() {
                1 => v.to_string(),
                2 => format!("max({v}.x, {v}.y)"),
                3 => format!("max(max({v}.x, {v}.y), {v}.z)"),
                _ => format!("max(max({v}.x, {v}.y), max({v}.z, {v}.w))"),
            };
            let (spread, scale) = (spread("variance"), spread("scale"));
            need.push(format!("!({spread} <= {CONTROL}.similarity * {scale})"));
            "mean"
        } else {
            // Integer and bool values are copied only when every used
            // neighbour agrees with the first used one (of pair (0, 1) if
            // it is complete, else of pair (2, 3): an unused neighbour's
            // record may be another frame's); matrix values never are.
            if matches!(ty, Type::Matrix(_)) {
                need.push("true".into());
                "v0"
            } else {
                self.line(1, "let first = select(v2, v0, ok[0]);");
                let eq = |j: usize| {
                    if ty.components() == 1 {
                        format!("(!ok[{j}] || v{j} == first)")
                    } else {
                        format!("(!ok[{j}] || all(v{j} == first))")
                    }
                };
                need.push(format!("!({} && {} && {} && {})", eq(0), eq(1), eq(2), eq(3)));
                "first"
            }
        }
    }

    /// The pixel's mask words (`mrsl_pmask<w>`), loaded once for every
    /// effect's test: llvmpipe loads a read-write storage texel again after
    /// each store to the texture in between, so a load per effect costs one.
    fn load_pixel_masks(&mut self, indent: usize) {
        let h = &self.i.layout.hierarchical;
        let (flag_words, mask_words) = (h.flag_words, h.mask_words);
        for w in 0..mask_words {
            self.line(indent, format!("let {} = {WORD}({POS}, {}u);", Name::PixelMask.of(w), flag_words + w));
        }
    }

    /// The pixel's mask words taken from its packed record, held in `record`.
    fn load_masks_from(&mut self, indent: usize, record: &str) {
        let h = &self.i.layout.hierarchical;
        let (flag_words, mask_words) = (h.flag_words, h.mask_words);
        for w in 0..mask_words {
            self.line(indent, format!("let {} = {};", Name::PixelMask.of(w), record_word(record, flag_words + w)));
        }
    }

    /// The neighbours' flag words, loaded once for every effect's `flagged`
    /// test (as the mask words are in `mrsl_shade`), or taken from their
    /// packed records.
    fn neighbour_flag_words(&mut self) {
        let refine_bit = &self.i.interface.refine_bit;
        let words: std::collections::BTreeSet<u32> =
            self.coarse_live().iter().filter_map(|e| refine_bit[e.index()].map(|b| bit(b).0)).collect();
        let packed = self.packed();
        for w in words {
            let loads: Vec<String> = (0..4)
                .map(|j| {
                    if packed {
                        record_word(&format!("{NEIGHBOUR_RECORDS}[{j}]"), w)
                    } else {
                        format!("{WORD}(q[{j}], {w}u)")
                    }
                })
                .collect();
            self.line(1, format!("var {} = array<u32, 4>({});", Name::NeighbourFlags.of(w), loads.join(", ")));
        }
    }
}
