//! The rate-image mode's kernels. The coarse kernel has three entry points:
//! `rate_list` lists, per shading-rate tile, the coarse samples the tile's
//! rate needs (its lattice of w x h cells); `rate_args` turns the count into
//! indirect dispatch arguments; `rate_coarse` shades the listed samples, one
//! lane each, and writes their records into a per-pixel interface. The fine
//! kernel resolves every pixel against the corners of its cell, at its
//! tile's rate, with the fine kernels' refinement rules ([`super::fine`]);
//! on a border between tiles of different rates, both sides resample from the
//! samples the coarser side has, so there is no seam: each corner of a cell
//! is a sample or a blend of two border samples, so a resolver reads eight
//! samples' keys and flags where a block's reads four.

use super::Writer;
use super::fine::{CORNER_SAMPLES, LANES, Level, Resolver};
use super::names::Name;
use super::writer::cut;
use crate::layout;
use mrsl_abi::KernelKind;
use mrsl_abi::entry;
use mrsl_abi::geometry::{RATE_ARGS_MAX_X, RATE_LIST_TILES, WORK_LIST_WORKGROUP};

/// The second border sample of each corner of a cell, as `MrslBlock::others` holds them.
const OTHER_SAMPLES: [&str; 4] = ["b.others.x", "b.others.y", "b.others.z", "b.others.w"];

impl Writer<'_, '_, '_> {
    /// The interface, the shading-rate image and, in the coarse kernel, the
    /// sample list, its counter and the indirect arguments.
    pub(super) fn rate_bindings(&mut self) {
        let l = self.i.layout;
        let access = if self.kind == KernelKind::RateCoarse { "read_write" } else { "read" };
        self.template(
            0,
            include_str!("templates/interface.wgsl"),
            &[("GROUP", &l.interface.group), ("BINDING", &l.interface.binding), ("ACCESS", &access)],
        );
        self.template(
            0,
            include_str!("templates/rate_bindings.wgsl"),
            &[("GROUP", &l.shading_rate.group), ("BINDING", &l.shading_rate.binding)],
        );
        if self.kind == KernelKind::RateCoarse {
            let h = &l.hierarchical;
            self.template(
                0,
                include_str!("templates/rate_queues.wgsl"),
                &[
                    ("GROUP", &l.interface.group),
                    ("WORK_BINDING", &h.work_binding),
                    ("QUEUE_BINDING", &h.queue_binding),
                    ("ARGS_GROUP", &h.args_group),
                    ("ARGS_BINDING", &mrsl_abi::BINDING_ARGS),
                    ("COARSE", &entry::RATE_COARSE),
                    ("ARGS", &entry::RATE_ARGS),
                ],
            );
        }
    }

    /// `mrsl_tile_rate` and `mrsl_tile_count`, which both kernels use.
    pub(super) fn rate_tiles(&mut self) {
        self.template(0, include_str!("templates/rate_tiles.wgsl"), &[]);
    }

    /// The coarse kernel's entry points in dispatch order: list, args, shade.
    pub(super) fn rate_coarse_entries(&mut self) {
        self.rate_tiles();
        self.template(
            0,
            include_str!("templates/rate_list.wgsl"),
            &[
                ("TILES", &RATE_LIST_TILES),
                ("LIST", &entry::RATE_LIST),
                ("ARGS", &entry::RATE_ARGS),
                ("COARSE", &entry::RATE_COARSE),
                ("MAX_X", &RATE_ARGS_MAX_X),
                ("WORK_GROUP", &WORK_LIST_WORKGROUP),
                ("WORK_GROUP_LESS_1", &(WORK_LIST_WORKGROUP - 1)),
            ],
        );
        self.coarse_main(include_str!("templates/rate_coarse_main.wgsl"));
    }

    // ---- Fine kernel ------------------------------------------------------------

    /// `MrslBlock` with each corner's two border samples, the resolver and the resamplers.
    pub(super) fn rate_fine_support(&mut self) {
        if self.coarse_live().is_empty() {
            return;
        }
        self.block_struct(include_str!("templates/rate_block_struct.wgsl"), |_| {});
        let level = Level::own(self.block);
        let r = self.resolver(&level, None);
        self.rate_resolve_function(&r);
        let c = self.checked();
        let [head, guard, tail] = cut(include_str!("templates/rate_resample.wgsl"), &["GUARD", "CORNERS"]);
        // A cell's corners are not renormalised across keys' edges: its effects are refined there.
        for s in self.resamplers(&level, &|_, _| "b.weights".to_string()) {
            let values = s.values();
            self.template(0, head, &values);
            if self.has_background() {
                self.line(1, format!("if (b.background) {{ return {}(); }}", s.wgsl_type));
            }
            self.template(0, guard, &values);
            // A corner on a border may blend two border samples.
            let get = Name::Get.within(level.suffix, s.name);
            for (k, lane) in LANES.iter().enumerate() {
                self.line(1, format!("var v{k} = {get}(b.corners.{lane});"));
                if layout::uses_nearest(c, s.effect) {
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
            self.template(0, tail, &values);
        }
    }

    /// `mrsl_resolve` of the rate-image mode (or a neighbour function's):
    /// the pixel's cell at its tile's rate, each corner's border samples,
    /// and the refine decisions over all eight samples. A key is tested
    /// between the pixel and every sample, and between the cell's corners.
    pub(super) fn rate_resolve_function(&mut self, r: &Resolver) {
        let [head, corners, refined] = cut(include_str!("templates/rate_resolve.wgsl"), &["CORNERS", "REFINED"]);
        self.template(0, head, &[("SUFFIX", &r.name)]);
        let samples = CORNER_SAMPLES.len() + OTHER_SAMPLES.len();
        for key in self.keys_of(&r.coarse) {
            let name = key.name;
            let mut tests: Vec<String> =
                (0..samples).map(|s| key.differs(&format!("k_{name}"), &format!("k{s}_{name}"))).collect();
            tests.extend((1..4).map(|s| key.differs(&format!("k0_{name}"), &format!("k{s}_{name}"))));
            self.template(
                0,
                include_str!("templates/rate_resolve_key.wgsl"),
                &[("NAME", &name), ("LOAD", &key.loader()), ("TESTS", &tests.join(" || "))],
            );
        }
        self.corner_flag_words(r);
        if !r.words.is_empty() {
            // The second border samples' flags, read only where a corner blends two.
            let first = CORNER_SAMPLES.len();
            for ci in 0..OTHER_SAMPLES.len() {
                for &w in &r.words {
                    self.line(1, format!("var f{}_{w} = f{ci}_{w};", first + ci));
                }
            }
            self.line(1, "if (blended) {");
            for (ci, sample) in OTHER_SAMPLES.iter().enumerate() {
                for &w in &r.words {
                    let word = r.level.record_word(self.i.interface, sample, w);
                    self.line(2, format!("f{}_{w} = {word};", first + ci));
                }
            }
            self.line(1, "}");
        }
        self.template(0, corners, &[]);
        self.refine_decisions(r, samples, &|w, e| w.discontinuity(e));
        self.background_decision();
        self.template(0, refined, &[]);
    }

    /// `rate_fine`, the entry point: per pixel of a tile in 4x4 blocks. A cell is at
    /// most 4x4 pixels, so 4x4 blocks keep a cell's pixels on neighbouring lanes.
    pub(super) fn rate_fine_entry(&mut self) {
        self.tile_pixel_blocks(4, 1);
        self.tile_list_entries();
        self.fine_main();
    }
}
