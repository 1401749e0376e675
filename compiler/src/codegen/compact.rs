//! The compacted fine pass of the block modes (`fine_main` of the `Fine`
//! kernels): He et al.'s "fine shading SIMD packets" within a workgroup.
//!
//! Where a block is refined, only some pixels of a workgroup re-evaluate a
//! coarse effect, and a SIMD machine runs the expensive evaluation with the
//! other lanes idle. Here every pixel first resolves its block and appends
//! itself to a workgroup list per coarse effect it refines; then, effect by
//! effect in dependency order, the first lanes of the workgroup evaluate the
//! effect for the listed pixels, densely, and leave the values in workgroup
//! memory; last, every pixel takes each coarse value from there or resamples
//! it, and evaluates its fine effects and outputs as before.
//!
//! An effect evaluated for another pixel is evaluated exactly as that pixel
//! would: at its position, with its dependencies at their rates there (from
//! the workgroup memory where refined, resampled from its block otherwise),
//! by the same `mrsl_eval_<effect>` every kernel shares, and derivatives
//! recompute their neighbours from positions. So forced refinement still
//! equals the reference bit for bit.
//!
//! The lists and values take workgroup memory in proportion to the number
//! of coarse effects; a program whose share would not fit
//! [`MAX_COMPACTION_BYTES`] keeps the uncompacted entry point.

use super::Writer;
use super::effects::Evaluation;
use super::fine::Level;
use super::names::{
    BLOCK, BLOCK_STRUCT, COMPACT_BLOCKS, COMPACT_COUNTS, COMPACT_LISTS, GRID, IN, IS_REFINED, LANE, LAST_BLOCK, LISTED,
    LOAD_CORNERS, Name, POS, TILE_PIXEL, WORKGROUP,
};
use crate::check::EffectId;
use crate::syntax::ast::Rate;
use crate::types::Type;
use mrsl_abi::geometry::PIXEL_WORKGROUP;

/// The workgroup memory the compaction may use: WebGPU guarantees 16,384
/// bytes per workgroup; the rest is left to the statistics counters.
pub(super) const MAX_COMPACTION_BYTES: u32 = 12 * 1024;

/// The bytes one element of an array of `ty` takes in workgroup memory (its
/// array stride in WGSL).
fn stride(ty: &Type) -> u32 {
    match ty {
        Type::Vector(_, 2) => 8,
        Type::Vector(_, _) => 16,
        Type::Matrix(cols) => 16 * u32::from(*cols),
        _ => 4,
    }
}

impl Writer<'_, '_, '_> {
    /// The workgroup memory the compacted entry point needs.
    fn compaction_bytes(&self) -> u32 {
        let coarse = self.coarse_live();
        let k = coarse.len() as u32;
        let block = 16 + 16 + 4 + 4 * k.div_ceil(32);
        let values: u32 = coarse.iter().map(|&e| stride(&self.checked().effects[e.index()].ty)).sum();
        4 * k + 4 * k * PIXEL_WORKGROUP + PIXEL_WORKGROUP * (block.div_ceil(16) * 16 + values)
    }

    /// Whether the fine entry point is compacted: a `Fine` kernel with live
    /// coarse effects whose lists and values fit the workgroup memory.
    pub(super) fn compacts(&self) -> bool {
        self.i.compact
            && self.file == mrsl_abi::KernelKind::Fine
            && !self.coarse_live().is_empty()
            && self.compaction_bytes() <= MAX_COMPACTION_BYTES
    }

    /// `fine_main`, compacted (see the module documentation).
    pub(super) fn compacted_fine_entry(&mut self) {
        let coarse = self.coarse_live();
        let wg = PIXEL_WORKGROUP;
        let k = coarse.len();
        self.line(0, "// Compaction: per coarse effect, the workgroup's pixels that re-evaluate it (local");
        self.line(0, "// indices), each pixel's block, and the values evaluated for them.");
        self.line(0, format!("var<workgroup> {COMPACT_COUNTS}: array<atomic<u32>, {k}>;"));
        self.line(0, format!("var<workgroup> {COMPACT_LISTS}: array<u32, {}>;", k as u32 * wg));
        self.line(0, format!("var<workgroup> {COMPACT_BLOCKS}: array<{BLOCK_STRUCT}, {wg}>;"));
        for &e in &coarse {
            let info = &self.checked().effects[e.index()];
            self.line(
                0,
                format!("var<workgroup> {}: array<{}, {wg}>;", Name::CompactValues.of(&info.name), info.ty.wgsl()),
            );
        }
        self.line(0, "");
        // One pixel per lane, unlike the ordinary fine kernel's pairs.
        self.line(0, format!("@compute @workgroup_size({wg}, 1, 1)"));
        self.line(
            0,
            format!(
                "fn {}(@builtin(workgroup_id) {WORKGROUP}: vec3<u32>, @builtin(local_invocation_index) {LANE}: u32) {{",
                self.kind.main_entry_point()
            ),
        );
        let tile = self.surface_tile(1);
        self.line(1, format!("let {POS} = {TILE_PIXEL}({tile}, {LANE});"));
        self.line(1, format!("let {IN} = all({POS} < {GRID}());"));
        // 1. Resolve, count, and list the pixel for each coarse effect it re-evaluates.
        self.line(1, format!("if ({IN}) {{"));
        self.resolve_preamble(2, "");
        self.line(2, format!("{COMPACT_BLOCKS}[{LANE}] = {BLOCK};"));
        self.statistics_on(2);
        let mask_y = self.mask_y(BLOCK, "0u");
        let mask_x = format!("{BLOCK}.refined0");
        self.template(
            3,
            include_str!("templates/rate.wgsl"),
            &[("LAST", &BLOCK), ("MASK_X", &mask_x), ("FROM_INNER", &mask_y)],
        );
        for j in 0..k {
            self.count_refined(j, &format!("{IS_REFINED}({LAST_BLOCK}, {j}u)"));
        }
        self.count_background(BLOCK);
        self.line(2, "}");
        for &e in &coarse {
            let j = self.coarse_index[&e];
            self.line(
                2,
                format!(
                    "if ({IS_REFINED}({BLOCK}, {j}u)) {{ {COMPACT_LISTS}[{}u + atomicAdd(&{COMPACT_COUNTS}[{j}], 1u)] = {LANE}; }}",
                    j * wg
                ),
            );
        }
        self.line(1, "}");
        self.line(1, "workgroupBarrier();");
        // 2. Each coarse effect, dependencies first, by the first lanes for the listed pixels.
        for &e in &coarse {
            let j = self.coarse_index[&e];
            let name = self.checked().effects[e.index()].name.clone();
            self.line(1, format!("// `{name}` where it is re-evaluated, one lane per listed pixel"));
            self.line(1, format!("if ({LANE} < atomicLoad(&{COMPACT_COUNTS}[{j}])) {{"));
            self.line(2, format!("let {LISTED} = {COMPACT_LISTS}[{}u + {LANE}];", j * wg));
            self.line(2, format!("let {POS} = {TILE_PIXEL}({tile}, {LISTED});"));
            self.line(2, format!("let {BLOCK} = {COMPACT_BLOCKS}[{LISTED}];"));
            for (d, _) in self.checked().effects[e.index()].deps.clone() {
                self.compacted_value(d, 2, LISTED);
            }
            self.evaluate(e, 2, "let ", Evaluation::Kernel);
            self.line(2, format!("{}[{LISTED}] = {};", Name::CompactValues.of(&name), self.effect_name(e)));
            self.line(1, "}");
            self.line(1, "workgroupBarrier();");
        }
        // 3. Per pixel: coarse values from the workgroup or resampled, then the fine effects.
        self.line(1, format!("if ({IN}) {{"));
        self.line(2, format!("let {BLOCK} = {COMPACT_BLOCKS}[{LANE}];"));
        let order = self.i.graph.order.clone();
        for &e in &order {
            if self.checked().effects[e.index()].rate == Rate::Coarse {
                self.compacted_value(e, 2, LANE);
            } else {
                self.evaluate(e, 2, "let ", Evaluation::Kernel);
            }
        }
        self.output_stores(&order, 2);
        self.line(1, "}");
        self.flush_workgroup_stats(PIXEL_WORKGROUP);
        self.line(0, "}");
    }

    /// Coarse effect `e` at the pixel of local index `lane`: from the
    /// workgroup memory where the pixel re-evaluated it, else resampled
    /// (when it is passed; where it is not, the resolve refined it).
    fn compacted_value(&mut self, e: EffectId, indent: usize, lane: &str) {
        let info = &self.checked().effects[e.index()];
        let (j, var) = (self.coarse_index[&e], self.effect_name(e));
        self.line(indent, format!("var {var}: {};", info.ty.wgsl()));
        self.line(indent, format!("if ({IS_REFINED}({BLOCK}, {j}u)) {{"));
        self.line(indent + 1, format!("{var} = {}[{lane}];", Name::CompactValues.of(&info.name)));
        if self.i.interface.is_passed(e) {
            self.line(indent, "} else {");
            // The corners are not kept across the barriers: each position loads its own again.
            let resample = Name::Resample.within(Level::own(self.block).suffix, &info.name);
            self.line(indent + 1, format!("{var} = {resample}({BLOCK}, {LOAD_CORNERS}({POS}));"));
        }
        self.line(indent, "}");
    }
}
