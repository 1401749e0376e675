//! The hierarchical kernel's derivatives from a level's neighbours. At
//! levels 0 to 3, a predicate's derivative of an operand that reads coarse
//! effects (`fwidth_surface(blocker)`) is a central difference over four
//! neighbours whose values are known before the level is shaded, instead of
//! an evaluation of the effects at the quad partner (docs/language.md,
//! section 9): at levels 1 to 3 the four the level interpolates from, whose
//! records are complete; at level 0 its lattice's neighbours along the axes,
//! where `hier_level0_values` stored the effects derivatives read (the
//! layout's neighbour values) before level 0 is shaded. The helpers that
//! take it (`mrsl_dl<k>`) are written with the other derivative helpers;
//! this module writes what they read: the level being shaded (`mrsl_level`,
//! which the level's shading entry point sets), the level's neighbours and
//! the weights of their differences, and the effects' values there
//! (`mrsl_stored_<effect>`).

use super::Writer;
use super::hierarchical::{LEVELS_WITH_PREDICATES, level_neighbours};
use super::names::{LEVEL, LEVEL_NEIGHBOURS, LEVEL_WEIGHTS, LOAD_RECORD, Name, POS};
use super::records::neighbours;
use crate::check::EffectId;
use mrsl_abi::KernelKind;
use mrsl_abi::geometry::HIERARCHICAL_LEVEL0;
use std::collections::BTreeSet;
use std::ops::RangeInclusive;

impl Writer<'_, '_, '_> {
    /// Whether some derivative of the kernel is taken from the levels' neighbours.
    pub(super) fn has_level_derivatives(&self) -> bool {
        !self.level_sites().is_empty()
    }

    /// Whether the hierarchical kernel stores the layout's neighbour values
    /// at level 0's pixels (`hier_level0_values`; see
    /// [`crate::layout::hierarchical_level0_values`]): level 0 then reads its
    /// own instead of evaluating them, and its predicates take their
    /// derivatives from its neighbours'.
    pub(super) fn stores_level0_values(&self) -> bool {
        self.file == KernelKind::Hierarchical && crate::layout::hierarchical_level0_values(self.i.layout)
    }

    /// Whether the shading entry points say which level they shade
    /// (`mrsl_level`): for the level derivatives, or for level 0 to read
    /// the values `hier_level0_values` stored.
    pub(super) fn says_level(&self) -> bool {
        self.has_level_derivatives() || self.stores_level0_values()
    }

    /// The levels whose predicates take their derivatives from the level's
    /// neighbours: 1 to 3, and 0 where its neighbours' values are stored
    /// before it is shaded.
    pub(super) fn levels_with_neighbour_derivatives(&self) -> RangeInclusive<usize> {
        let first = if self.stores_level0_values() { 0 } else { 1 };
        first..=*LEVELS_WITH_PREDICATES.end()
    }

    /// `mrsl_level`, `mrsl_level_neighbours(p)`, `mrsl_level_weights()` and
    /// `mrsl_stored_<effect>(pos)` for the effects those derivatives read;
    /// nothing where the kernel has no such derivative.
    pub(super) fn level_derivative_helpers(&mut self) {
        if self.says_level() {
            self.line(0, "// The level whose work list the invocation shades (1 to 3; 0 elsewhere, and at level 0):");
            self.line(0, "// a predicate's derivative of coarse effects is then taken from the level's neighbours.");
            self.line(0, format!("var<private> {LEVEL}: u32;"));
            self.line(0, "");
        }
        let sites = self.level_sites();
        if sites.is_empty() {
            return;
        }
        self.line(
            0,
            format!("// The four neighbours of a pixel of level `{LEVEL}` in opposite pairs (0, 1) and (2, 3): those"),
        );
        self.line(0, "// it interpolates from, or at level 0 its lattice's neighbours along the axes.");
        self.line(0, format!("fn {LEVEL_NEIGHBOURS}(p: vec2<i32>) -> array<vec2<i32>, 4> {{"));
        self.level_switch(|level| format!("return {};", neighbours(level_neighbours(level))));
        self.line(0, "}");
        self.line(0, "");
        self.line(0, format!("// The weights that turn the pairs' differences (1 - 0, 2 - 3) at level `{LEVEL}` into"));
        self.line(0, "// differences per pixel: along x (.x, .y) and along y (.z, .w).");
        self.line(0, format!("fn {LEVEL_WEIGHTS}() -> vec4<f32> {{"));
        self.level_switch(|level| {
            let w = pair_weights(level_neighbours(level));
            format!("return vec4<f32>({:?}, {:?}, {:?}, {:?});", w[0], w[1], w[2], w[3])
        });
        self.line(0, "}");
        self.line(0, "");
        let read: BTreeSet<EffectId> = sites.iter().flat_map(|&k| self.i.deriv.sites[k].effects.clone()).collect();
        for e in read {
            self.stored_value(e);
        }
    }

    /// A `switch` over `mrsl_level` with a `return` per level (the last as
    /// the default).
    fn level_switch(&mut self, body: impl Fn(usize) -> String) {
        self.line(1, format!("switch {LEVEL} {{"));
        let levels = self.levels_with_neighbour_derivatives();
        let last = *levels.end();
        for level in levels {
            let case = if level == last { "default".to_string() } else { format!("case {level}u") };
            self.line(2, format!("{case}: {{ {} }}", body(level)));
        }
        self.line(1, "}");
    }

    /// `mrsl_stored_<effect>(pos)`: the effect's value in pixel `pos`'s
    /// complete record, or at level 0 as `hier_level0_values` stored it;
    /// zero at a background pixel, whose record holds no values (the
    /// background rule: there every coarse effect reads as zero).
    fn stored_value(&mut self, e: EffectId) {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let ty = info.ty.wgsl();
        let record = if self.packed() { format!("{LOAD_RECORD}({POS})") } else { POS.to_string() };
        self.line(0, format!("// `{}` as a complete record holds it (at level 0, as stored before it).", info.name));
        self.line(0, format!("fn {}({POS}: vec2<i32>) -> {ty} {{", Name::Stored.of(&info.name)));
        if self.has_background() {
            self.line(1, format!("if ({}) {{ return {ty}(); }}", self.background_here(POS)));
        }
        if self.stores_level0_values() {
            self.line(1, format!("if ({LEVEL} == 0u) {{ return {}; }}", self.level0_value(e)));
        }
        self.line(1, format!("return {}({record});", Name::RecordGet.of(&info.name)));
        self.line(0, "}");
        self.line(0, "");
    }

    /// Effect `e` at level-0 pixel `mrsl_pos`, as `hier_level0_values`
    /// stored it (WGSL): its words in the neighbour values' texel of the pixel.
    pub(super) fn level0_value(&self, e: EffectId) -> String {
        self.neighbour_value(e, &format!("{POS} / {}", HIERARCHICAL_LEVEL0.step))
    }
}

/// The weights of a level's pair differences: with `u` the offset of
/// neighbour 1 and `w` that of neighbour 2 (their partners lie opposite),
/// `f(1) - f(0) = 2 u . grad f` and `f(2) - f(3) = 2 w . grad f` for a
/// linear `f`; solving the two for `grad f` gives the x component as
/// `a (f(1) - f(0)) + b (f(2) - f(3))` and the y component likewise:
/// `[a_x, b_x, a_y, b_y]`. Exact for linear values, as the interpolation is.
fn pair_weights(offsets: [(i32, i32); 4]) -> [f32; 4] {
    let (u, w) = (offsets[1], offsets[2]);
    debug_assert!(offsets[0] == (-u.0, -u.1) && offsets[3] == (-w.0, -w.1), "neighbours in opposite pairs");
    let det = 2.0 * (u.0 * w.1 - u.1 * w.0) as f32;
    // `+ 0.0` writes a zero weight as `0.0`, not `-0.0`.
    [w.1 as f32 / det + 0.0, -u.1 as f32 / det + 0.0, -w.0 as f32 / det + 0.0, u.0 as f32 / det + 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights recover a linear function's gradient from its values at
    /// every level's neighbours.
    #[test]
    fn weights_recover_a_gradient() {
        let (gx, gy) = (0.75f32, -2.5f32);
        let f = |(x, y): (i32, i32)| gx * x as f32 + gy * y as f32;
        for level in LEVELS_WITH_PREDICATES {
            let n = level_neighbours(level);
            let w = pair_weights(n);
            let (along, across) = (f(n[1]) - f(n[0]), f(n[2]) - f(n[3]));
            assert!((w[0] * along + w[1] * across - gx).abs() < 1e-6, "level {level}: x");
            assert!((w[2] * along + w[3] * across - gy).abs() < 1e-6, "level {level}: y");
        }
    }
}
