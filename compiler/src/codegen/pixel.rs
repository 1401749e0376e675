//! Per-pixel entry points, as the fine, reference, dynamic fine and the
//! record modes' final passes share them: lanes mapped to the pixels of a
//! tile, the in-image guard, the effects in dependency order, the output
//! stores, and the per-workgroup statistics that must all reach a barrier.

use super::effects::Evaluation;
use super::names::{
    BLOCK, BLOCK_STRUCT, CONTROL, CORNERS, CORNERS_STRUCT, FIRST, GRID, INNER_BLOCK, IS_REFINED, LANE_PIXEL,
    LEVEL_VALUES, LOAD_CORNERS, Name, POS, WORKGROUP_STATS,
};
use super::words::pack_words;
use super::writer::cut;
use super::{ViewLevel, Writer};
use crate::check::EffectId;
use crate::limits::MAX_PARAMETERS;
use crate::syntax::ast::Rate;
use crate::types::{Scalar, Type};
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::{FINE_PIXELS_PER_LANE, TILE};

/// The condition of the instrumentation a dispatch runs only with statistics
/// on (control field `statistics`): the refine mask and the counters.
pub(super) fn statistics_enabled() -> String {
    format!("{CONTROL}.statistics != 0u")
}

/// What a per-pixel prologue ([`Writer::pixel_main`]) finds in scope besides `mrsl_pos`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Scope {
    /// Nothing more: a fine kernel's prologue resolves the pixel.
    Position,
    /// `mrsl_b` (in the dynamic mode also `mrsl_b2`), the pixel's blocks,
    /// which the entry point resolved for its lane's pixels ([`Writer::effect_major_pixels`]).
    Resolved,
}

impl Writer<'_, '_, '_> {
    /// Whether the kernel counts per-pixel re-evaluations of coarse effects
    /// (statistics and refine mask): the per-pixel kernels that can reuse
    /// coarse values, when there are live coarse effects.
    pub(super) fn counts_stats(&self) -> bool {
        let per_pixel_reuse =
            self.kind.is_fine() || matches!(self.kind, KernelKind::Hierarchical | KernelKind::Checkerboard);
        per_pixel_reuse && !self.coarse_live().is_empty()
    }

    /// The statistics counters (global and per workgroup) and the refine mask.
    pub(super) fn stats_bindings(&mut self) {
        let l = self.i.layout;
        let [head, tail] = cut(include_str!("templates/stats.wgsl"), &["BUFFER"]);
        self.template(0, head, &[]);
        self.stats_buffer();
        self.template(
            0,
            tail,
            &[
                ("COUNTERS", &self.workgroup_counters()),
                ("MASK_GROUP", &l.refine_mask.group),
                ("MASK_BINDING", &l.refine_mask.binding),
            ],
        );
    }

    /// The global statistics counters (layout `stats`).
    pub(super) fn stats_buffer(&mut self) {
        let stats = &self.i.layout.stats;
        self.template(
            0,
            include_str!("templates/stats_buffer.wgsl"),
            &[("GROUP", &stats.group), ("BINDING", &stats.binding)],
        );
    }

    /// `mrsl_tile_pixel` for tiles shaded in `block`x`block` blocks: consecutive
    /// lanes cover whole blocks. With `per_lane` pixels per lane (the block
    /// fine kernels' [`FINE_PIXELS_PER_LANE`]), the lane's first pixel; the
    /// others lie `block / per_lane` rows apart in the same block.
    pub(super) fn tile_pixel_blocks(&mut self, block: u32, per_lane: u32) {
        assert_eq!(block % per_lane, 0, "a block's rows split evenly among a lane's pixels");
        let values: &super::writer::Values = &[
            ("TILE", &TILE),
            ("BLOCK", &block),
            ("PER_BLOCK", &(block * block / per_lane)),
            ("BLOCKS_X", &(TILE / block)),
        ];
        let [comment, function] = cut(include_str!("templates/tile_pixel_blocks.wgsl"), &["LANES"]);
        self.template(0, comment, values);
        if per_lane > 1 {
            let rows = block / per_lane;
            self.line(
                0,
                format!("// With {per_lane} pixels per lane, the lane's first: the others follow at steps of"),
            );
            self.line(0, format!("// +(0, {rows}) in the same block and share its coarse samples."));
        }
        self.template(0, function, values);
    }

    /// `mrsl_tile_pixel` for tiles shaded in row-major order.
    pub(super) fn tile_pixel_rows(&mut self) {
        self.template(0, include_str!("templates/tile_pixel_rows.wgsl"), &[("TILE", &TILE)]);
    }

    /// The kernel's main entry point, one lane per pixel of a tile (after
    /// `mrsl_tile_pixel`). Inside the image, `prologue` runs (refine
    /// decisions, refine mask, statistics), then every live effect in
    /// dependency order: coarse ones as `coarse` writes them (at an
    /// indentation), the others evaluated; then the outputs are stored.
    ///
    /// Pixels outside the image return at once unless the kernel counts
    /// statistics: then every lane must reach the barrier before the
    /// workgroup's counters are added up, so they skip the work instead.
    ///
    /// In the block modes' and the dynamic mode's fine kernels a lane shades
    /// [`FINE_PIXELS_PER_LANE`] pixels of one block with the block's corners
    /// loaded once (`mrsl_c`), effect by effect when the program has coarse
    /// effects ([`Self::effect_major_pixels`]). (A loop over the pixels, the
    /// whole work in its body, ran at about the one-pixel kernel's time on
    /// llvmpipe; the pixels written out one after the other at 0.75 of it;
    /// docs/eval/evaluation.md.)
    pub(super) fn pixel_main(
        &mut self,
        mut prologue: impl FnMut(&mut Self, Scope),
        mut coarse: impl FnMut(&mut Self, EffectId, usize),
    ) {
        let [x, y, z] = self.kind.workgroup_size();
        let pairs = matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine);
        let [head, tail] = cut(include_str!("templates/pixel_main.wgsl"), &["LISTED"]);
        let workgroup = format!("{x}, {y}, {z}");
        self.template(0, head, &[("WORKGROUP", &workgroup), ("ENTRY", &self.file.main_entry_point())]);
        let tile = self.surface_tile(1);
        self.template(0, tail, &[("FIRST", &if pairs { FIRST } else { POS }), ("TILE", &tile)]);
        self.pixel_lanes(&mut prologue, &mut coarse);
        if self.counts_stats() {
            self.flush_workgroup_stats(x);
        }
        self.line(0, "}");
    }

    /// The body of [`Self::pixel_main`] after its lane's first pixel, without
    /// the statistics' flush: the lane's pixels' work.
    pub(super) fn pixel_lanes(
        &mut self,
        prologue: &mut impl FnMut(&mut Self, Scope),
        coarse: &mut impl FnMut(&mut Self, EffectId, usize),
    ) {
        let pairs = matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine);
        let counted = self.counts_stats();
        if pairs && !self.coarse_live().is_empty() {
            self.effect_major_pixels(prologue);
        } else if pairs {
            // No coarse effects: the pixels' work, one after the other.
            for k in 0..FINE_PIXELS_PER_LANE {
                let at = self.lane_pixel(k);
                self.line(1, format!("if (all({at} < {GRID}())) {{"));
                self.line(2, format!("let {POS} = {at};"));
                self.pixel_body(2, prologue, coarse);
                self.line(1, "}");
            }
        } else {
            // The record modes' final passes keep one shape, counting or not.
            let returns = !counted && !matches!(self.kind, KernelKind::Hierarchical | KernelKind::Checkerboard);
            if returns {
                self.line(1, format!("if (any({POS} >= {GRID}())) {{ return; }}"));
                self.pixel_body(1, prologue, coarse);
            } else {
                self.line(1, format!("if (all({POS} < {GRID}())) {{"));
                self.pixel_body(2, prologue, coarse);
                self.line(1, "}");
            }
        }
    }

    /// The end of a counting entry point of `lanes` lanes: the workgroup's
    /// counters added to the statistics buffer once.
    pub(super) fn flush_workgroup_stats(&mut self, lanes: u32) {
        self.template(
            0,
            include_str!("templates/stats_flush.wgsl"),
            &[
                ("COUNTERS", &self.workgroup_counters()),
                ("TARGET", &self.counter_target()),
                ("WORKGROUP", &lanes),
                ("STATISTICS_ON", &statistics_enabled()),
            ],
        );
    }

    /// One pixel's work at `mrsl_pos` (see [`Writer::pixel_main`]).
    pub(super) fn pixel_body(
        &mut self,
        indent: usize,
        prologue: &mut impl FnMut(&mut Self, Scope),
        coarse: &mut impl FnMut(&mut Self, EffectId, usize),
    ) {
        prologue(self, Scope::Position);
        let order = self.i.graph.order.clone();
        for &e in &order {
            if self.checked().effects[e.index()].rate == Rate::Coarse {
                coarse(self, e, indent);
            } else {
                self.evaluate(e, indent, "let ", Evaluation::Kernel);
            }
        }
        self.output_stores(&order, indent);
    }

    /// The per-workgroup counters: one per coarse effect, and with a
    /// background rule one more, the background pixels.
    pub(super) fn workgroup_counters(&self) -> usize {
        self.i.counters.len() + usize::from(self.has_background())
    }

    /// Where workgroup counter `k` goes in the statistics buffer: counter `k`
    /// for a coarse effect; the background pixels after the dynamic mode's
    /// count of 2x2 samples (layout `stats`).
    pub(super) fn counter_target(&self) -> String {
        let k = self.i.counters.len();
        if self.has_background() { format!("select(k, k + 1u, k == {k}u)") } else { "k".to_string() }
    }

    /// Counts the pixel as background, and writes the refine mask's mark of
    /// one (x 0, y all ones), where `block` says so (inside a
    /// `statistics_on` block).
    pub(super) fn count_background(&mut self, block: &str) {
        if self.has_background() {
            let k = self.i.counters.len();
            self.line(3, format!("if ({block}.background) {{ atomicAdd(&{WORKGROUP_STATS}[{k}], 1u); }}"));
        }
    }

    /// What the refine mask's `.y` holds: `inner` (the dynamic mode's 2x2
    /// level), or all ones at a background pixel.
    pub(super) fn mask_y(&self, block: &str, inner: &str) -> String {
        if self.has_background() {
            format!("select({inner}, 0xffffffffu, {block}.background)")
        } else {
            inner.to_string()
        }
    }

    /// Counts coarse effect `k` as re-evaluated by this pixel where `condition`
    /// holds (inside a `statistics_on` block, hence the indentation).
    pub(super) fn count_refined(&mut self, k: usize, condition: &str) {
        self.count_refined_at(3, k, condition);
    }

    /// [`Self::count_refined`] at an indentation.
    pub(super) fn count_refined_at(&mut self, indent: usize, k: usize, condition: &str) {
        self.line(indent, format!("if ({condition}) {{ atomicAdd(&{WORKGROUP_STATS}[{k}], 1u); }}"));
    }

    /// Opens the block of instrumentation a dispatch runs only with
    /// statistics on (control field `statistics`): the refine mask and the
    /// counters. Timed runs leave it out; the branch is uniform.
    pub(super) fn statistics_on(&mut self, indent: usize) {
        self.line(indent, format!("if ({}) {{", statistics_enabled()));
    }

    pub(super) fn output_stores(&mut self, order: &[EffectId], indent: usize) {
        self.output_stores_at(order, indent, POS, "");
    }

    /// [`Self::output_stores`] at `pos`, of the values named `{prefix}{output}`.
    fn output_stores_at(&mut self, order: &[EffectId], indent: usize, pos: &str, prefix: &str) {
        let c = self.checked();
        for e in order {
            let info = &c.effects[e.index()];
            if info.rate != Rate::Out {
                continue;
            }
            let value = to_vec4(&format!("{prefix}{}", self.effect_name(*e)), &info.ty);
            self.line(indent, format!("textureStore({}, {pos}, {value});", Name::Out.of(&info.name)));
        }
        if let ViewLevel::Outer { values, .. } = self.i.level {
            // The multi-rate resolve pass: the values finer levels read, stored at the pixel.
            for &(e, offset) in values {
                let info = &c.effects[e.index()];
                for (j, word) in pack_words(&format!("{prefix}{}", self.effect_name(e)), &info.ty).iter().enumerate() {
                    let layer = offset + j as u32;
                    let store = format!("textureStore({LEVEL_VALUES}, {pos}, {layer}, vec4<u32>({word}, 0u, 0u, 0u));");
                    self.line(indent, store);
                }
            }
        }
    }

    /// The `k`-th pixel of a block fine kernel's lane: the first
    /// (`mrsl_first`), or `B / FINE_PIXELS_PER_LANE` rows per step below it.
    fn lane_pixel(&self, k: u32) -> String {
        match k * self.block / FINE_PIXELS_PER_LANE {
            0 => FIRST.to_string(),
            dy => format!("{FIRST} + vec2<i32>(0, {dy})"),
        }
    }

    /// The block and dynamic fine kernels' pixels, effect by effect: a lane
    /// resolves its [`FINE_PIXELS_PER_LANE`] pixels of one block
    /// (`mrsl_pos<k>`, `mrsl_b<k>`, in the dynamic mode also the inner level
    /// `mrsl_inner<k>`; the values `mrsl_v<k>_<effect>`), then evaluates
    /// each effect for all of them. A coarse effect is resampled at each
    /// pixel (in the dynamic mode from the inner level where the outer one
    /// refined it) and re-evaluated, in a loop, at the pixels that refine it
    /// at their innermost level.
    ///
    /// Why a loop and not a branch per pixel: llvmpipe runs the body of an
    /// `if` that no lane of a SIMD group takes (masked), and leaves a loop
    /// only after its first iteration, once no lane is left in it. A branch
    /// per pixel therefore costs a masked evaluation per pixel where nothing
    /// is refined; the loop costs one per lane, and where a lane refines one
    /// pixel of its two it runs the evaluation once, not twice (ablation
    /// "nothing refined at run time", docs/eval/evaluation.md).
    fn effect_major_pixels(&mut self, prologue: &mut impl FnMut(&mut Self, Scope)) {
        let pixels: Vec<u32> = (0..FINE_PIXELS_PER_LANE).collect();
        self.resolve_lane_pixels(prologue);
        let c = self.checked();
        let order = self.i.graph.order.clone();
        for &e in &order {
            if c.effects[e.index()].rate == Rate::Coarse {
                self.lane_coarse_value(e);
                continue;
            }
            for &k in &pixels {
                let (pos, prefix) = (Name::LanePos.of(k), Name::LaneValue.within(k, ""));
                self.evaluate_at(e, 1, "let ", &pos, &prefix, Evaluation::Kernel);
            }
        }
        for &k in &pixels {
            self.line(1, format!("if ({}) {{", Name::LaneIn.of(k)));
            self.output_stores_at(&order, 2, &Name::LanePos.of(k), &Name::LaneValue.within(k, ""));
            self.line(1, "}");
        }
    }

    /// The start of [`Self::effect_major_pixels`]: the lane's block corners,
    /// each pixel's position (`mrsl_pos<k>`), whether it is in the image
    /// (`mrsl_in<k>`) and its resolved blocks (`mrsl_b<k>`, `mrsl_inner<k>`),
    /// then each pixel's `prologue`.
    fn resolve_lane_pixels(&mut self, prologue: &mut impl FnMut(&mut Self, Scope)) {
        let dynamic = self.kind == KernelKind::DynamicFine;
        let resolve = self.own_level_resolver();
        // A lane past the image's edge still loads (clamped) corners and
        // resolves; its pixels' statistics and stores are skipped below.
        self.line(1, format!("let {CORNERS} = {LOAD_CORNERS}(min({FIRST}, {GRID}() - vec2<i32>(1)));"));
        for k in 0..FINE_PIXELS_PER_LANE {
            let (pos, block) = (Name::LanePos.of(k), Name::LaneBlock.of(k));
            self.line(1, format!("let {pos} = {};", self.lane_pixel(k)));
            self.line(1, format!("let {} = all({pos} < {GRID}());", Name::LaneIn.of(k)));
            self.line(1, format!("let {block} = {resolve}({pos}, {CORNERS});"));
            if dynamic {
                self.resolve_inner(1, "", [&pos, &block, &Name::LaneInner.of(k)]);
            }
        }
        for k in 0..FINE_PIXELS_PER_LANE {
            self.line(1, format!("if ({}) {{", Name::LaneIn.of(k)));
            self.line(2, format!("let {POS} = {};", Name::LanePos.of(k)));
            self.line(2, format!("let {BLOCK} = {};", Name::LaneBlock.of(k)));
            if dynamic {
                self.line(2, format!("let {INNER_BLOCK} = {};", Name::LaneInner.of(k)));
            }
            prologue(self, Scope::Resolved);
            self.line(1, "}");
        }
    }

    /// Whether the kernel's lanes shade their pixels effect by effect
    /// ([`Self::effect_major_pixels`]): the block and dynamic fine kernels
    /// (and the tile kernel's pixels) of a program with coarse effects.
    fn effect_major(&self) -> bool {
        matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine) && !self.coarse_live().is_empty()
    }

    /// `mrsl_lane_<effect>` of every coarse effect that has one
    /// ([`Self::lane_params`]), before the function whose lanes call them.
    pub(super) fn lane_functions(&mut self) {
        if !self.effect_major() {
            return;
        }
        self.template(0, include_str!("templates/lane_effects.wgsl"), &[]);
        for e in self.coarse_live() {
            let Some(params) = self.lane_params(e) else { continue };
            let info = &self.checked().effects[e.index()];
            let typed: Vec<String> = params.iter().map(|(name, ty)| format!("{name}: {ty}")).collect();
            self.line(0, format!("// `{}` at the lane's pixels.", info.name));
            self.line(0, format!("fn {}({}) {{", Name::Lane.of(&info.name), typed.join(", ")));
            self.lane_coarse_body(e, true);
            self.line(0, "}");
            self.line(0, "");
        }
    }

    /// The parameters of `mrsl_lane_<effect>`, which computes coarse effect
    /// `e` at the lane's pixels: what its part of the lane's work reads (the
    /// corners, each pixel's position, whether it is inside the image, its
    /// resolved blocks, its values of `e`'s dependencies) and, through
    /// pointers, each pixel's value of `e`. None where they would be more
    /// than WGSL allows: that effect's part stays in the lane's function.
    fn lane_params(&self, e: EffectId) -> Option<Vec<(String, String)>> {
        let c = self.checked();
        let pixels = 0..FINE_PIXELS_PER_LANE;
        let deps = self.deps_params(e);
        let mut params = vec![(CORNERS.to_string(), CORNERS_STRUCT.to_string())];
        for k in pixels.clone() {
            params.push((Name::LanePos.of(k), "vec2<i32>".into()));
            params.push((Name::LaneIn.of(k), "bool".into()));
            params.push((Name::LaneBlock.of(k), BLOCK_STRUCT.into()));
            if self.kind == KernelKind::DynamicFine {
                params.push((Name::LaneInner.of(k), BLOCK_STRUCT.into()));
            }
        }
        for d in &deps {
            let ty = c.effects[d.index()].ty.wgsl();
            params.extend(pixels.clone().map(|k| (Name::LaneValue.within(k, self.effect_name(*d)), ty.clone())));
        }
        let ty = format!("ptr<function, {}>", c.effects[e.index()].ty.wgsl());
        params.extend(pixels.map(|k| (Name::LaneValue.within(k, self.effect_name(e)), ty.clone())));
        (params.len() <= MAX_PARAMETERS).then_some(params)
    }

    /// Coarse effect `e` at the lane's pixels in [`Self::effect_major_pixels`]:
    /// a call of its `mrsl_lane_<effect>` (into the pixels' values, declared
    /// here), or where it has none, its work written here.
    fn lane_coarse_value(&mut self, e: EffectId) {
        let Some(params) = self.lane_params(e) else {
            return self.lane_coarse_body(e, false);
        };
        let info = &self.checked().effects[e.index()];
        for k in 0..FINE_PIXELS_PER_LANE {
            self.line(1, format!("var {}: {};", Name::LaneValue.within(k, self.effect_name(e)), info.ty.wgsl()));
        }
        let args: Vec<String> = params
            .iter()
            .map(|(name, ty)| if ty.starts_with("ptr<") { format!("&{name}") } else { name.clone() })
            .collect();
        self.line(1, format!("{}({});", Name::Lane.of(&info.name), args.join(", ")));
    }

    /// The work of coarse effect `e` at the lane's pixels: resampled at each
    /// (when passed), then re-evaluated in a loop at the pixels that refine
    /// it at their innermost level (`mrsl_b<k>`, or in the dynamic mode
    /// `mrsl_inner<k>`). In `mrsl_lane_<effect>` (`through`) the values are
    /// pointers the caller declared; in the lane's function, its variables.
    fn lane_coarse_body(&mut self, e: EffectId, through: bool) {
        let pixels: Vec<u32> = (0..FINE_PIXELS_PER_LANE).collect();
        let dynamic = self.kind == KernelKind::DynamicFine;
        let info = &self.checked().effects[e.index()];
        let (index, name) = (self.coarse_index[&e], self.effect_name(e));
        let value = |k: u32| format!("{}{}", if through { "*" } else { "" }, Name::LaneValue.within(k, &name));
        for &k in &pixels {
            if !self.i.interface.is_passed(e) {
                if !through {
                    self.line(1, format!("var {}: {};", value(k), info.ty.wgsl()));
                }
                continue;
            }
            let (block, inner) = (Name::LaneBlock.of(k), Name::LaneInner.of(k));
            let resample = self.level_resampler(false, &info.name);
            let declare = if through { "" } else { "var " };
            self.line(1, format!("{declare}{} = {resample}({block}, {CORNERS});", value(k)));
            if dynamic {
                let resample2 = self.level_resampler(true, &info.name);
                self.line(
                    1,
                    format!(
                        "if ({IS_REFINED}({block}, {index}u) && !{IS_REFINED}({inner}, {index}u)) {{ {} = {resample2}({inner}); }}",
                        value(k)
                    ),
                );
            }
        }
        let last = if dynamic { Name::LaneInner } else { Name::LaneBlock };
        let todo: Vec<String> = pixels
            .iter()
            .map(|&k| {
                let (inside, at) = (Name::LaneIn.of(k), last.of(k));
                format!("select(0u, {}u, {inside} && {IS_REFINED}({at}, {index}u))", 1u32 << k)
            })
            .collect();
        let todo_name = Name::Todo.of(&name);
        self.line(1, format!("// `{}`, re-evaluated at the lane's pixels that refine it", info.name));
        self.line(1, format!("var {todo_name} = {};", todo.join(" | ")));
        self.line(1, "loop {");
        self.line(2, format!("if ({todo_name} == 0u) {{ break; }}"));
        self.line(2, format!("let {LANE_PIXEL} = countTrailingZeros({todo_name});"));
        self.line(2, format!("{todo_name} &= {todo_name} - 1u;"));
        // The position and the dependencies of pixel `mrsl_k`, under the
        // names `evaluate` uses: `mrsl_pos` from `mrsl_pos<k>`, each
        // dependency from `mrsl_v<k>_<dependency>`.
        let mut locals = vec![(POS.to_string(), pixels.iter().map(|&k| Name::LanePos.of(k)).collect::<Vec<_>>())];
        for d in self.deps_params(e) {
            let dep = self.effect_name(d);
            let at = pixels.iter().map(|&k| Name::LaneValue.within(k, &dep)).collect();
            locals.push((dep, at));
        }
        for (local, at) in &locals {
            self.line(2, format!("var {local} = {};", at[0]));
            for &k in &pixels[1..] {
                self.line(2, format!("if ({LANE_PIXEL} == {k}u) {{ {local} = {}; }}", at[k as usize]));
            }
        }
        self.evaluate(e, 2, "let ", Evaluation::Kernel);
        for &k in &pixels {
            self.line(2, format!("if ({LANE_PIXEL} == {k}u) {{ {} = {name}; }}", value(k)));
        }
        self.line(1, "}");
    }
}

/// Widens an output value to the `vec4` that `textureStore` takes.
fn to_vec4(value: &str, ty: &Type) -> String {
    let (s, one) = match ty.scalar() {
        Some(Scalar::Uint) => ("u32", "1u"),
        Some(Scalar::Int) => ("i32", "1i"),
        _ => ("f32", "1.0"),
    };
    match ty.components() {
        1 => format!("vec4<{s}>({value}, 0, 0, {one})"),
        2 => format!("vec4<{s}>({value}, 0, {one})"),
        3 => format!("vec4<{s}>({value}, {one})"),
        _ => value.to_string(),
    }
}
