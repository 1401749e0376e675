//! The rate-image mode's kernels. The coarse kernel has three entry points:
//! `rate_list` lists, per shading-rate tile, the coarse samples the tile's
//! rate needs (its lattice of w x h cells); `rate_args` turns the count into
//! indirect dispatch arguments; `rate_coarse` shades the listed samples, one
//! lane each, and writes their records into a per-pixel interface. The fine
//! kernel resolves every pixel against the corners of its cell, at its
//! tile's rate, with the fine kernels' refinement rules ([`super::block`]);
//! on a border between tiles of different rates, both sides resample from the
//! samples the coarser side has, so there is no seam.

use super::Writer;
use mrsl_abi::KernelKind;
use mrsl_abi::entry;
use mrsl_abi::geometry::{RATE_ARGS_MAX_X, RATE_LIST_TILES, WORK_LIST_WORKGROUP};

impl Writer<'_, '_, '_> {
    /// The interface, the shading-rate image and, in the coarse kernel, the
    /// sample list, its counter and the indirect arguments.
    pub(super) fn rate_bindings(&mut self) {
        self.interface_bindings();
        let l = self.i.layout;
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
        self.coarse_entry();
    }
}
