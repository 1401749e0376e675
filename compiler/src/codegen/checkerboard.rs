//! The checkerboard kernel, a baseline: `cb_shade` shades the coarse
//! effects in half the 2x2 quads (a checkerboard of quads; all of them when
//! refinement is forced) into the per-pixel records, and `cb_final`
//! reconstructs the other quads' pixels from the same pixel of the
//! edge-adjacent quads (rejecting taps across a discontinuity key, using only
//! complete opposite pairs), shading in place where no pair is usable, then
//! evaluates the fine effects and outputs.

use super::Writer;
use super::effects::Evaluation;
use super::names::{ALONE, BACKGROUND_HERE, Name, POS, SHADED, WORKGROUP_STATS};
use super::records::{axis_neighbours, neighbours};
use super::writer::cut;
use crate::check::EffectId;
use crate::types::{Scalar, Type};
use mrsl_abi::entry;
use mrsl_abi::geometry::CHECKERBOARD_QUADS_PER_WORKGROUP;
use std::fmt::Display;

/// Lanes of a 2x2 quad.
const QUAD_LANES: u32 = 4;

impl Writer<'_, '_, '_> {
    pub(super) fn checkerboard_bindings(&mut self) {
        self.record_binding(
            "Checkerboard mode: per pixel records of the coarse effects' values (layout `hierarchical`).",
            false,
        );
    }

    pub(super) fn checkerboard_entries(&mut self) {
        let coarse = self.coarse_live();
        // The same pixel of the edge-adjacent quads.
        let taps = neighbours(axis_neighbours(2));
        self.record_helpers();
        self.checkerboard_shade_entry(&coarse);
        self.checkerboard_taps(&coarse, &taps);
        self.checkerboard_reconstruction(&coarse, &taps);
        self.tile_list_entries();
        self.checkerboard_final_entry(coarse.len());
    }

    /// `cb_shade`: this frame's quads evaluate every coarse effect and store it in their records.
    fn checkerboard_shade_entry(&mut self, coarse: &[EffectId]) {
        let c = self.checked();
        let [head, end] = cut(include_str!("templates/checkerboard_shade.wgsl"), &["EFFECTS"]);
        self.template(
            0,
            head,
            &[
                ("QUADS", &CHECKERBOARD_QUADS_PER_WORKGROUP),
                ("WORKGROUP", &(CHECKERBOARD_QUADS_PER_WORKGROUP * QUAD_LANES)),
                ("ENTRY", &entry::CB_SHADE),
            ],
        );
        for &e in coarse {
            self.effect_chain(&[e], 1, Evaluation::Kernel);
            let info = &c.effects[e.index()];
            self.line(1, format!("{}({POS}, {});", Name::RecordPut.of(&info.name), self.effect_name(e)));
        }
        self.template(0, end, &[]);
    }

    /// The neighbouring quads' taps a pixel reconstructs from, and which lie
    /// on its side of every key a coarse effect reads.
    fn checkerboard_taps(&mut self, coarse: &[EffectId], taps: &str) {
        let [head, note, end] = cut(include_str!("templates/taps.wgsl"), &["IN_IMAGE", "PAIRS"]);
        self.template(0, head, &[("TAPS", &taps)]);
        // The taps serve every coarse effect together, so a tap is rejected
        // across any key a coarse effect reads (this baseline does not
        // reconstruct per effect).
        let tap_tests: Vec<String> = self
            .keys_of(coarse)
            .iter()
            .map(|key| format!("ok[k] = ok[k] && ({});", key.matches(&key.load("taps[k]"), &key.load("p"))))
            .collect();
        self.neighbour_pairs("taps", &tap_tests, note, ["pair_x", "pair_y"]);
        self.template(0, end, &[]);
    }

    /// Per coarse effect, its value at a pixel from the taps on its side:
    /// blended where the type blends, else the first tap's.
    fn checkerboard_reconstruction(&mut self, coarse: &[EffectId], taps: &str) {
        let c = self.checked();
        let [head, blend, first_tap, end] =
            cut(include_str!("templates/reconstruct.wgsl"), &["BLEND", "FIRST_TAP", "END"]);
        for &e in coarse {
            let info = &c.effects[e.index()];
            let blendable =
                matches!(info.ty, Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _) | Type::Matrix(_));
            let ty = info.ty.wgsl();
            let values: [(&str, &dyn Display); 3] = [("NAME", &info.name), ("TYPE", &ty), ("TAPS", &taps)];
            self.template(0, head, &values);
            self.template(0, if blendable { blend } else { first_tap }, &values);
            self.template(0, end, &values);
        }
        self.line(0, "");
    }

    /// `cb_final`: each pixel's outputs from its record or its
    /// reconstruction, with the statistics (`coarse`: the coarse effects counted).
    fn checkerboard_final_entry(&mut self, coarse: usize) {
        let [head, stats, end] = cut(include_str!("templates/checkerboard_final.wgsl"), &["STATS", "COUNTS"]);
        let [value, evaluated] = cut(include_str!("templates/checkerboard_value.wgsl"), &["EVALUATE"]);
        // The background rule: a background pixel takes zeros and is not counted (but as background).
        let background = self.has_background().then(|| self.background_here(POS));
        let (bg_line, evaluated_test, mask_y, zero) = match &background {
            Some(test) => (
                format!("\n        let {BACKGROUND_HERE} = {test};"),
                format!("!{BACKGROUND_HERE} && ({SHADED} || {ALONE})"),
                format!("select(0u, 0xffffffffu, {BACKGROUND_HERE})"),
                format!("if ({BACKGROUND_HERE}) {{}} else "),
            ),
            None => (String::new(), format!("{SHADED} || {ALONE}"), "0u".into(), String::new()),
        };
        self.record_final(
            |w, _| {
                w.template(0, head, &[("BACKGROUND", &bg_line)]);
                if coarse > 0 {
                    let all = if coarse >= 32 { u32::MAX } else { (1u32 << coarse) - 1 };
                    w.template(
                        0,
                        stats,
                        &[
                            ("ALL", &all),
                            ("STATISTICS_ON", &super::pixel::statistics_enabled()),
                            ("EVALUATED", &evaluated_test),
                            ("MASK_Y", &mask_y),
                        ],
                    );
                    for k in 0..coarse {
                        w.line(4, format!("atomicAdd(&{WORKGROUP_STATS}[{k}], 1u);"));
                    }
                    let count = match &background {
                        Some(_) => format!(
                            "\n            if ({BACKGROUND_HERE}) {{ atomicAdd(&{WORKGROUP_STATS}[{coarse}], 1u); }}"
                        ),
                        None => String::new(),
                    };
                    w.template(0, end, &[("BACKGROUND_COUNT", &count)]);
                }
            },
            |w, e, indent| {
                let info = &w.checked().effects[e.index()];
                let (var, ty) = (w.effect_name(e), info.ty.wgsl());
                let values: [(&str, &dyn Display); 4] =
                    [("VAR", &var), ("TYPE", &ty), ("NAME", &info.name), ("ZERO", &zero)];
                w.template(indent, value, &values);
                w.evaluate(e, indent + 1, "", Evaluation::Kernel);
                w.template(indent, evaluated, &values);
            },
        );
    }
}
