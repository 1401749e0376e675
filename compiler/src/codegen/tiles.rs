//! The tile lists of the per-pixel passes that write the outputs (every
//! mode's but the reference's and the hierarchical mode's), where the
//! program has a background rule: `fine_tiles` sorts the image's
//! tiles into surface tiles (some pixel is not background) and background
//! tiles, `fine_tile_args` turns the two lists' lengths into indirect
//! arguments, `fine_background` shades the background tiles and the main
//! entry point the surface tiles (the plan dispatches them in that order).
//!
//! Why lists and not a branch: on llvmpipe a lane runs every instruction of
//! the kernel whatever its branches say, even one its whole workgroup
//! agrees on, so a sky pixel in the full fine kernel still pays its corners,
//! its resolve and the refinement loops' masked first iterations. Left out
//! of that dispatch, it pays only what the background entry point does: the
//! fine effects, with every coarse effect read as zero, and the outputs.
//! Without a background rule the entry points are empty and not dispatched.

use super::Writer;
use super::effects::Evaluation;
use super::names::{GRID, LANE, LISTED_TILE, POS, REFINE_MASK, TILE_ORIGIN, WORKGROUP, WORKGROUP_STATS};
use super::pixel::statistics_enabled;
use crate::syntax::ast::Rate;
use mrsl_abi::geometry::{
    BACKGROUND_TILE_LIST, FINE_PIXELS_PER_LANE, FINE_WORKGROUP, QUEUE_WORDS_PER_LEVEL, SURFACE_TILE_LIST, TILE,
    TILE_LISTS,
};
use mrsl_abi::{BACKGROUND_MARK, BINDING_ARGS, GROUP_ARGS, GROUP_STAGE, entry};

impl Writer<'_, '_, '_> {
    /// Whether the kernel shades over tile lists: the per-pixel passes that
    /// have them ([`mrsl_abi::KernelKind::has_tile_lists`]), in a program with a
    /// background rule.
    pub(super) fn lists_tiles(&self) -> bool {
        self.file.has_tile_lists() && self.has_background()
    }

    /// The first lines of the main entry point: with tile lists, the surface
    /// tile its workgroup shades (the workgroup returns past the list's end).
    /// Returns the tile's expression for `mrsl_tile_pixel`.
    pub(super) fn surface_tile(&mut self, indent: usize) -> String {
        if !self.lists_tiles() {
            return format!("{WORKGROUP}.xy");
        }
        self.listed_tile(indent, SURFACE_TILE_LIST);
        TILE_ORIGIN.to_string()
    }

    fn listed_tile(&mut self, indent: usize, list: u32) {
        self.line(indent, format!("let {TILE_ORIGIN} = {LISTED_TILE}({WORKGROUP}.xy, {LANE}, {list}u);"));
        self.line(indent, format!("if ({TILE_ORIGIN}.x == 0xffffu) {{ return; }}"));
    }

    /// The tile lists' bindings and helpers and the entry points before the
    /// main one: `fine_tiles`, `fine_tile_args` and `fine_background`
    /// (nothing in a kernel without them, such as the reference's).
    pub(super) fn tile_list_entries(&mut self) {
        if !self.file.has_tile_lists() {
            return;
        }
        if !self.lists_tiles() {
            self.line(0, "// No background rule: the plan shades every tile with the main entry point and");
            self.line(0, "// dispatches none of these.");
            for name in [entry::FINE_TILES, entry::FINE_TILE_ARGS, entry::FINE_BACKGROUND] {
                self.line(0, "@compute @workgroup_size(1, 1, 1)");
                self.line(0, format!("fn {name}() {{}}"));
            }
            self.line(0, "");
            return;
        }
        let h = &self.i.layout.hierarchical;
        self.template(
            0,
            include_str!("templates/tile_lists.wgsl"),
            &[
                ("GROUP", &GROUP_STAGE),
                ("LIST_BINDING", &h.work_binding),
                ("COUNTS_BINDING", &h.queue_binding),
                ("ARGS_GROUP", &GROUP_ARGS),
                ("ARGS_BINDING", &BINDING_ARGS),
                ("TILE", &TILE),
                ("LANES", &FINE_WORKGROUP),
                ("PER_LANE", &FINE_PIXELS_PER_LANE),
                ("TILES_ENTRY", &entry::FINE_TILES),
                ("ARGS_ENTRY", &entry::FINE_TILE_ARGS),
                ("LISTS", &TILE_LISTS),
                ("ARG_WORDS", &QUEUE_WORDS_PER_LEVEL),
            ],
        );
        self.background_entry();
    }

    /// `fine_background`: a background tile's pixels, row by row, each with
    /// its coarse effects as zero (the background rule) and its fine
    /// effects evaluated as the main entry point evaluates them, so that
    /// its image is the same; the refine mask marks it background.
    fn background_entry(&mut self) {
        self.line(0, format!("@compute @workgroup_size({FINE_WORKGROUP}, 1, 1)"));
        self.line(
            0,
            format!(
                "fn {}(@builtin(workgroup_id) {WORKGROUP}: vec3<u32>, @builtin(local_invocation_index) {LANE}: u32) {{",
                entry::FINE_BACKGROUND
            ),
        );
        self.listed_tile(1, BACKGROUND_TILE_LIST);
        self.background_pixels();
        if self.counts_stats() {
            self.flush_workgroup_stats(FINE_WORKGROUP);
        }
        self.line(0, "}");
        self.line(0, "");
    }

    /// The pixels of background tile `mrsl_tile` for lane `mrsl_li` (of
    /// [`FINE_WORKGROUP`]), each with its coarse effects as zero (the
    /// background rule) and its fine effects evaluated as the main entry
    /// point evaluates them, so that its image is the same; the refine mask
    /// marks it background. The body of `fine_background`, and of the tile
    /// kernel's `mrsl_tile_background`.
    pub(super) fn background_pixels(&mut self) {
        let counted = self.counts_stats();
        let order = self.i.graph.order.clone();
        for k in 0..FINE_PIXELS_PER_LANE {
            let pixel = match k * FINE_WORKGROUP {
                0 => LANE.to_string(),
                offset => format!("({LANE} + {offset}u)"),
            };
            self.line(1, "{");
            self.line(
                2,
                format!(
                    "let {POS} = vec2<i32>({TILE_ORIGIN} * {TILE}u + vec2<u32>({pixel} % {TILE}u, {pixel} / {TILE}u));"
                ),
            );
            self.background_known_at(2, POS);
            self.line(2, format!("if (all({POS} < {GRID}())) {{"));
            if counted {
                let [x, y] = BACKGROUND_MARK;
                let background = self.i.counters.len();
                self.line(3, format!("if ({}) {{", statistics_enabled()));
                self.line(4, format!("textureStore({REFINE_MASK}, {POS}, vec4<u32>({x}u, {y}u, 0u, 1u));"));
                self.line(4, format!("atomicAdd(&{WORKGROUP_STATS}[{background}], 1u);"));
                self.line(3, "}");
            }
            for &e in &order {
                let info = &self.checked().effects[e.index()];
                if info.rate == Rate::Coarse {
                    let ty = info.ty.wgsl();
                    self.line(3, format!("let {}: {ty} = {ty}();", self.effect_name(e)));
                } else {
                    self.evaluate(e, 3, "let ", Evaluation::Kernel);
                }
            }
            self.output_stores(&order, 3);
            self.line(2, "}");
            self.line(1, "}");
        }
    }
}
