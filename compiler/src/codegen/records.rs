//! Per-pixel records, shared by the hierarchical and checkerboard modes:
//! both shade coarse effects at some pixels into a record per pixel
//! (`mrsl_values`, layout `hierarchical`) and fill the other pixels from
//! neighbours that were shaded (the hierarchical kernel writes each
//! pixel's outputs where it completes its record; the checkerboard kernel
//! in a final per-pixel pass that reads the records). What they share: the
//! record binding and accessors, the neighbour-pair test (neighbours in
//! opposite pairs, only complete pairs used) and the final pass's shape.

use super::Writer;
use super::names::{Name, PUT_MASKS, PUT_RECORD, SET_WORD, VALUES, WORD};
use super::pixel::Scope;
use super::words::{pack_words, unpack_with};
use super::writer::cut;
use crate::check::EffectId;

/// The four neighbours at distance `d` along the axes, in opposite pairs (0, 1) and (2, 3).
pub(super) fn axis_neighbours(d: i32) -> [(i32, i32); 4] {
    [(-d, 0), (d, 0), (0, -d), (0, d)]
}

/// The four neighbours at distance `d` along the diagonals, in opposite pairs (0, 1) and (2, 3).
pub(super) fn diagonal_neighbours(d: i32) -> [(i32, i32); 4] {
    [(-d, -d), (d, d), (d, -d), (-d, d)]
}

/// The neighbours of pixel `p` at `offsets`, as a WGSL `array<vec2<i32>, 4>`.
pub(super) fn neighbours(offsets: [(i32, i32); 4]) -> String {
    let points: Vec<String> = offsets.iter().map(|(x, y)| format!("p + vec2<i32>({x}, {y})")).collect();
    format!("array<vec2<i32>, 4>({})", points.join(", "))
}

/// Word `k` of a packed record held in `record` (a `MrslRecord`): a
/// component of one of its texels.
pub(super) fn record_word(record: &str, k: u32) -> String {
    format!("{record}[{}].{}", k / 4, ["x", "y", "z", "w"][k as usize % 4])
}

impl Writer<'_, '_, '_> {
    /// The record texture, after a comment on what the mode keeps in it: a
    /// texel per word, or with `packed` four words per texel.
    pub(super) fn record_binding(&mut self, what: &str, packed: bool) {
        let l = self.i.layout;
        let format = if packed { "rgba32uint" } else { "r32uint" };
        self.template(
            0,
            include_str!("templates/record_binding.wgsl"),
            &[
                ("WHAT", &what),
                ("GROUP", &l.interface.group),
                ("BINDING", &l.hierarchical.values_binding),
                ("FORMAT", &format),
            ],
        );
    }

    /// The packed records' helpers (the hierarchical kernel's, with
    /// `Options::packed_records`): `mrsl_word`, `MrslRecord` and its loader,
    /// `mrsl_hget_X(record)` for every live coarse effect, and the stores
    /// `mrsl_put_record` and `mrsl_put_masks`. A record is stored whole, a
    /// texel at a time, from the values the invocation holds (`mrsl_pv_*`):
    /// the invocation that classifies or shades a pixel knows all of it.
    pub(super) fn packed_record_helpers(&mut self) {
        let c = self.checked();
        let h = &self.i.layout.hierarchical;
        let texels = h.record_words.div_ceil(4);
        let loads: Vec<String> = (0..texels).map(|t| format!("textureLoad({VALUES}, p, {t})")).collect();
        self.template(
            0,
            include_str!("templates/records_packed.wgsl"),
            &[("TEXELS", &texels), ("LOADS", &loads.join(", "))],
        );
        let mut words: Vec<String> = vec!["0u".into(); (texels * 4) as usize];
        let flags: Vec<String> = (0..h.flag_words).map(|w| format!("f{w}")).collect();
        let masks: Vec<String> = (0..h.mask_words).map(|w| format!("m{w}")).collect();
        for (w, name) in flags.iter().chain(&masks).enumerate() {
            words[w] = name.clone();
        }
        for (k, &e) in self.coarse_live().iter().enumerate() {
            let info = &c.effects[e.index()];
            let offset = h.value_offsets[k];
            let unpack = unpack_with(&info.ty, |j| record_word("r", offset + j));
            let values =
                [("NAME", &info.name as &dyn std::fmt::Display), ("TYPE", &info.ty.wgsl()), ("UNPACK", &unpack)];
            self.template(0, include_str!("templates/record_access_packed.wgsl"), &values);
            for (j, word) in pack_words(&Name::PixelValue.of(&info.name), &info.ty).into_iter().enumerate() {
                words[(offset + j as u32) as usize] = word;
            }
        }
        let params = |names: &[String]| names.iter().map(|n| format!(", {n}: u32")).collect::<String>();
        let all = params(&[flags.clone(), masks.clone()].concat());
        self.line(0, format!("fn {PUT_RECORD}(p: vec2<i32>{all}) {{"));
        for (t, texel) in words.chunks(4).enumerate() {
            self.line(1, format!("textureStore({VALUES}, p, {t}, vec4<u32>({}));", texel.join(", ")));
        }
        self.line(0, "}");
        self.line(0, format!("fn {PUT_MASKS}(p: vec2<i32>{}) {{", params(&masks)));
        let mask_range = h.flag_words..h.flag_words + h.mask_words;
        for t in mask_range.start / 4..mask_range.end.div_ceil(4) {
            let texel: Vec<String> = (t * 4..t * 4 + 4)
                .map(|w| if mask_range.contains(&w) { masks[(w - h.flag_words) as usize].clone() } else { "0u".into() })
                .collect();
            self.line(1, format!("textureStore({VALUES}, p, {t}, vec4<u32>({}));", texel.join(", ")));
        }
        self.line(0, "}");
        self.line(0, "");
    }

    /// `mrsl_word` / `mrsl_set_word`, and `mrsl_hget_X` / `mrsl_hput_X` for every live coarse effect.
    pub(super) fn record_helpers(&mut self) {
        let c = self.checked();
        let h = &self.i.layout.hierarchical;
        self.template(0, include_str!("templates/records.wgsl"), &[]);
        let [access, end] = cut(include_str!("templates/record_access.wgsl"), &["STORES"]);
        for (k, &e) in self.coarse_live().iter().enumerate() {
            let info = &c.effects[e.index()];
            let offset = h.value_offsets[k];
            let unpack = unpack_with(&info.ty, |j| format!("{WORD}(p, {}u)", offset + j));
            let values =
                [("NAME", &info.name as &dyn std::fmt::Display), ("TYPE", &info.ty.wgsl()), ("UNPACK", &unpack)];
            self.template(0, access, &values);
            for (j, word) in pack_words("v", &info.ty).iter().enumerate() {
                self.line(1, format!("{SET_WORD}(p, {}u, {word});", offset + j as u32));
            }
            self.template(0, end, &[]);
        }
        self.line(0, "");
    }

    /// The neighbour-pair test both record modes decide with, over
    /// `ok: array<bool, 4>` and the neighbours `{points}[k]` in opposite pairs
    /// (0, 1) and (2, 3): `ok[k]` is whether neighbour k lies inside the
    /// image (and passes the `tap_tests` lines, written inside the loop);
    /// then `note` (a template section); then `let {pairs[0]}` and
    /// `let {pairs[1]}` say whether each pair is complete. Only complete
    /// pairs are used, so that a mean stays centred (exact for linear values).
    pub(super) fn neighbour_pairs(&mut self, points: &str, tap_tests: &[String], note: &str, pairs: [&str; 2]) {
        let [head, tests, tail] = cut(include_str!("templates/neighbour_pairs.wgsl"), &["TAP_TESTS", "NOTE"]);
        let values = [("POINTS", &points as &dyn std::fmt::Display), ("A", &pairs[0]), ("B", &pairs[1])];
        self.template(0, head, &values);
        for test in tap_tests {
            self.line(2, test);
        }
        self.template(0, tests, &values);
        self.template(0, note, &[]);
        self.template(0, tail, &values);
    }

    /// The final pass of a record mode (the checkerboard's): one lane per pixel of a tile in row
    /// order, `prologue`, then coarse effects as `coarse` writes them and
    /// the others evaluated, then the outputs (see [`Writer::pixel_main`]).
    pub(super) fn record_final(
        &mut self,
        prologue: impl FnMut(&mut Self, Scope),
        coarse: impl FnMut(&mut Self, EffectId, usize),
    ) {
        self.tile_pixel_rows();
        self.pixel_main(prologue, coarse);
    }
}
