//! Per-pixel entry points, as the fine, reference, dynamic fine and the
//! record modes' final passes share them: lanes mapped to the pixels of a
//! tile, the in-image guard, the effects in dependency order, the output
//! stores, and the per-workgroup statistics that must all reach a barrier.

use super::Writer;
use super::writer::cut;
use crate::check::EffectId;
use crate::syntax::ast::Rate;
use crate::types::{Scalar, Type};
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::{FINE_PIXELS_PER_LANE, TILE};

/// The condition of the instrumentation a dispatch runs only with statistics
/// on (control field `statistics`): the rate image and the counters.
pub(super) const STATISTICS_ON: &str = "mrsl_ctl.statistics != 0u";

impl Writer<'_, '_, '_> {
    /// Whether the kernel counts per-pixel re-evaluations of coarse effects
    /// (statistics and rate image): the per-pixel kernels that can reuse
    /// coarse values, when there are live coarse effects.
    pub(super) fn counts_stats(&self) -> bool {
        let per_pixel_reuse =
            self.kind.is_fine() || matches!(self.kind, KernelKind::Hierarchical | KernelKind::Checkerboard);
        per_pixel_reuse && !self.coarse_live().is_empty()
    }

    /// The statistics counters (global and per workgroup) and the rate image.
    pub(super) fn stats_bindings(&mut self) {
        let l = self.i.layout;
        let [head, tail] = cut(include_str!("templates/stats.wgsl"), &["BUFFER"]);
        self.template(0, head, &[]);
        self.stats_buffer();
        self.template(
            0,
            tail,
            &[
                ("COUNTERS", &self.coarse_live().len()),
                ("RATE_GROUP", &l.rate_image.group),
                ("RATE_BINDING", &l.rate_image.binding),
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
    /// decisions, rate image, statistics), then every live effect in
    /// dependency order: coarse ones as `coarse` writes them (at an
    /// indentation), the others evaluated; then the outputs are stored.
    ///
    /// Pixels outside the image return at once unless the kernel counts
    /// statistics: then every lane must reach the barrier before the
    /// workgroup's counters are added up, so they skip the work instead.
    ///
    /// In the block modes' fine kernels a lane shades
    /// [`FINE_PIXELS_PER_LANE`] pixels of one block, one after the other,
    /// with the block's corners loaded once (`mrsl_c`). The pixels are
    /// written out one after the other, not as a loop: llvmpipe ran the
    /// re-evaluations inside a loop at about the one-pixel kernel's time,
    /// written out at 0.75 of it (paired, 1920x1080, docs/evaluation.md).
    pub(super) fn pixel_main(
        &mut self,
        mut prologue: impl FnMut(&mut Self),
        mut coarse: impl FnMut(&mut Self, EffectId, usize),
    ) {
        let [x, y, z] = self.kind.workgroup_size();
        let pairs = matches!(self.kind, KernelKind::Fine | KernelKind::DynamicFine);
        self.template(
            0,
            include_str!("templates/pixel_main.wgsl"),
            &[
                ("WORKGROUP", &format!("{x}, {y}, {z}")),
                ("ENTRY", &self.kind.main_entry_point()),
                ("FIRST", &if pairs { "mrsl_first" } else { "mrsl_pos" }),
            ],
        );
        let counted = self.counts_stats();
        if pairs {
            if !self.coarse_live().is_empty() {
                // A lane past the image's edge still loads (clamped) corners: it skips its pixels below.
                self.line(1, "let mrsl_c = mrsl_corners(min(mrsl_first, mrsl_grid() - vec2<i32>(1)));");
                self.corners_loaded = true;
            }
            for k in 0..FINE_PIXELS_PER_LANE {
                let at = match k * self.block / FINE_PIXELS_PER_LANE {
                    0 => "mrsl_first".to_string(),
                    dy => format!("(mrsl_first + vec2<i32>(0, {dy}))"),
                };
                self.line(1, format!("if (all({at} < mrsl_grid())) {{"));
                self.line(2, format!("let mrsl_pos = {at};"));
                self.pixel_body(2, &mut prologue, &mut coarse);
                self.line(1, "}");
            }
            self.corners_loaded = false;
        } else {
            // The record modes' final passes keep one shape, counting or not.
            let returns = !counted && !matches!(self.kind, KernelKind::Hierarchical | KernelKind::Checkerboard);
            if returns {
                self.line(1, "if (any(mrsl_pos >= mrsl_grid())) { return; }");
                self.pixel_body(1, &mut prologue, &mut coarse);
            } else {
                self.line(1, "if (all(mrsl_pos < mrsl_grid())) {");
                self.pixel_body(2, &mut prologue, &mut coarse);
                self.line(1, "}");
            }
        }
        if counted {
            self.template(
                0,
                include_str!("templates/stats_flush.wgsl"),
                &[("COUNTERS", &self.coarse_live().len()), ("WORKGROUP", &x), ("STATISTICS_ON", &STATISTICS_ON)],
            );
        }
        self.line(0, "}");
    }

    /// One pixel's work at `mrsl_pos` (see [`Writer::pixel_main`]).
    fn pixel_body(
        &mut self,
        indent: usize,
        prologue: &mut impl FnMut(&mut Self),
        coarse: &mut impl FnMut(&mut Self, EffectId, usize),
    ) {
        prologue(self);
        let order = self.i.graph.order.clone();
        for &e in &order {
            if self.checked().effects[e.index()].rate == Rate::Coarse {
                coarse(self, e, indent);
            } else {
                self.evaluate(e, indent, "let ");
            }
        }
        self.output_stores(&order, indent);
    }

    /// Counts coarse effect `k` as re-evaluated by this pixel where `condition`
    /// holds (inside a `statistics_on` block, hence the indentation).
    pub(super) fn count_refined(&mut self, k: usize, condition: &str) {
        self.line(3, format!("if ({condition}) {{ atomicAdd(&mrsl_wg_stats[{k}], 1u); }}"));
    }

    /// Opens the block of instrumentation a dispatch runs only with
    /// statistics on (control field `statistics`): the rate image and the
    /// counters. Timed runs leave it out; the branch is uniform.
    pub(super) fn statistics_on(&mut self, indent: usize) {
        self.line(indent, format!("if ({STATISTICS_ON}) {{"));
    }

    pub(super) fn output_stores(&mut self, order: &[EffectId], indent: usize) {
        let c = self.checked();
        for e in order {
            let info = &c.effects[e.index()];
            if info.rate != Rate::Out {
                continue;
            }
            let value = to_vec4(&self.effect_name(*e), &info.ty);
            self.line(indent, format!("textureStore(mrsl_out_{}, mrsl_pos, {value});", info.name));
        }
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
