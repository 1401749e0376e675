//! The kernels a program compiles to: their names, entry points in dispatch
//! order and workgroup sizes, stated once in [`KernelKind`] and [`entry`].

use crate::geometry::{COARSE_WORKGROUP, FINE_WORKGROUP, PIXEL_WORKGROUP, TILE_LANES, WORK_LIST_WORKGROUP};
use serde::{Deserialize, Serialize};

/// Entry-point names of the generated kernels. The runtime looks pipelines
/// up by these names; the compiler writes them and keeps user names clear of them.
pub mod entry {
    pub const COARSE: &str = "coarse_main";
    /// The block coarse kernel's first entry point: the neighbour values
    /// (`Layout::neighbours`), dispatched over the samples before `coarse_main`.
    pub const COARSE_NEIGHBOURS: &str = "coarse_neighbours";
    pub const FINE: &str = "fine_main";
    pub const REFERENCE: &str = "reference_main";
    pub const DYNAMIC_COARSE: &str = "dynamic_coarse_main";
    pub const DYNAMIC_FINE: &str = "dynamic_fine_main";
    /// The per-pixel passes that write the outputs (but the reference's and
    /// the hierarchical mode's; see
    /// [`KernelKind::has_tile_lists`]), first: list every tile as a
    /// surface tile (a pixel in it is not background) or a background tile
    /// (every pixel is), in the tile lists (`TileLists`, `TileCounts`).
    pub const FINE_TILES: &str = "fine_tiles";
    /// Turn the two lists' lengths into indirect dispatch arguments (binds [`crate::GROUP_ARGS`]).
    pub const FINE_TILE_ARGS: &str = "fine_tile_args";
    /// Shade the background tiles (indirect): every coarse effect reads as
    /// zero there, so no coarse sample is read and nothing is refined.
    pub const FINE_BACKGROUND: &str = "fine_background";
    /// Hierarchical, with a background rule: list each 32x32 tile as a
    /// surface tile or a background tile (`geometry::HIERARCHICAL_TILE`).
    pub const HIER_TILES: &str = "hier_tiles";
    /// Hierarchical: turn the tile lists' lengths into the indirect arguments
    /// of every level's dispatch over the surface tiles and of
    /// `hier_background` (binds [`crate::GROUP_ARGS`]).
    pub const HIER_TILE_ARGS: &str = "hier_tile_args";
    /// Hierarchical: the outputs of the background tiles' pixels, whose coarse
    /// effects read as zero (indirect dispatch).
    pub const HIER_BACKGROUND: &str = "hier_background";
    /// Hierarchical, before level 0: the neighbour values (`Layout::neighbours`,
    /// the coarse effects derivatives read elsewhere) at every level-0 pixel,
    /// for level 0's predicates to take their derivatives from (empty, and not
    /// dispatched, without them).
    pub const HIER_LEVEL0_VALUES: &str = "hier_level0_values";
    /// Hierarchical level 0: every 4th pixel, always shaded.
    pub const HIER_LEVEL0: &str = "hier_level0";
    /// Hierarchical levels 1 to 4: classify the level's pixels into its work list.
    pub const HIER_CLASSIFY: [&str; 4] = ["hier_classify_1", "hier_classify_2", "hier_classify_3", "hier_classify_4"];
    /// Hierarchical levels 1 to 4: turn the work-list count into indirect dispatch
    /// arguments (these alone bind [`crate::GROUP_ARGS`]).
    pub const HIER_ARGS: [&str; 4] = ["hier_args_1", "hier_args_2", "hier_args_3", "hier_args_4"];
    /// Hierarchical levels 1 to 4: shade the compacted work list (indirect dispatch).
    pub const HIER_SHADE: [&str; 4] = ["hier_shade_1", "hier_shade_2", "hier_shade_3", "hier_shade_4"];
    /// Checkerboard: shade the coarse effects in half the 2x2 quads.
    pub const CB_SHADE: &str = "cb_shade";
    /// Checkerboard final pass: reconstruct, then fine effects and outputs per pixel.
    pub const CB_FINAL: &str = "cb_final";
    /// Rate-image mode: per shading-rate tile, append the coarse samples its rate needs to the work list.
    pub const RATE_LIST: &str = "rate_list";
    /// Rate-image mode: turn the work-list count into indirect dispatch arguments
    /// (binds [`crate::GROUP_ARGS`]).
    pub const RATE_ARGS: &str = "rate_args";
    /// Rate-image mode: shade the coarse samples of the work list (indirect dispatch).
    pub const RATE_COARSE: &str = "rate_coarse";
    /// Rate-image mode, per pixel: resample at the tile's rate or evaluate, then fine effects and outputs.
    pub const RATE_FINE: &str = "rate_fine";

    /// The block modes' tile kernel: one workgroup shades one screen tile end
    /// to end (its coarse samples, their refinement and its pixels), with the
    /// coarse-to-fine interface in workgroup memory.
    pub const TILE: &str = "tile_main";

    /// Multi-rate mode: the `coarse(4)` effects resolved at every pixel
    /// from the 4x4 samples (resampled or evaluated) and stored for the
    /// 2x2 samples and the pixels to read.
    pub const MULTI_RESOLVE: &str = "multi_resolve_main";

    /// Prefixes of generated entry points; user identifiers with them are renamed.
    pub const RESERVED_PREFIXES: [&str; 3] = ["hier_", "cb_", "rate_"];
}

/// The hierarchical kernel's entry points in dispatch order: the tile lists
/// (empty and not dispatched without a background rule), the neighbour
/// values at level 0's pixels (empty and not dispatched without them), level 0, then per
/// level 1 to 4 classify, args and (indirect) shade, then the background
/// tiles. There is no final pass: each pixel's outputs are written where its
/// record is complete.
const HIERARCHICAL_ENTRY_POINTS: [&str; 17] = [
    entry::HIER_TILES,
    entry::HIER_TILE_ARGS,
    entry::HIER_LEVEL0_VALUES,
    entry::HIER_LEVEL0,
    entry::HIER_CLASSIFY[0],
    entry::HIER_ARGS[0],
    entry::HIER_SHADE[0],
    entry::HIER_CLASSIFY[1],
    entry::HIER_ARGS[1],
    entry::HIER_SHADE[1],
    entry::HIER_CLASSIFY[2],
    entry::HIER_ARGS[2],
    entry::HIER_SHADE[2],
    entry::HIER_CLASSIFY[3],
    entry::HIER_ARGS[3],
    entry::HIER_SHADE[3],
    entry::HIER_BACKGROUND,
];

/// Which kernel: each is one WGSL module with the entry points [`KernelKind::entry_points`] lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// One invocation per coarse sample: coarse effects, refine flags, interface writes.
    Coarse,
    /// One invocation per pixel: resample or re-evaluate coarse effects, then fine effects and outputs.
    Fine,
    /// The block modes (coarse 2x2 and 4x4) in one dispatch: a workgroup per
    /// screen tile evaluates the tile's coarse samples into workgroup memory,
    /// then resamples or refines its pixels from there.
    Tile,
    /// One invocation per pixel: every effect evaluated per pixel.
    Reference,
    /// Dynamic mode, second level: one invocation per 2x2 coarse sample, shading
    /// only samples that a 4x4 block refined by the (4x4) coarse kernel needs.
    DynamicCoarse,
    /// Dynamic mode, per pixel: 4x4 value, else 2x2 value, else evaluated.
    DynamicFine,
    /// Hierarchical (DACS) mode: level 0 and four classified levels shading
    /// compacted work lists; a pixel's outputs are written by the entry
    /// point that completes its record.
    Hierarchical,
    /// Checkerboard baseline: coarse effects shaded in half the 2x2 quads,
    /// reconstructed in the others.
    Checkerboard,
    /// Rate-image mode, coarse part: the samples each shading-rate tile needs
    /// at its rate, listed, then shaded from the compacted list.
    RateCoarse,
    /// Rate-image mode, per pixel: coarse values resampled at the tile's rate
    /// (or evaluated), then fine effects and outputs.
    RateFine,
    /// Multi-rate mode, per block size: the block coarse kernel over the
    /// effects of one level (4x4: the `coarse(4)` ones; 2x2: the others,
    /// reading the `coarse(4)` values [`KernelKind::MultiResolve`] stored).
    MultiCoarse,
    /// Multi-rate mode: the `coarse(4)` effects at every pixel, resampled
    /// from the 4x4 samples or evaluated, stored per pixel.
    MultiResolve,
    /// Multi-rate mode, per pixel: the 2x2 level's effects resampled or
    /// evaluated, the `coarse(4)` ones read as stored, then fine effects and outputs.
    MultiFine,
}

impl KernelKind {
    /// Every kind, in the order the compiler writes them.
    pub const ALL: [KernelKind; 13] = [
        KernelKind::Coarse,
        KernelKind::Fine,
        KernelKind::Tile,
        KernelKind::Reference,
        KernelKind::DynamicCoarse,
        KernelKind::DynamicFine,
        KernelKind::Hierarchical,
        KernelKind::Checkerboard,
        KernelKind::RateCoarse,
        KernelKind::RateFine,
        KernelKind::MultiCoarse,
        KernelKind::MultiResolve,
        KernelKind::MultiFine,
    ];

    /// The name used in file names and messages (`dynamic_coarse`).
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Coarse => "coarse",
            KernelKind::Fine => "fine",
            KernelKind::Tile => "tile",
            KernelKind::Reference => "reference",
            KernelKind::DynamicCoarse => "dynamic_coarse",
            KernelKind::DynamicFine => "dynamic_fine",
            KernelKind::Hierarchical => "hierarchical",
            KernelKind::Checkerboard => "checkerboard",
            KernelKind::RateCoarse => "rate_coarse",
            KernelKind::RateFine => "rate_fine",
            KernelKind::MultiCoarse => "multi_coarse",
            KernelKind::MultiResolve => "multi_resolve",
            KernelKind::MultiFine => "multi_fine",
        }
    }

    /// The kind called `name` (see [`KernelKind::name`]).
    pub fn from_name(name: &str) -> Option<KernelKind> {
        KernelKind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Every entry point of the kernel, in dispatch order.
    pub fn entry_points(self) -> &'static [&'static str] {
        match self {
            KernelKind::Coarse => &[entry::COARSE_NEIGHBOURS, entry::COARSE],
            KernelKind::Fine => &[entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, entry::FINE],
            KernelKind::Reference => &[entry::REFERENCE],
            KernelKind::Tile => &[entry::TILE],
            KernelKind::DynamicCoarse => &[entry::DYNAMIC_COARSE],
            KernelKind::DynamicFine => {
                &[entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, entry::DYNAMIC_FINE]
            }
            KernelKind::Hierarchical => &HIERARCHICAL_ENTRY_POINTS,
            KernelKind::Checkerboard => {
                &[entry::CB_SHADE, entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, entry::CB_FINAL]
            }
            KernelKind::RateCoarse => &[entry::RATE_LIST, entry::RATE_ARGS, entry::RATE_COARSE],
            KernelKind::RateFine => {
                &[entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, entry::RATE_FINE]
            }
            KernelKind::MultiCoarse => &[entry::COARSE],
            KernelKind::MultiResolve => &[entry::MULTI_RESOLVE],
            KernelKind::MultiFine => &[entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND, entry::FINE],
        }
    }

    /// Whether the kernel's per-pixel pass can shade over tile lists (it has
    /// the `fine_tiles`, `fine_tile_args` and `fine_background` entry
    /// points, empty without a background rule): every per-pixel pass that
    /// writes the outputs but the reference's and the hierarchical mode's
    /// (whose final pass measured no faster over them: docs/eval/evaluation.md).
    pub fn has_tile_lists(self) -> bool {
        self.entry_points().contains(&entry::FINE_TILES)
    }

    /// The last entry point dispatched: the one that writes the outputs (in
    /// the hierarchical kernel the last of several that do).
    pub fn main_entry_point(self) -> &'static str {
        let all = self.entry_points();
        all[all.len() - 1]
    }

    /// Whether the kernel runs per coarse sample (else per pixel).
    pub fn is_coarse(self) -> bool {
        matches!(
            self,
            KernelKind::Coarse | KernelKind::DynamicCoarse | KernelKind::RateCoarse | KernelKind::MultiCoarse
        )
    }

    /// Whether the kernel writes the program's outputs.
    pub fn writes_outputs(self) -> bool {
        !self.is_coarse() && self != KernelKind::MultiResolve
    }

    /// Whether the kernel resolves coarse values per pixel from an interface buffer.
    pub fn is_fine(self) -> bool {
        matches!(
            self,
            KernelKind::Fine
                | KernelKind::DynamicFine
                | KernelKind::RateFine
                | KernelKind::MultiResolve
                | KernelKind::MultiFine
        )
    }

    /// Whether the kernel exists once per block size (coarse and fine); the
    /// other kinds exist once per program.
    pub fn per_block_size(self) -> bool {
        matches!(
            self,
            KernelKind::Coarse
                | KernelKind::Fine
                | KernelKind::Tile
                | KernelKind::MultiCoarse
                | KernelKind::MultiResolve
                | KernelKind::MultiFine
        )
    }

    /// Workgroup size of the main entry point. (The compacted fine kernel of
    /// `mrsl::Options::compact` shades one pixel per lane: [`PIXEL_WORKGROUP`].)
    pub fn workgroup_size(self) -> [u32; 3] {
        if matches!(self, KernelKind::Fine | KernelKind::DynamicFine | KernelKind::MultiResolve | KernelKind::MultiFine)
        {
            [FINE_WORKGROUP, 1, 1]
        } else if self == KernelKind::Tile {
            [TILE_LANES, 1, 1]
        } else if matches!(self, KernelKind::RateCoarse | KernelKind::Hierarchical) {
            // Lanes over a work list (the hierarchical kernel's last entry point shades one).
            [WORK_LIST_WORKGROUP, 1, 1]
        } else if self.is_coarse() {
            [COARSE_WORKGROUP, COARSE_WORKGROUP, 1]
        } else {
            [PIXEL_WORKGROUP, 1, 1]
        }
    }
}

impl std::fmt::Display for KernelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
