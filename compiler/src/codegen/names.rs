//! Generated names: the one place where the kernels' own identifiers are
//! made, as naga's `proc::Namer` makes a module's. Every name the generator
//! writes starts with `mrsl_`, `Mrsl` or `MRSL_`, a namespace no user name
//! is written in ([`super::body::wgsl_ident`] escapes those into
//! `mrsl_user_<name>`, a [`Name`] family of its own).
//!
//! - A **family** ([`Name`]) is a prefix and what tells its members apart: an
//!   effect's, input's or output's name, a number (a derivative site, a word,
//!   a lane's pixel) or a level's suffix. [`Name::of`] and [`Name::within`]
//!   make a member; templates write the prefix before a placeholder
//!   (`mrsl_load_{{NAME}}`).
//! - A **fixed name** is one identifier: the constants below, for the names
//!   that writers and templates share, and [`FIXED`], which also lists the
//!   names only templates write (their helpers, entry points and locals).
//!
//! The tests below hold both sides to this module: every `mrsl_` identifier
//! in a template is a fixed name or a family's prefix, and no writer outside
//! this module spells one in a string literal. A name renamed here and not
//! in a template (or the reverse) fails them.

use std::collections::BTreeSet;
use std::fmt::Display;

/// A family of generated names: a prefix, then what tells the members apart.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Name {
    /// `mrsl_eval_<effect>`: an effect's function, shared by every kernel.
    Eval,
    /// `mrsl_prefix<k>`: the statements of an effect's body before derivative
    /// site `k`, run at a position, then the site's operand there.
    Prefix,
    /// `mrsl_val_<effect>`: an effect's value alone, without what only decides its refine flag.
    Val,
    /// `mrsl_at_<effect>`: an effect's value at another position (derivatives).
    At,
    /// `mrsl_r_<effect>`: the refine flag an evaluation of the effect sets.
    RefineFlag,
    /// `mrsl_r<k>`: in a resolver, whether coarse effect `k` is evaluated per pixel.
    Refined,
    /// `mrsl_flags<w>`: the refine flag word `w` a coarse sample gathers.
    FlagWord,
    /// `mrsl_w<w>`: word `w` of the block coarse kernel's record, before it is stored.
    RecordWord,
    /// `mrsl_pmask<w>`: mask word `w` of a hierarchical pixel's record, loaded once.
    PixelMask,
    /// `mrsl_qflags<w>`: flag word `w` of a hierarchical pixel's four neighbours, loaded once.
    NeighbourFlags,
    /// `mrsl_resolve<level>` and a neighbour function's `mrsl_resolve<level>_<effect>`.
    Resolve,
    /// `mrsl_resample<level>_<effect>`: a coarse effect resampled at a level.
    Resample,
    /// `mrsl_get<level>_<effect>`: a coarse effect's value in a sample's record at a level.
    Get,
    /// `mrsl_hget_<effect>`: a coarse effect's value in a pixel's record (record modes).
    RecordGet,
    /// `mrsl_hput_<effect>`: a coarse effect's value stored into a pixel's record.
    RecordPut,
    /// `mrsl_pv_<effect>`: the hierarchical kernel's value of a coarse effect at the
    /// invocation's pixel, as it stored it in the record (a private variable).
    PixelValue,
    /// `mrsl_reconstruct_<effect>`: the checkerboard mode's reconstruction of an effect.
    Reconstruct,
    /// `mrsl_cv_<effect>`: the compacted fine pass's values of an effect, per lane.
    CompactValues,
    /// `mrsl_todo_<effect>`: the lane's pixels that re-evaluate a coarse effect.
    Todo,
    /// `mrsl_v<k>_<effect>`: an effect's value at pixel `k` of a fine kernel's lane.
    LaneValue,
    /// `mrsl_pos<k>`: pixel `k` of a fine kernel's lane.
    LanePos,
    /// `mrsl_in<k>`: whether pixel `k` of the lane lies inside the image.
    LaneIn,
    /// `mrsl_b<k>`: the resolved block of pixel `k` of the lane.
    LaneBlock,
    /// `mrsl_inner<k>`: the innermost level pixel `k` of the lane refined to (dynamic mode).
    LaneInner,
    /// `mrsl_load_<input>`: a G-buffer channel at a position's pixel.
    Load,
    /// `mrsl_gb_<channel>`: a G-buffer channel's binding.
    GBuffer,
    /// `mrsl_out_<output>`: an output's binding.
    Out,
    /// `mrsl_d<site>`: the operand of a derivative site at a position.
    Operand,
    /// `mrsl_dr<site>`: the operand of a derivative site at a pixel whose
    /// record is complete, its effects read from the record.
    StoredOperand,
    /// `mrsl_dl<site>`: a derivative site's differences along x and y from a
    /// hierarchical level's neighbours.
    LevelDifferences,
    /// `mrsl_stored_<effect>`: a coarse effect's value in a complete record (zero at a background pixel).
    Stored,
    /// `mrsl_ddx_<site>`: a derivative site's difference along x.
    Ddx,
    /// `mrsl_ddy_<site>`: a derivative site's difference along y.
    Ddy,
    /// `mrsl_select_m<n>`: `select` for `matNxN`.
    SelectMatrix,
    /// `mrsl_user_<name>`: a user name escaped out of the generated namespace.
    User,
    /// `MrslArgs<k>_<effect>`: part `k` of an effect's dependencies, packed
    /// into a structure where they would be too many parameters.
    Args,
    /// `mrsl_args<k>`: the parameter that holds part `k` of the dependencies.
    ArgsParam,
    /// `MrslSurface_<channel>`: a surface key's value, a position and its normal.
    SurfaceStruct,
    /// `mrsl_surface_key_<channel>`: a surface key's value at a position.
    SurfaceKey,
    /// `mrsl_surface_edge_<channel>`: whether two surface key values lie on different surfaces.
    SurfaceEdge,
    /// `mrsl_apart_<effect>`: whether two positions lie across one of an effect's keys.
    Apart,
    /// `mrsl_classify_<effect>`: the hierarchical classification of one coarse effect.
    Classify,
    /// `mrsl_lane_<effect>`: a coarse effect at the pixels of a fine kernel's lane.
    Lane,
}

impl Name {
    /// Every family, for the tests that check names against this module.
    #[cfg_attr(not(test), expect(dead_code, reason = "read by the tests"))]
    pub(super) const ALL: [Name; 43] = [
        Name::Eval,
        Name::Val,
        Name::At,
        Name::RefineFlag,
        Name::Refined,
        Name::FlagWord,
        Name::RecordWord,
        Name::PixelMask,
        Name::NeighbourFlags,
        Name::Resolve,
        Name::Resample,
        Name::Get,
        Name::RecordGet,
        Name::RecordPut,
        Name::PixelValue,
        Name::Reconstruct,
        Name::CompactValues,
        Name::Todo,
        Name::LaneValue,
        Name::LanePos,
        Name::LaneIn,
        Name::LaneBlock,
        Name::LaneInner,
        Name::Load,
        Name::GBuffer,
        Name::Out,
        Name::Operand,
        Name::StoredOperand,
        Name::LevelDifferences,
        Name::Stored,
        Name::Ddx,
        Name::Ddy,
        Name::SelectMatrix,
        Name::User,
        Name::Args,
        Name::ArgsParam,
        Name::SurfaceStruct,
        Name::SurfaceKey,
        Name::SurfaceEdge,
        Name::Apart,
        Name::Classify,
        Name::Prefix,
        Name::Lane,
    ];

    /// What every member's name starts with.
    pub(super) const fn prefix(self) -> &'static str {
        match self {
            Name::Eval => "mrsl_eval_",
            Name::Val => "mrsl_val_",
            Name::At => "mrsl_at_",
            Name::RefineFlag => "mrsl_r_",
            Name::Refined => "mrsl_r",
            Name::FlagWord => "mrsl_flags",
            Name::RecordWord => "mrsl_w",
            Name::PixelMask => "mrsl_pmask",
            Name::NeighbourFlags => "mrsl_qflags",
            Name::Resolve => "mrsl_resolve",
            Name::Resample => "mrsl_resample",
            Name::Get => "mrsl_get",
            Name::RecordGet => "mrsl_hget_",
            Name::RecordPut => "mrsl_hput_",
            Name::PixelValue => "mrsl_pv_",
            Name::Reconstruct => "mrsl_reconstruct_",
            Name::CompactValues => "mrsl_cv_",
            Name::Todo => "mrsl_todo_",
            Name::LaneValue => "mrsl_v",
            Name::LanePos => "mrsl_pos",
            Name::LaneIn => "mrsl_in",
            Name::LaneBlock => "mrsl_b",
            Name::LaneInner => "mrsl_inner",
            Name::Load => "mrsl_load_",
            Name::GBuffer => "mrsl_gb_",
            Name::Out => "mrsl_out_",
            Name::Operand => "mrsl_d",
            Name::StoredOperand => "mrsl_dr",
            Name::LevelDifferences => "mrsl_dl",
            Name::Stored => "mrsl_stored_",
            Name::Ddx => "mrsl_ddx_",
            Name::Ddy => "mrsl_ddy_",
            Name::SelectMatrix => "mrsl_select_m",
            Name::User => "mrsl_user_",
            Name::Args => "MrslArgs",
            Name::ArgsParam => "mrsl_args",
            Name::SurfaceStruct => "MrslSurface_",
            Name::SurfaceKey => "mrsl_surface_key_",
            Name::SurfaceEdge => "mrsl_surface_edge_",
            Name::Apart => "mrsl_apart_",
            Name::Classify => "mrsl_classify_",
            Name::Prefix => "mrsl_prefix",
            Name::Lane => "mrsl_lane_",
        }
    }

    /// The member named by `part`: `<prefix><part>` (`mrsl_eval_shade`, `mrsl_w3`).
    pub(super) fn of(self, part: impl Display) -> String {
        format!("{}{part}", self.prefix())
    }

    /// The member of `group` named by `part`: `<prefix><group>_<part>` (a
    /// level's suffix, a lane's pixel, then an effect: `mrsl_resample2_ao`, `mrsl_v1_ao`).
    pub(super) fn within(self, group: impl Display, part: impl Display) -> String {
        format!("{}{group}_{part}", self.prefix())
    }
}

// ---- Fixed names the writers write ----------------------------------------------

/// The position an invocation or function evaluates at (a coarse sample or a pixel).
pub(super) const POS: &str = "mrsl_pos";
/// `mrsl_background(pos)`: whether nothing was drawn at a position (the background rule).
pub(super) const BACKGROUND: &str = "mrsl_background";
/// In an entry point over background tiles: that the invocation shades
/// one, and the pixel it shades, where the background channel's loader
/// returns the rule's value.
pub(super) const IN_BACKGROUND_TILE: &str = "mrsl_in_background_tile";
pub(super) const BACKGROUND_PIXEL: &str = "mrsl_background_pixel";
/// The first pixel of a fine kernel's lane.
pub(super) const FIRST: &str = "mrsl_first";
/// Whether a compacted fine pass's pixel lies inside the image.
pub(super) const IN: &str = "mrsl_in";
/// `mrsl_grid()`: the positions of the kernel.
pub(super) const GRID: &str = "mrsl_grid";
/// The quad pairs of a position along x and along y (positions.wgsl, rate_positions.wgsl).
pub(super) const PAIR_X: &str = "mrsl_pair_x";
pub(super) const PAIR_Y: &str = "mrsl_pair_y";
/// `mrsl_tile_pixel(wg, li)`: the pixel of a lane of a tile.
pub(super) const TILE_PIXEL: &str = "mrsl_tile_pixel";
/// With tile lists: the tile a fine workgroup shades, and
/// `mrsl_listed_tile(wg, li, list)`, which reads it from a list.
pub(super) const TILE_ORIGIN: &str = "mrsl_tile";
pub(super) const LISTED_TILE: &str = "mrsl_listed_tile";
/// The refine mask (layout `refine_mask`).
pub(super) const REFINE_MASK: &str = "mrsl_refine_mask";
/// The control block (`MrslControl`).
pub(super) const CONTROL: &str = "mrsl_ctl";
/// The user uniforms (`MrslUniforms`).
pub(super) const UNIFORMS: &str = "mrsl_u";
/// `mrsl_octahedral(e)` and `mrsl_rgb9e5(v)`: decodings of packed channels
/// (templates/octahedral.wgsl, templates/rgb9e5.wgsl).
pub(super) const OCTAHEDRAL: &str = "mrsl_octahedral";
pub(super) const RGB9E5: &str = "mrsl_rgb9e5";
/// Whether the runtime forces refinement, in a coarse kernel.
pub(super) const FORCE: &str = "mrsl_force";
/// The refine flag parameter of `mrsl_eval_<effect>`.
pub(super) const REFINE: &str = "mrsl_refine";
/// A coarse invocation's sample (`global_invocation_id`) and the sample grid.
pub(super) const GID: &str = "mrsl_gid";
pub(super) const SAMPLES: &str = "mrsl_n";
/// Where a coarse sample's record starts in an interface buffer.
pub(super) const RECORD: &str = "mrsl_rec";
/// The per-pixel entry points' workgroup and lane (`local_invocation_index`).
pub(super) const WORKGROUP: &str = "mrsl_wg";
pub(super) const LANE: &str = "mrsl_li";
/// The per-workgroup statistics counters.
pub(super) const WORKGROUP_STATS: &str = "mrsl_wg_stats";
/// The statistics counters (layout `stats`).
pub(super) const STATS: &str = "mrsl_stats";
/// The checkerboard final pass: whether the pixel's quad was shaded, whether
/// no tap could reconstruct it, and whether the background rule holds there.
pub(super) const SHADED: &str = "mrsl_shaded";
pub(super) const ALONE: &str = "mrsl_alone";
pub(super) const BACKGROUND_HERE: &str = "mrsl_bg";

/// A pixel's resolved block at a fine kernel's (first) level (`MrslBlock`).
pub(super) const BLOCK: &str = "mrsl_b";
/// A pixel's resolved block at the dynamic mode's inner level.
pub(super) const INNER_BLOCK: &str = "mrsl_b2";
/// The innermost level a pixel resolved, whose refined effects it counts.
pub(super) const LAST_BLOCK: &str = "mrsl_last";
/// The corners of a lane's block (`MrslCorners`), and the function that loads them.
pub(super) const CORNERS: &str = "mrsl_c";
pub(super) const LOAD_CORNERS: &str = "mrsl_corners";
/// `mrsl_is_refined(b, k)`: whether block `b` evaluates coarse effect `k` per pixel.
pub(super) const IS_REFINED: &str = "mrsl_is_refined";
/// In the effect-major fine kernel: the lane's pixel being evaluated.
pub(super) const LANE_PIXEL: &str = "mrsl_k";
/// The records of the coarse samples (one level, or the dynamic mode's inner level).
pub(super) const INTERFACE: &str = "mrsl_interface";
pub(super) const INTERFACE2: &str = "mrsl_interface2";
/// The multi-rate mode's `coarse(4)` values per pixel (layout `levels.values`).
pub(super) const LEVEL_VALUES: &str = "mrsl_level_values";
/// `mrsl_pixel(pos)`: the pixel of a position.
pub(super) const PIXEL: &str = "mrsl_pixel";
/// The records of the dynamic mode's outer level, as its inner coarse kernel reads them.
pub(super) const PARENT: &str = "mrsl_parent";
/// The neighbour values of the block coarse kernel (layout `neighbours`).
pub(super) const NEIGHBOURS: &str = "mrsl_neighbours";

/// The compacted fine pass's lists per coarse effect, their counts, the
/// pixels' blocks, and a listed pixel.
pub(super) const COMPACT_LISTS: &str = "mrsl_cq";
pub(super) const COMPACT_COUNTS: &str = "mrsl_cq_n";
pub(super) const COMPACT_BLOCKS: &str = "mrsl_cb";
pub(super) const LISTED: &str = "mrsl_q";

/// A per-pixel record's word, read and written (record modes).
pub(super) const WORD: &str = "mrsl_word";
pub(super) const SET_WORD: &str = "mrsl_set_word";
/// Packed per-pixel records (four words to a texel): a record's texels
/// (`MrslRecord`), loaded whole (`mrsl_record(p)`) and stored whole
/// (`mrsl_put_record(p, flags.., masks..)`, its values from `mrsl_pv_*`), or
/// only the texels of its mask words (`mrsl_put_masks(p, masks..)`, the
/// other words of those texels zero); the hierarchical pixel's own record
/// and its four neighbours', loaded once.
pub(super) const RECORD_TYPE: &str = "MrslRecord";
/// The record texture of the record modes.
pub(super) const VALUES: &str = "mrsl_values";
pub(super) const LOAD_RECORD: &str = "mrsl_record";
pub(super) const PUT_RECORD: &str = "mrsl_put_record";
pub(super) const PUT_MASKS: &str = "mrsl_put_masks";
pub(super) const PIXEL_RECORD: &str = "mrsl_prec";
pub(super) const NEIGHBOUR_RECORDS: &str = "mrsl_qr";
/// The hierarchical kernel's shading of a pixel: with its refine flags
/// (levels 0 to 3, whose flags the next level's classification reads), and
/// for the values alone at level 4, the last, whose flags nothing reads.
pub(super) const SHADE: &str = "mrsl_shade";
pub(super) const SHADE_LAST: &str = "mrsl_shade_last";
/// The hierarchical level whose work list an invocation shades (1 to 3, else
/// 0: a private variable the level's entry point sets), the four neighbours
/// that level interpolates from (`mrsl_level_neighbours(p)`), and the weights
/// that turn their pairs' differences into differences per pixel
/// (`mrsl_level_weights()`): a predicate's derivative of coarse effects at
/// levels 1 to 3 is taken from those neighbours (`Name::LevelDifferences`).
pub(super) const LEVEL: &str = "mrsl_level";
pub(super) const LEVEL_NEIGHBOURS: &str = "mrsl_level_neighbours";
pub(super) const LEVEL_WEIGHTS: &str = "mrsl_level_weights";
/// A derivative helper's operand at the position itself, which the caller passes.
pub(super) const HERE: &str = "mrsl_here";
/// `mrsl_count(start, step, extent)`: a hierarchical lattice's points along an axis.
pub(super) const COUNT: &str = "mrsl_count";
/// `mrsl_tile_invocation(wg, lid, per, list)`: the lattice invocation of a
/// lane of a dispatch over a hierarchical tile list.
pub(super) const TILE_INVOCATION: &str = "mrsl_tile_invocation";
/// The `local_invocation_id` of the hierarchical entry points over tile lists.
pub(super) const LOCAL_ID: &str = "mrsl_lid";
/// `mrsl_tile_args(word, tiles, per_tile)`: indirect arguments over a hierarchical tile list.
pub(super) const TILE_ARGS: &str = "mrsl_tile_args";

/// The tile kernel ([`super::tile`]): its samples per side and ring (layout
/// `tile`), the slots of its records and neighbour values, the workgroup
/// memory holding them, the tile's first sample (a private variable its
/// entry point sets), where a sample's record and neighbour values sit, its
/// phases (a sample's neighbour values, a sample, a group's pixels) and
/// their parameters.
pub(super) const TILE_SAMPLES: &str = "MRSL_TILE";
pub(super) const TILE_RING: &str = "MRSL_RING";
pub(super) const RECORD_SLOTS: &str = "MRSL_RECORD_SLOTS";
pub(super) const NEIGHBOUR_SLOTS: &str = "MRSL_NEIGHBOUR_SLOTS";
pub(super) const WORKGROUP_RECORDS: &str = "mrsl_wg_records";
pub(super) const WORKGROUP_NEIGHBOURS: &str = "mrsl_wg_neighbours";
pub(super) const ORIGIN: &str = "mrsl_origin";
pub(super) const RECORD_SLOT: &str = "mrsl_record_slot";
pub(super) const NEIGHBOUR_SLOT: &str = "mrsl_neighbour_slot";
pub(super) const TILE_NEIGHBOURS: &str = "mrsl_tile_neighbours";
/// The refine flags the tile kernel keeps beside its neighbour values (the
/// record's flag words, per record slot), and whether a sample is one of
/// the records' (`mrsl_is_record`).
pub(super) const WORKGROUP_NEIGHBOUR_FLAGS: &str = "mrsl_wg_neighbour_flags";
pub(super) const IS_RECORD: &str = "mrsl_is_record";
pub(super) const TILE_SAMPLE: &str = "mrsl_tile_sample";
pub(super) const TILE_PIXELS: &str = "mrsl_tile_pixels";
pub(super) const SLOT: &str = "mrsl_slot";
pub(super) const OWNED: &str = "mrsl_owned";
/// With a background rule: per 8x8 tile of the tile kernel's pixels, whether
/// a pixel of it is not background (`mrsl_wg_surface_tiles`), and the
/// pixels of one that is wholly background (`mrsl_tile_background`).
pub(super) const SURFACE_TILES: &str = "mrsl_wg_surface_tiles";
/// Which of the tile kernel's 8x8 tiles of pixels a group of lanes shades.
pub(super) const GROUP_TILE: &str = "mrsl_group_tile";
pub(super) const TILE_BACKGROUND: &str = "mrsl_tile_background";

/// The tile kernel's neighbour phase in wave `wave` ([`mrsl_abi::NeighbourValue::wave`]).
pub(super) fn tile_neighbours_wave(wave: u32) -> String {
    format!("{TILE_NEIGHBOURS}{wave}")
}

/// The tile kernel's coarse part is the coarse kernel's functions renamed
/// into a namespace of their own ([`coarse_part_name`]): in it a position
/// is a coarse sample, in the rest of the kernel a pixel, and the two sets
/// of helpers (`mrsl_grid`, `mrsl_load_<input>`, `mrsl_eval_<effect>`, ...)
/// live in one module. No other generated name starts with these.
pub(super) const COARSE_PART: &str = "mrsl_c_";
pub(super) const COARSE_PART_TYPE: &str = "MrslC_";

/// A generated name of the coarse kernel as the tile kernel's coarse part
/// names it: `mrsl_grid` is `mrsl_c_grid`, `MrslSurface_p` is `MrslC_Surface_p`.
pub(super) fn coarse_part_name(name: &str) -> String {
    if let Some(rest) = name.strip_prefix("mrsl_") {
        format!("{COARSE_PART}{rest}")
    } else if let Some(rest) = name.strip_prefix("Mrsl") {
        format!("{COARSE_PART_TYPE}{rest}")
    } else {
        panic!("`{name}` is not a generated name")
    }
}

/// `text` with every function and structure it defines renamed into the
/// coarse part's namespace, at its definition and at every use.
pub(super) fn rename_into_coarse_part(text: &str) -> String {
    let defined: BTreeSet<&str> = text
        .lines()
        .filter_map(|line| line.strip_prefix("fn ").or_else(|| line.strip_prefix("struct ")))
        .map(|rest| &rest[..rest.find(|c: char| !is_ident_char(c)).unwrap_or(rest.len())])
        .collect();
    let mut out = String::with_capacity(text.len() + text.len() / 8);
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.push_str(&rest[..start]);
        let word = &rest[start..];
        let len = word.find(|c: char| !is_ident_char(c)).unwrap_or(word.len());
        let ident = &word[..len];
        if defined.contains(ident) {
            out.push_str(&coarse_part_name(ident));
        } else {
            out.push_str(ident);
        }
        rest = &word[len..];
    }
    out.push_str(rest);
    out
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The words of one record, and the coarse kernels' block size.
pub(super) const STRIDE: &str = "MRSL_STRIDE";
pub(super) const BLOCK_SIZE: &str = "MRSL_BLOCK";
/// The structures of a resolved block and of a block's corners.
pub(super) const BLOCK_STRUCT: &str = "MrslBlock";
pub(super) const CORNERS_STRUCT: &str = "MrslCorners";

/// Every fixed name: the constants above, and the names only templates
/// write, by template. A template may use no other `mrsl_` name but a
/// family's prefix.
#[cfg_attr(not(test), expect(dead_code, reason = "read by the tests"))]
pub(super) const FIXED: &[&str] = &[
    POS,
    BACKGROUND,
    IN_BACKGROUND_TILE,
    BACKGROUND_PIXEL,
    FIRST,
    IN,
    GRID,
    TILE_PIXEL,
    TILE_ORIGIN,
    LISTED_TILE,
    REFINE_MASK,
    CONTROL,
    UNIFORMS,
    FORCE,
    REFINE,
    GID,
    SAMPLES,
    RECORD,
    WORKGROUP,
    LANE,
    WORKGROUP_STATS,
    STATS,
    SHADED,
    ALONE,
    BACKGROUND_HERE,
    BLOCK,
    INNER_BLOCK,
    LAST_BLOCK,
    CORNERS,
    LOAD_CORNERS,
    IS_REFINED,
    LANE_PIXEL,
    INTERFACE,
    INTERFACE2,
    LEVEL_VALUES,
    PIXEL,
    PARENT,
    NEIGHBOURS,
    COMPACT_LISTS,
    COMPACT_COUNTS,
    COMPACT_BLOCKS,
    LISTED,
    WORD,
    SET_WORD,
    RECORD_TYPE,
    VALUES,
    LOAD_RECORD,
    PUT_RECORD,
    PUT_MASKS,
    PIXEL_RECORD,
    NEIGHBOUR_RECORDS,
    SHADE,
    SHADE_LAST,
    LEVEL,
    LEVEL_NEIGHBOURS,
    LEVEL_WEIGHTS,
    COUNT,
    TILE_INVOCATION,
    LOCAL_ID,
    TILE_ARGS,
    TILE_SAMPLES,
    TILE_RING,
    RECORD_SLOTS,
    NEIGHBOUR_SLOTS,
    WORKGROUP_RECORDS,
    WORKGROUP_NEIGHBOURS,
    ORIGIN,
    RECORD_SLOT,
    NEIGHBOUR_SLOT,
    TILE_NEIGHBOURS,
    WORKGROUP_NEIGHBOUR_FLAGS,
    IS_RECORD,
    TILE_SAMPLE,
    TILE_PIXELS,
    SLOT,
    OWNED,
    SURFACE_TILES,
    GROUP_TILE,
    TILE_BACKGROUND,
    STRIDE,
    BLOCK_SIZE,
    BLOCK_STRUCT,
    CORNERS_STRUCT,
    OCTAHEDRAL,
    RGB9E5,
    // resources.wgsl, uniforms.wgsl, stats.wgsl, positions.wgsl: bindings and position helpers
    "MrslControl",
    "MrslUniforms",
    PAIR_X,
    PAIR_Y,
    // derivative.wgsl, derivative_both.wgsl: the operand here, at the pair's other position
    HERE,
    "mrsl_there",
    "mrsl_second",
    "mrsl_difference",
    // derivative_levels.wgsl: a level's neighbours, the operand there, the pairs' differences
    "mrsl_near",
    "mrsl_vals",
    "mrsl_inside",
    "mrsl_loaded",
    "mrsl_along",
    "mrsl_across",
    "mrsl_weights",
    // derivative_on_surface.wgsl
    "mrsl_other",
    "mrsl_mirror",
    "mrsl_flip",
    "mrsl_taken",
    // dynamic_gate.wgsl, parent_refined.wgsl, any_refined.wgsl, resolve_inner.wgsl
    "mrsl_parent_refined",
    "mrsl_any_refined",
    // records.wgsl, record_binding.wgsl, hierarchical_*.wgsl, level*.wgsl, shade.wgsl, classify.wgsl
    "mrsl_work",
    "mrsl_queue",
    "mrsl_args",
    "mrsl_work_offset",
    // hierarchical_tiles.wgsl: the tile grid and where the tile list starts
    "mrsl_htile_grid",
    "mrsl_tile_list",
    "mrsl_classify",
    "mrsl_level0",
    "mrsl_finish",
    // tile_lists.wgsl: the lists, their lengths, the workgroup's tile and whether it has surface
    "mrsl_tiles",
    "mrsl_tiles_n",
    "mrsl_tile_grid",
    "mrsl_wg_tile",
    "mrsl_wg_surface",
    // checkerboard_*.wgsl, taps.wgsl
    "mrsl_qx",
    "mrsl_qy",
    "mrsl_shaded_quad",
    "mrsl_taps",
    "mrsl_ok",
    // rate_*.wgsl: the shading-rate image, the tiles, the sample list
    "mrsl_shading_rate",
    "mrsl_tile_rate",
    "mrsl_tile_count",
    "mrsl_rate_corner",
    "mrsl_sample_pixel",
    "mrsl_axis_count",
    "mrsl_axis_at",
    "mrsl_cell",
    "mrsl_cell_of",
    "mrsl_list",
    "mrsl_packed",
];

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;
    use std::path::Path;

    /// Where a generated name starts: `mrsl_`, `Mrsl` before a capital, `MRSL_`.
    fn starts_name(text: &str) -> bool {
        text.starts_with("mrsl_")
            || text.starts_with("MRSL_")
            || text.strip_prefix("Mrsl").is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_uppercase()))
    }

    fn is_ident(c: char) -> bool {
        c.is_ascii_alphanumeric() || c == '_'
    }

    /// The generated names in `text`, each whole (an identifier's run of characters).
    fn names_in(text: &str) -> Vec<&str> {
        let mut names = vec![];
        let mut rest = text;
        while let Some(start) = rest.find(['m', 'M']) {
            let before = text.len() - rest.len() + start;
            let at = &rest[start..];
            let len = at.find(|c: char| !is_ident(c)).unwrap_or(at.len());
            let preceded = text[..before].chars().next_back().is_some_and(is_ident);
            if !preceded && starts_name(at) {
                names.push(&at[..len]);
            }
            rest = &at[len.max(1)..];
        }
        names
    }

    /// The names of `text` that this module does not declare: neither a
    /// fixed name nor a family's prefix (written before a placeholder or a
    /// `<part>` of prose).
    fn undeclared(text: &str) -> BTreeSet<String> {
        let prefixes: BTreeSet<&str> = Name::ALL.iter().map(|n| n.prefix()).collect();
        names_in(text).into_iter().filter(|n| !FIXED.contains(n) && !prefixes.contains(n)).map(String::from).collect()
    }

    fn files(dir: &Path, ext: &str) -> Vec<(String, String)> {
        let mut files: Vec<(String, String)> = std::fs::read_dir(dir)
            .expect("the directory exists")
            .map(|entry| entry.expect("a directory entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == ext))
            .map(|p| {
                let text = std::fs::read_to_string(&p).expect("a readable file");
                (p.file_name().expect("a file name").to_string_lossy().into_owned(), text)
            })
            .collect();
        files.sort();
        files
    }

    fn codegen_dir() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("src/codegen")
    }

    #[test]
    fn templates_use_declared_names() {
        let templates = files(&codegen_dir().join("templates"), "wgsl");
        assert!(templates.len() > 50, "the templates are found");
        let wrong: Vec<String> = templates
            .iter()
            .filter_map(|(file, text)| {
                let names = undeclared(text);
                (!names.is_empty()).then(|| format!("{file}: {}", names.into_iter().collect::<Vec<_>>().join(", ")))
            })
            .collect();
        assert!(wrong.is_empty(), "templates use names codegen/names.rs does not declare:\n{}", wrong.join("\n"));
    }

    /// The string literals of Rust source `text`, outside comments.
    fn string_literals(text: &str) -> Vec<&str> {
        let mut literals = vec![];
        let bytes = text.as_bytes();
        let mut k = 0;
        while k < bytes.len() {
            match bytes[k] {
                b'/' if bytes.get(k + 1) == Some(&b'/') => {
                    k += text[k..].find('\n').unwrap_or(text.len() - k);
                }
                b'\'' if bytes.get(k + 2) == Some(&b'\'') || bytes.get(k + 1) == Some(&b'\\') => {
                    // A character literal, which may be `'"'`.
                    k += text[k + 1..].find('\'').map_or(1, |end| end + 2);
                }
                b'"' => {
                    let start = k + 1;
                    k = start;
                    while k < bytes.len() && bytes[k] != b'"' {
                        k += if bytes[k] == b'\\' { 2 } else { 1 };
                    }
                    literals.push(&text[start..k.min(text.len())]);
                    k += 1;
                }
                _ => k += 1,
            }
        }
        literals
    }

    #[test]
    fn writers_make_names_here() {
        let wrong: Vec<String> = files(&codegen_dir(), "rs")
            .iter()
            .filter(|(file, _)| file != "names.rs")
            .flat_map(|(file, text)| {
                string_literals(text)
                    .into_iter()
                    .flat_map(names_in)
                    .map(move |name| format!("{file}: {name}"))
                    .collect::<Vec<_>>()
            })
            .collect();
        assert!(
            wrong.is_empty(),
            "writers spell generated names; make them in codegen/names.rs:\n{}",
            wrong.join("\n")
        );
    }

    #[test]
    fn names_are_distinct() {
        let fixed: BTreeSet<&str> = FIXED.iter().copied().collect();
        assert_eq!(fixed.len(), FIXED.len(), "a fixed name is declared twice");
        let prefixes: BTreeSet<&str> = Name::ALL.iter().map(|n| n.prefix()).collect();
        assert_eq!(prefixes.len(), Name::ALL.len(), "two families share a prefix");
        assert!(FIXED.iter().chain(&prefixes).all(|n| starts_name(n)), "every name is in the generated namespace");
        // The coarse part's namespace holds no other name.
        let coarse_part = |n: &&str| n.starts_with(COARSE_PART) || n.starts_with(COARSE_PART_TYPE);
        assert!(!FIXED.iter().chain(&prefixes).any(coarse_part), "a name starts like the tile kernel's coarse part");
        assert_eq!(coarse_part_name("MrslSurface_p"), "MrslC_Surface_p");
        assert_eq!(
            names_in("let mrsl_b = mrsl_resolve{{S}}(mrsl_pos); // `Mrsl` mrslc xmrsl_a"),
            ["mrsl_b", "mrsl_resolve", "mrsl_pos"]
        );
        assert_eq!(string_literals("f(\"a\\\"b\", '\"'); // \"c\"\n\"d\""), ["a\\\"b", "d"]);
    }

    #[test]
    fn definitions_are_renamed_where_they_are_used() {
        let text = "fn mrsl_grid() -> i32 { return 1; }\nstruct MrslSurface_p { p: f32 }\n\
                    fn mrsl_eval_a(x: MrslSurface_p) -> i32 { return mrsl_grid() + mrsl_u.k + mrsl_gridx; }\n";
        assert_eq!(
            rename_into_coarse_part(text),
            "fn mrsl_c_grid() -> i32 { return 1; }\nstruct MrslC_Surface_p { p: f32 }\n\
             fn mrsl_c_eval_a(x: MrslC_Surface_p) -> i32 { return mrsl_c_grid() + mrsl_u.k + mrsl_gridx; }\n"
        );
    }
}
