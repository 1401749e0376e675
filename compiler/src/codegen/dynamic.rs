//! The dynamic mode: the ordinary coarse kernel at the outer block size,
//! then `dynamic_coarse_main` over the inner block size's samples, shading
//! only those near an outer block that refined (and tagging their records
//! with the frame, so stale ones are recognised), then `dynamic_fine_main`,
//! which takes a coarse value from the outer level, else from the inner
//! level, else evaluates it per pixel. This module holds what the block
//! kernels ([`super::block`]) add for it.

use super::Writer;
use super::block::{corners_differ, sample_grid};
use super::effects::Evaluation;
use super::fine::Level;
use super::names::{BLOCK, CONTROL, CORNERS, INNER_BLOCK, INTERFACE, INTERFACE2, IS_REFINED, Name, PARENT};
use super::writer::cut;
use crate::check::EffectId;
use mrsl_abi::geometry::{DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK};

impl Level {
    /// The outer level: the ordinary coarse kernel's records.
    pub(super) const DYNAMIC_OUTER: Level =
        Level { suffix: "", block: DYNAMIC_OUTER_BLOCK, buffer: INTERFACE, parent: false };
    /// The inner level: `dynamic_coarse_main`'s tagged records.
    pub(super) const DYNAMIC_INNER: Level =
        Level { suffix: "2", block: DYNAMIC_INNER_BLOCK, buffer: INTERFACE2, parent: true };
}

impl Writer<'_, '_, '_> {
    /// `dynamic_coarse_main` reads the outer level, writes the inner one and
    /// counts the samples it shades.
    pub(super) fn dynamic_coarse_bindings(&mut self) {
        let l = self.i.layout;
        self.template(
            0,
            include_str!("templates/dynamic_bindings.wgsl"),
            &[
                ("PARENT_GROUP", &l.interface.group),
                ("PARENT_BINDING", &l.interface.binding),
                ("GROUP", &l.interface2.group),
                ("BINDING", &l.interface2.binding),
            ],
        );
        // The count of shaded samples (the last counter).
        self.stats_buffer();
    }

    /// `dynamic_fine_main` also reads the inner level.
    pub(super) fn inner_interface_binding(&mut self) {
        let l = self.i.layout;
        self.template(
            0,
            include_str!("templates/interface2.wgsl"),
            &[("GROUP", &l.interface2.group), ("BINDING", &l.interface2.binding)],
        );
    }

    /// `mrsl_parent_refined(p)`: whether any outer block holding a pixel of
    /// the inner blocks around the sample at pixel `p` was refined (flags,
    /// key disagreement, force).
    pub(super) fn parent_refined(&mut self) {
        let iface = self.i.interface;
        let block = DYNAMIC_OUTER_BLOCK;
        let [head, flags, keys] = cut(include_str!("templates/parent_refined.wgsl"), &["FLAGS", "KEYS"]);
        self.template(0, head, &[("GRID", &sample_grid(block)), ("BLOCK", &block)]);
        for layer in 0..iface.flag_words.div_ceil(4) {
            self.line(3, format!("let t{layer} = textureLoad({PARENT}, corners[j], {layer}, 0);"));
        }
        for w in 0..iface.flag_words {
            let lane = ["x", "y", "z", "w"][(w % 4) as usize];
            self.line(3, format!("refined = refined || t{}.{lane} != 0u;", w / 4));
        }
        self.template(0, flags, &[]);
        // Conservative: the inner samples are needed where any coarse effect
        // may be refined at the outer level, so every key a coarse effect reads.
        for key in self.keys_of(&self.coarse_live()) {
            self.template(
                0,
                include_str!("templates/parent_key.wgsl"),
                &[
                    ("NAME", &key.name),
                    ("LOAD", &key.loader()),
                    ("BLOCK", &block),
                    ("TESTS", &corners_differ(&key, "").join(" || ")),
                ],
            );
        }
        self.template(0, keys, &[]);
    }

    /// The start of `dynamic_coarse_main` after the sample's position: return
    /// unless a parent block refined; count the sample and tag its record fresh.
    pub(super) fn dynamic_coarse_gate(&mut self) {
        self.template(
            0,
            include_str!("templates/dynamic_gate.wgsl"),
            &[
                ("INNER", &DYNAMIC_INNER_BLOCK),
                ("OUTER", &DYNAMIC_OUTER_BLOCK),
                // The counter after the per-effect ones (layout `stats.counters`).
                ("SAMPLES", &self.coarse_live().len()),
                ("STATISTICS_ON", &super::pixel::statistics_enabled()),
            ],
        );
    }

    /// `mrsl_any_refined(b)`: whether a pixel refined anything at the outer
    /// level, and so needs the inner one.
    pub(super) fn any_refined(&mut self, mask_words: u32) {
        let words: Vec<String> = (0..mask_words).map(|w| format!("b.refined{w}")).collect();
        self.template(0, include_str!("templates/any_refined.wgsl"), &[("WORDS", &words.join(" | "))]);
    }

    /// The comment before the inner level's resolver.
    pub(super) fn inner_level_note(&mut self, block: u32) {
        self.template(0, include_str!("templates/inner_level_note.wgsl"), &[("BLOCK", &block)]);
    }

    /// In the inner level's resolver: a corner whose record is not tagged
    /// with this frame was skipped by `dynamic_coarse_main`, so it is stale.
    pub(super) fn stale_corners(&mut self, buffer: &str, stride: u32) {
        let tags: Vec<String> = ["x", "y", "z", "w"]
            .iter()
            .map(|corner| format!("{buffer}[b.corners.{corner} * {stride}u + {}u] != {CONTROL}.frame + 1u", stride - 1))
            .collect();
        self.line(1, format!("disc = disc || {};", tags.join(" || ")));
    }

    /// After `outer` (`mrsl_b`, the 4x4 level at `pos`): `inner` (`mrsl_b2`),
    /// the inner level, resolved only where the outer one refined. `name` is
    /// the suffix of a neighbour function's own resolver, or empty.
    pub(super) fn resolve_inner(&mut self, indent: usize, name: &str, [pos, outer, inner]: [&str; 3]) {
        self.template(
            indent,
            include_str!("templates/resolve_inner.wgsl"),
            &[
                ("LEVEL", &Level::DYNAMIC_INNER.suffix),
                ("NAME", &name),
                ("POS", &pos),
                ("OUTER", &outer),
                ("INNER", &inner),
            ],
        );
    }

    /// A coarse effect in `dynamic_fine_main`, into its declared variable:
    /// resampled from the outer level unless refined there, else from the
    /// inner level unless refined there, else evaluated.
    pub(super) fn dynamic_coarse_value(&mut self, e: EffectId, indent: usize, how: Evaluation) {
        let info = &self.checked().effects[e.index()];
        let (index, name) = (self.coarse_index[&e], self.effect_name(e));
        if self.i.interface.is_passed(e) {
            let outer = Name::Resample.within(Level::DYNAMIC_OUTER.suffix, &info.name);
            let inner = Name::Resample.within(Level::DYNAMIC_INNER.suffix, &info.name);
            self.line(indent, format!("if (!{IS_REFINED}({BLOCK}, {index}u)) {{"));
            self.line(indent + 1, format!("{name} = {outer}({BLOCK}, {CORNERS});"));
            self.line(indent, format!("}} else if (!{IS_REFINED}({INNER_BLOCK}, {index}u)) {{"));
            self.line(indent + 1, format!("{name} = {inner}({INNER_BLOCK});"));
            self.line(indent, "} else {");
        } else {
            self.line(indent, format!("if ({IS_REFINED}({INNER_BLOCK}, {index}u)) {{"));
        }
        self.evaluate(e, indent + 1, "", how);
        self.line(indent, "}");
    }
}
