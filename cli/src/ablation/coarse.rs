//! The block modes' coarse-pass variants: edits of the coarse kernel, each
//! timed with the fine pass emptied ([`super::block::no_fine_work`]), so
//! that the frame is the coarse pass and the launches alone and a part of
//! the coarse pass is a large share of it.

use super::block::no_fine_work;
use super::{Edit, apply_edits, edit_lines, indent};

/// The predicates: every `refine;` statement dropped, so that what only
/// decides refinement (the `change` sums, the derivatives and their key
/// tests) is dead code the driver's compiler removes.
fn no_predicates(w: &str) -> Option<String> {
    edit_lines(w, |l| (l.trim_start() == "*mrsl_refine = true; // refine").then(String::new))
}

/// The derivatives' key tests: every difference is taken across the quad
/// pair, as `fwidth` takes it, never flipped to the sample's own surface.
fn no_surface_derivatives(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        l.trim_start().starts_with("let mrsl_flip = ").then(|| format!("{}let mrsl_flip = false;", indent(l)))
    })
}

/// Every coarse effect reads zero: each evaluation returns at its first
/// line, as at a background sample. What is left is the launches, the
/// background test, the flag words and the record stores.
fn no_coarse_effects(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        let ty = t.strip_prefix("if (mrsl_background(mrsl_pos)) { return ")?.strip_suffix("; }")?;
        Some(format!("{}if (true) {{ return {ty}; }}", indent(l)))
    })
}

/// The coarse kernel's entry points' test of their sample against the grid.
const SAMPLE_BOUNDS: &str = "if (mrsl_gid.x >= u32(mrsl_n.x) || mrsl_gid.y >= u32(mrsl_n.y)) { return; }";

/// Nothing at all: each entry point returns at once.
fn launches_only(w: &str) -> Option<String> {
    edit_lines(w, |l| (l.trim_start() == SAMPLE_BOUNDS).then(|| format!("{}if (true) {{ return; }}", indent(l))))
}

/// (Fine kernel.) The tile classification lists no tile, so that the
/// indirect dispatches over the lists launch no workgroup.
fn lists_no_tile(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        (l.trim_start() == "let tile = mrsl_wg.x | (mrsl_wg.y << 16u);")
            .then(|| format!("{l}\n{}if (true) {{ return; }}", indent(l)))
    })
}

/// (Fine kernel.) The tile classification loads no pixel.
fn classifies_nothing(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        (l.trim_start() == "if (all(pos < mrsl_grid()) && !mrsl_background(pos)) { surface = true; }").then(String::new)
    })
}

/// The samples' lanes laid out in 4x2 samples per eight lanes (two such
/// groups side by side, four rows of them: the 8x8 samples of a
/// workgroup) instead of rows of eight: a SIMD group of eight lanes covers
/// 16x8 pixels rather than 32x4, as the reference's lanes cover whole 2x2
/// blocks. What the lanes' layout costs in divergence and locality.
fn lanes_in_4x2_samples(w: &str) -> Option<String> {
    let changed = edit_lines(w, |l| match l.trim_start() {
        "@compute @workgroup_size(8, 8, 1)" => Some("@compute @workgroup_size(64, 1, 1)".to_string()),
        SAMPLE_BOUNDS => {
            let i = indent(l);
            Some(format!(
                "{i}let mrsl_li = mrsl_gid.x % 64u;\n\
                 {i}let mrsl_lane = vec2<u32>((mrsl_li / 8u) % 2u * 4u + mrsl_li % 4u, mrsl_li / 16u * 2u + (mrsl_li % 8u) / 4u);\n\
                 {i}let mrsl_at = vec2<u32>(mrsl_gid.x / 64u, mrsl_gid.y) * 8u + mrsl_lane;\n\
                 {i}if (mrsl_at.x >= u32(mrsl_n.x) || mrsl_at.y >= u32(mrsl_n.y)) {{ return; }}"
            ))
        }
        "let mrsl_pos = vec2<i32>(mrsl_gid.xy);" => Some(format!("{}let mrsl_pos = vec2<i32>(mrsl_at);", indent(l))),
        _ => None,
    })?;
    changed.contains("let mrsl_pos = vec2<i32>(mrsl_at);").then_some(changed)
}

/// A variant of the coarse pass: edits of the coarse kernel, and of the
/// fine kernel after [`no_fine_work`] has emptied it.
pub(super) struct PassVariant {
    pub name: &'static str,
    pub removes: &'static str,
    pub coarse: &'static [Edit],
    pub fine: &'static [Edit],
}

impl PassVariant {
    /// The coarse and fine kernels of the variant, or `None` when one of
    /// its edits has nothing to edit.
    pub fn apply(&self, coarse: &str, fine: &str) -> Option<(String, String)> {
        Some((apply_edits(self.coarse, coarse)?, apply_edits(self.fine, &no_fine_work(fine)?)?))
    }
}

/// The variants; their figures are shares of the full kernel's frame, like
/// the fine pass's, and are read against "no fine pass work" (the coarse
/// pass and the launches as the full program runs them).
pub(super) const VARIANTS: [PassVariant; 7] = [
    PassVariant {
        name: "coarse pass, no predicates",
        removes: "from the coarse pass alone (no fine pass work): the predicates, and with them what only decides refinement (the change sums, the derivatives and their key tests)",
        coarse: &[no_predicates],
        fine: &[],
    },
    PassVariant {
        name: "coarse pass, no surface derivatives",
        removes: "from the coarse pass alone: the key tests of the predicates' derivatives (differences across the quad pair, as `fwidth` takes them)",
        coarse: &[no_surface_derivatives],
        fine: &[],
    },
    PassVariant {
        name: "coarse pass, lanes in 4x2 samples (changed)",
        removes: "nothing; changes the coarse pass alone: eight lanes cover 4x2 samples (16x8 pixels) instead of a row of eight (32x4 pixels)",
        coarse: &[lanes_in_4x2_samples],
        fine: &[],
    },
    PassVariant {
        name: "coarse pass, no coarse effects",
        removes: "from the coarse pass alone: every coarse effect (each reads zero, as at a background sample); left: the launches, the background tests, the flag words and the record stores, and the fine pass's tile lists",
        coarse: &[no_coarse_effects],
        fine: &[],
    },
    PassVariant {
        name: "launches and tile lists",
        removes: "the coarse pass's work too (its entry points return at once); left: the launches, the fine pass's tile classification and its dispatches over the tile lists (empty workgroups)",
        coarse: &[launches_only],
        fine: &[],
    },
    PassVariant {
        name: "launches and tile classification",
        removes: "also the list writes and the workgroups of the dispatches over the tile lists (no tile is listed)",
        coarse: &[launches_only],
        fine: &[lists_no_tile],
    },
    PassVariant {
        name: "launches",
        removes: "also the tile classification's loads: what is left is the launches, the clears and the statistics' readback",
        coarse: &[launches_only],
        fine: &[lists_no_tile, classifies_nothing],
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::WORKLOAD_PROGRAM;
    use mrsl_abi::KernelKind;

    /// Every variant edits the kernels the code generator writes for the
    /// workload, and the results validate.
    #[test]
    fn every_variant_edits_the_workload_kernels() {
        let program = mrsl::compile(WORKLOAD_PROGRAM, &mrsl::Options::default()).unwrap();
        for block in [2, 4] {
            let coarse = &program.kernel(KernelKind::Coarse, block).unwrap().wgsl;
            let fine = &program.kernel(KernelKind::Fine, block).unwrap().wgsl;
            let emptied = no_fine_work(fine).unwrap();
            for v in &VARIANTS {
                let (c, f) = v.apply(coarse, fine).unwrap_or_else(|| panic!("{}: no line to edit", v.name));
                assert!(&c != coarse || f != emptied, "{}: nothing edited", v.name);
                for (kernel, wgsl) in [("coarse", &c), ("fine", &f)] {
                    mrsl::validate_wgsl(wgsl).unwrap_or_else(|e| panic!("{} (block {block}, {kernel}): {e}", v.name));
                }
            }
        }
    }
}
