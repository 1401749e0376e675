//! The hierarchical kernel's derivatives from a level's neighbours. At
//! levels 1 to 3, a predicate's derivative of an operand that reads coarse
//! effects (`fwidth_surface(blocker)`) is a central difference over the four
//! neighbours the level interpolates from, whose records are complete when
//! the level is shaded, instead of an evaluation of the effects at the quad
//! partner (docs/language.md, section 9). The helpers that take it
//! (`mrsl_dl<k>`) are written with the other derivative helpers; this module
//! writes what they read: the level being shaded (`mrsl_level`, which the
//! level's shading entry point sets), the level's neighbours and the weights
//! of their differences, and the effects' values in a complete record
//! (`mrsl_stored_<effect>`).

use super::Writer;
use super::hierarchical::classified_neighbours;
use super::names::{LEVEL, LEVEL_NEIGHBOURS, LEVEL_WEIGHTS, LOAD_RECORD, Name, POS};
use super::records::neighbours;
use crate::check::EffectId;
use mrsl_abi::geometry::HIERARCHICAL_LEVELS;
use std::collections::BTreeSet;

/// The levels whose shading evaluates predicates and reads the level's
/// neighbours for their derivatives: 1 to 3, every classified level but the
/// last, which shades values alone (level 0's neighbours are shaded in the
/// same dispatch).
pub(super) const LEVELS_WITH_NEIGHBOUR_DERIVATIVES: std::ops::RangeInclusive<usize> = 1..=HIERARCHICAL_LEVELS.len() - 1;

impl Writer<'_, '_, '_> {
    /// Whether some derivative of the kernel is taken from the levels' neighbours.
    pub(super) fn has_level_derivatives(&self) -> bool {
        !self.level_sites().is_empty()
    }

    /// `mrsl_level`, `mrsl_level_neighbours(p)`, `mrsl_level_weights()` and
    /// `mrsl_stored_<effect>(pos)` for the effects those derivatives read;
    /// nothing where the kernel has no such derivative.
    pub(super) fn level_derivative_helpers(&mut self) {
        let sites = self.level_sites();
        if sites.is_empty() {
            return;
        }
        self.line(0, "// The level whose work list the invocation shades (1 to 3; 0 elsewhere): a predicate's");
        self.line(0, "// derivative of coarse effects is then taken from the level's neighbours.");
        self.line(0, format!("var<private> {LEVEL}: u32;"));
        self.line(0, "");
        self.line(
            0,
            format!("// The four neighbours level `{LEVEL}` interpolates from, in opposite pairs (0, 1) and (2, 3)."),
        );
        self.line(0, format!("fn {LEVEL_NEIGHBOURS}(p: vec2<i32>) -> array<vec2<i32>, 4> {{"));
        self.level_switch(|level| format!("return {};", neighbours(classified_neighbours(level))));
        self.line(0, "}");
        self.line(0, "");
        self.line(0, format!("// The weights that turn the pairs' differences (1 - 0, 2 - 3) at level `{LEVEL}` into"));
        self.line(0, "// differences per pixel: along x (.x, .y) and along y (.z, .w).");
        self.line(0, format!("fn {LEVEL_WEIGHTS}() -> vec4<f32> {{"));
        self.level_switch(|level| {
            let w = pair_weights(classified_neighbours(level));
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
        let last = *LEVELS_WITH_NEIGHBOUR_DERIVATIVES.end();
        for level in LEVELS_WITH_NEIGHBOUR_DERIVATIVES {
            let case = if level == last { "default".to_string() } else { format!("case {level}u") };
            self.line(2, format!("{case}: {{ {} }}", body(level)));
        }
        self.line(1, "}");
    }

    /// `mrsl_stored_<effect>(pos)`: the effect's value in pixel `pos`'s
    /// complete record; zero at a background pixel, whose record holds no
    /// values (the background rule: there every coarse effect reads as zero).
    fn stored_value(&mut self, e: EffectId) {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let ty = info.ty.wgsl();
        let record = if self.packed() { format!("{LOAD_RECORD}({POS})") } else { POS.to_string() };
        self.line(0, format!("// `{}` as a complete record holds it.", info.name));
        self.line(0, format!("fn {}({POS}: vec2<i32>) -> {ty} {{", Name::Stored.of(&info.name)));
        if self.has_background() {
            self.line(1, format!("if ({}) {{ return {ty}(); }}", self.background_here(POS)));
        }
        self.line(1, format!("return {}({record});", Name::RecordGet.of(&info.name)));
        self.line(0, "}");
        self.line(0, "");
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
        for level in LEVELS_WITH_NEIGHBOUR_DERIVATIVES {
            let n = classified_neighbours(level);
            let w = pair_weights(n);
            let (along, across) = (f(n[1]) - f(n[0]), f(n[2]) - f(n[3]));
            assert!((w[0] * along + w[1] * across - gx).abs() < 1e-6, "level {level}: x");
            assert!((w[2] * along + w[3] * across - gy).abs() < 1e-6, "level {level}: y");
        }
    }
}
