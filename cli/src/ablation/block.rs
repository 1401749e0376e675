//! The block modes' ablation variants: edits of the coarse 2x2 or 4x4 fine
//! kernel, each removing one part of the fine pass.

use super::{Variant, edit_lines, indent};
use mrsl_abi::{CompiledProgram, KernelKind};

/// The statistics atomics, their barrier and the refine-mask store: the
/// blocks a dispatch with `DispatchOptions::statistics` off skips, removed
/// from the text (the full kernel and the other variants run with them).
pub(super) fn no_instrumentation(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        (l.trim_start() == "if (mrsl_ctl.statistics != 0u) {").then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// No coarse effect is evaluated per pixel: every one is resampled (and
/// in the compacted kernel, no pixel is listed for evaluation).
pub(super) fn nothing_refined(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("if (mrsl_is_refined(mrsl_b, ") && t.contains("mrsl_cq[") {
            return Some(String::new());
        }
        if let Some((todo, _)) = t.strip_prefix("var mrsl_todo_").and_then(|r| r.split_once(" = ")) {
            // The block fine kernel's loops over a lane's refined pixels.
            return Some(format!("{}var mrsl_todo_{todo} = 0u;", indent(l)));
        }
        (t.starts_with("if (mrsl_is_refined(mrsl_b, ") && t.ends_with(")) {"))
            .then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// No coarse effect is evaluated per pixel, but the evaluation branches stay
/// in the kernel behind a per-pixel condition only the run time knows to be
/// false (no pixel has a negative position): what a branch that no lane
/// takes still costs where a SIMD machine cannot tell it is untaken.
fn nothing_refined_at_run_time(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if let Some((todo, pixels)) = t.strip_prefix("var mrsl_todo_").and_then(|r| r.split_once(" = ")) {
            let pixels = pixels.strip_suffix(';')?;
            // `mrsl_pos0`, the lane's first pixel: the loop is in the effect's
            // `mrsl_lane_<effect>`, which takes it (and not `mrsl_first`).
            return Some(format!("{}var mrsl_todo_{todo} = ({pixels}) & select(0u, 3u, mrsl_pos0.x < 0);", indent(l)));
        }
        let cond = t.strip_prefix("if (mrsl_is_refined(mrsl_b, ")?.strip_suffix(")) {")?;
        Some(format!("{}if (mrsl_is_refined(mrsl_b, {cond}) && mrsl_pos.x < 0) {{", indent(l)))
    })
}

/// The loops that re-evaluate a lane's refined pixels, deleted whole:
/// what the kernel would cost if a loop no lane enters cost nothing. On
/// llvmpipe it does not: a loop's body runs once with every lane masked
/// off even when its first test breaks, so `nothing_refined` (the loops
/// kept, never entered) still pays each coarse effect's body once.
fn no_refinement_loops(w: &str) -> Option<String> {
    // The indentation of the loop being deleted, once its `loop {` is seen.
    let deleting = std::cell::RefCell::new(None::<String>);
    let after_todo = std::cell::Cell::new(false);
    edit_lines(w, |l| {
        let t = l.trim_start();
        let mut open = deleting.borrow_mut();
        if let Some(at) = open.as_deref() {
            if l == format!("{at}}}") {
                *open = None;
            }
            return Some(String::new());
        }
        if after_todo.replace(t.starts_with("var mrsl_todo_")) && t == "loop {" {
            *open = Some(indent(l).to_string());
            return Some(String::new());
        }
        None
    })
}

/// The key loads and comparisons of the resolve: every corner on each
/// pixel's side of every key (`side_<key>` all true), or
/// in the kernels that refine a whole block at an edge, `disc_<key>` false.
fn no_key_tests(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if let Some(name) = t.strip_prefix("let side_").and_then(|r| r.split(' ').next()) {
            return Some(format!("{}let side_{name} = vec4<bool>(true);", indent(l)));
        }
        let name = t.strip_prefix("let disc_")?.split(' ').next()?;
        Some(format!("{}let disc_{name} = false;", indent(l)))
    })
}

/// The surface keys' test in squared form, without its square root and
/// the two normalisations: `dot(d, n)^2 > t^2 dot(d, d) dot(n, n)` for each
/// normal, the same test up to rounding. What the roots cost.
fn surface_tests_without_roots(w: &str) -> Option<String> {
    replace_surface_edge_body(w, |t| {
        format!(
            "let d = b.p - a.p;\n    let bound = {t} * {t} * dot(d, d);\n    let da = dot(d, a.n);\n    \
             let db = dot(d, b.n);\n    return da * da > bound * dot(a.n, a.n) || db * db > bound * dot(b.n, b.n);"
        )
    })
}

/// The key comparisons without their arithmetic, the loads kept: a surface
/// key's test and a threshold key's distance become exact comparisons of
/// the values loaded. What the tests cost beyond their loads.
fn key_comparisons_without_arithmetic(w: &str) -> Option<String> {
    let surface = replace_surface_edge_body(w, |_| "return any(a.p != b.p) || any(a.n != b.n);".to_string());
    let w = surface.as_deref().unwrap_or(w);
    let threshold = edit_lines(w, |l| {
        let t = l.trim_start();
        if !t.starts_with("let side_") || !t.contains("distance(") {
            return None;
        }
        // `distance(a, b) <= t` of plain names, as `effects.rs` writes it.
        let mut out = String::new();
        let mut rest = l;
        while let Some(at) = rest.find("distance(") {
            out.push_str(&rest[..at]);
            let args = &rest[at + "distance(".len()..];
            let (pair, after) = args.split_once(") <= ")?;
            let (a, b) = pair.split_once(", ")?;
            let end = after.find([',', ')']).unwrap_or(after.len());
            out.push_str(&format!("all({a} == {b})"));
            rest = &after[end..];
        }
        out.push_str(rest);
        Some(out)
    });
    threshold.or(surface)
}

/// Replaces the body of each surface key's edge test (`fn mrsl_surface_edge_`)
/// with `body(threshold)`, the threshold read from its `bound` line.
fn replace_surface_edge_body(w: &str, body: impl Fn(&str) -> String) -> Option<String> {
    let mut out = String::with_capacity(w.len());
    let mut changed = false;
    let mut lines = w.lines();
    while let Some(l) = lines.next() {
        out.push_str(l);
        out.push('\n');
        if !(l.starts_with("fn mrsl_surface_edge_") && l.ends_with("-> bool {")) {
            continue;
        }
        let body_lines: Vec<&str> = lines.by_ref().take_while(|l| *l != "}").collect();
        let bound = body_lines.iter().find_map(|l| l.trim_start().strip_prefix("let bound = "))?;
        let threshold = bound.split(" * ").next()?;
        out.push_str(&format!("    {}\n}}\n", body(threshold)));
        changed = true;
    }
    changed.then_some(out)
}

/// The corners' refine-flag words of the resolve (read as zero).
fn no_flag_reads(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        let (lhs, rhs) = t.strip_prefix("let f")?.split_once(" = ")?;
        // Read from the buffer, or from the lane's preloaded corners (`c.w<word>`).
        let read = rhs.starts_with("mrsl_interface[") || rhs.starts_with("c.w");
        (read && lhs.contains('_')).then(|| format!("{}let f{lhs} = 0u;", indent(l)))
    })
}

/// The resampling of the coarse effects (they read zero): each resampling
/// function of the preloaded corners returns its type's zero value, and
/// elsewhere the calls are dropped.
fn no_resampling(w: &str) -> Option<String> {
    let returned = std::cell::RefCell::new(None::<String>);
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("fn mrsl_resample_") && t.contains("c: MrslCorners") {
            *returned.borrow_mut() = t.rsplit_once("-> ").map(|(_, ty)| ty.trim_end_matches(" {").to_string());
            return None;
        }
        if t.starts_with("return ")
            && let Some(ty) = returned.borrow_mut().take()
        {
            return Some(format!("{}return {ty}();", indent(l)));
        }
        let resamples = t.ends_with("(mrsl_b);") || t.ends_with("(mrsl_b, mrsl_c);");
        (t.contains(" = mrsl_resample_") && resamples && !t.starts_with("let ")).then(String::new)
    })
}

/// Everything the fine pass does per pixel.
pub(super) fn no_fine_work(w: &str) -> Option<String> {
    edit_lines(w, |l| match l.trim_start() {
        // The guard of each pixel (a block fine kernel's lane has several).
        t if t.starts_with("if (all(") && t.ends_with(" < mrsl_grid())) {") => {
            Some(format!("{}if (false && {}", indent(l), &t["if (".len()..]))
        }
        "let mrsl_in = all(mrsl_pos < mrsl_grid());" => Some(format!("{}let mrsl_in = false;", indent(l))),
        // The block fine kernel's pixels (`mrsl_in<k>`): nothing is stored,
        // so nothing is computed.
        t if t.starts_with("let mrsl_in") && t.ends_with(" < mrsl_grid());") => {
            let name = t["let ".len()..].split(' ').next()?;
            Some(format!("{}let {name} = false;", indent(l)))
        }
        _ => None,
    })
}

/// The tile kernel without one of its phases: its call deleted, so that
/// what the phase wrote in workgroup memory stays zero (WGSL zeroes it).
/// `None` for a kernel without the call (the fine kernel).
fn without_call(w: &str, call: &str) -> Option<String> {
    edit_lines(w, |l| {
        let start = l.find(call)?;
        let end = start + l[start..].find(");")? + 2;
        Some(format!("{}{}", &l[..start], &l[end..]))
    })
}

/// The tile kernel's samples not evaluated: its records zero (nothing
/// flagged, every coarse effect resampled as zero).
fn no_tile_samples(w: &str) -> Option<String> {
    without_call(w, "mrsl_c_tile_sample(")
}

/// The tile kernel's neighbour values not evaluated, in every wave (the
/// derivatives at the samples read zero, and so do the neighbour values
/// and the flags the samples read back).
fn no_tile_neighbours(w: &str) -> Option<String> {
    let waves = (0..).map(|wave| format!("mrsl_c_tile_neighbours{wave}(")).take_while(|call| w.contains(call));
    waves.fold(None, |edited: Option<String>, call| without_call(edited.as_deref().unwrap_or(w), &call).or(edited))
}

/// The tile kernel's pixels not shaded (left: its coarse phases and the launch).
fn no_tile_pixels(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("mrsl_tile_pixels(") {
            return Some(String::new());
        }
        // The last group's guarded call.
        t.starts_with("if (mrsl_group_tile < ").then(String::new)
    })
}

/// Every pixel as the background rule leaves it: no corners loaded, no
/// resolve, every coarse effect reading zero, the fine effects still
/// evaluated and stored: what a pixel of a tile known to be wholly
/// background would cost a kernel dispatched over such tiles alone.
/// `None` for a program without a background rule (its blocks have no
/// `background` field).
fn as_background(w: &str) -> Option<String> {
    if !w.contains("    background: bool,") {
        return None;
    }
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("let mrsl_c = mrsl_corners(") {
            return Some(format!("{}var mrsl_c: MrslCorners;", indent(l)));
        }
        let (pixel, _) = t.strip_prefix("let mrsl_b")?.split_once(" = mrsl_resolve(")?;
        Some(format!("{0}var mrsl_b{pixel}: MrslBlock;\n{0}mrsl_b{pixel}.background = true;", indent(l)))
    })
}

/// The background entry points load the background channel at the pixel
/// they shade instead of taking the rule's value (`mrsl_in_background_tile`
/// is never set): the kernels as they were before the value was known.
/// `None` where the kernel does not know it (no background rule, or one
/// whose value is not one bit pattern).
pub(super) fn background_channel_loaded(w: &str) -> Option<String> {
    edit_lines(w, |l| (l.trim_start() == "mrsl_in_background_tile = true;").then(String::new))
}

/// The variants. Removing the key tests or the flag reads from the full
/// kernel would also change what is refined, so those parts are measured
/// within the fixed cost (nothing refined), where they decide nothing.
pub(super) const VARIANTS: [Variant; 18] = [
    Variant {
        name: "no instrumentation",
        removes: "the statistics atomics, their barrier and the refine-mask store (`DispatchOptions::statistics` off)",
        edits: &[no_instrumentation],
    },
    Variant {
        name: "nothing refined (fixed cost)",
        removes: "the per-pixel re-evaluation of refined coarse effects: every pixel resolves and resamples",
        edits: &[nothing_refined],
    },
    Variant {
        name: "nothing refined at run time",
        removes: "the same re-evaluations, but their branches stay, untaken by a per-pixel test: what a SIMD machine runs of a branch no lane takes",
        edits: &[nothing_refined_at_run_time],
    },
    Variant {
        name: "fixed cost, no key tests",
        removes: "also the discontinuity-key loads and comparisons of the resolve",
        edits: &[nothing_refined, no_key_tests],
    },
    Variant {
        name: "fixed cost, no flag reads",
        removes: "also the corners' refine-flag words of the resolve",
        edits: &[nothing_refined, no_flag_reads],
    },
    Variant {
        name: "fixed cost, no resampling",
        removes: "also the resampling of the coarse effects (they read zero)",
        edits: &[nothing_refined, no_resampling],
    },
    Variant {
        name: "every pixel background",
        removes: "the corners, the resolve, the refinement loops and every coarse effect at every pixel (as where nothing was drawn): what a tile known to be wholly background would cost",
        edits: &[as_background, no_refinement_loops],
    },
    Variant {
        name: "fixed cost, no instrumentation",
        removes: "the fixed cost as timed runs pay it: nothing refined, statistics off",
        edits: &[nothing_refined, no_instrumentation],
    },
    Variant {
        name: "fixed cost, no instrumentation, no key tests",
        removes: "the key loads and comparisons from the fixed cost as timed runs pay it (with statistics on, a pixel the keys tear also counts itself with an atomic add, which would be counted as the keys' cost)",
        edits: &[nothing_refined, no_instrumentation, no_key_tests],
    },
    Variant {
        name: "fixed cost, no instrumentation, surface tests without roots",
        removes: "the square root and normalisations of the surface keys' test (the same test squared), statistics off",
        edits: &[nothing_refined, no_instrumentation, surface_tests_without_roots],
    },
    Variant {
        name: "fixed cost, no instrumentation, key comparisons without arithmetic",
        removes: "the arithmetic of the key tests, their loads kept (exact comparisons of the values), statistics off",
        edits: &[nothing_refined, no_instrumentation, key_comparisons_without_arithmetic],
    },
    Variant {
        name: "fixed cost, no refinement loops",
        removes: "the fixed cost, statistics off, without the loops that re-evaluate refined pixels: no lane enters them here, but a SIMD machine may still run their bodies with every lane masked off",
        edits: &[nothing_refined, no_refinement_loops, no_instrumentation],
    },
    Variant {
        name: "every pixel background, no instrumentation",
        removes: "the same as a background pixel costs a timed run: statistics off",
        edits: &[as_background, no_refinement_loops, no_instrumentation],
    },
    Variant {
        name: "background channel loaded (added)",
        removes: "nothing; adds work: the background tiles' pixels load the background channel instead of taking the rule's value, so what the program computes only where something was drawn no longer folds away there (statistics off, as timed runs)",
        edits: &[background_channel_loaded, no_instrumentation],
    },
    Variant {
        name: "no fine pass work",
        removes: "everything the fine pass does per pixel (left: the coarse pass and the launches)",
        edits: &[no_fine_work],
    },
    Variant {
        name: "tile: no samples",
        removes: "the tile kernel's sample phase: its records stay zero, so nothing is flagged and every coarse effect resamples zero (its neighbour values and pixels kept)",
        edits: &[no_tile_samples],
    },
    Variant {
        name: "tile: no neighbour values",
        removes: "the tile kernel's first phase: the values its samples' derivatives read are zero",
        edits: &[no_tile_neighbours],
    },
    Variant {
        name: "tile: no pixels",
        removes: "the tile kernel's pixel phase (left: its coarse phases, barriers and launch)",
        edits: &[no_tile_pixels],
    },
];

/// `program` with the block fine and tile kernels of size `block` refining nothing
/// ([`nothing_refined`]): the block mode's fixed cost, which `bench --suite`
/// reports as its floor. `None` when the kernel has nothing to edit.
pub fn refining_nothing(program: &CompiledProgram, block: u32) -> Option<CompiledProgram> {
    // Both plans' kernels: the fine kernel (CPU devices) and the tile kernel (GPUs).
    let mut edited = program.clone();
    for kind in [KernelKind::Fine, KernelKind::Tile] {
        let wgsl = nothing_refined(&program.kernel(kind, block)?.wgsl)?;
        edited = super::with_kernel(&edited, (kind, Some(block)), &wgsl);
    }
    Some(edited)
}

#[cfg(test)]
mod tests {
    use super::super::apply;
    use super::*;
    use crate::setup::WORKLOAD_PROGRAM;

    /// Every variant edits the kernel the code generator writes for the
    /// workload, so a template change that breaks an edit fails here.
    #[test]
    fn every_variant_edits_the_workload_kernel() {
        let program = mrsl::compile(WORKLOAD_PROGRAM, &mrsl::Options::default()).unwrap();
        for block in [2, 4] {
            let fine = &program.kernel(KernelKind::Fine, block).unwrap().wgsl;
            let tile = &program.kernel(KernelKind::Tile, block).unwrap().wgsl;
            for v in &VARIANTS {
                // The tile kernel's pixels are the fine kernel's code: every variant edits
                // it but the one of the background tiles' entry point, which it has not;
                // the fine kernel has no tile phases.
                let kernels: &[&String] = match v.name {
                    name if name.starts_with("tile: ") => &[tile],
                    "background channel loaded (added)" => &[fine],
                    _ => &[fine, tile],
                };
                for &kernel in kernels {
                    let edited = apply(v, kernel).unwrap_or_else(|| panic!("{}: no line to edit", v.name));
                    assert_ne!(&edited, kernel, "{}", v.name);
                    mrsl::validate_wgsl(&edited).unwrap_or_else(|e| panic!("{} (block {block}): {e}", v.name));
                }
                assert_eq!(v.name.starts_with("tile: "), apply(v, fine).is_none(), "{}", v.name);
            }
            let unlooped = no_refinement_loops(fine).unwrap();
            assert_eq!(unlooped.matches("loop {").count(), 0, "block {block}: a refinement loop is left");
            assert!(fine.matches("loop {").count() >= 3, "the workload refines three coarse effects");
            // The compacted kernel takes the edits that apply to it too.
            let compacted =
                mrsl::compile(WORKLOAD_PROGRAM, &mrsl::Options { compact: true, ..Default::default() }).unwrap();
            let fine = &compacted.kernel(KernelKind::Fine, block).unwrap().wgsl;
            let unlisted = nothing_refined(fine).expect("the compacted kernel lists pixels");
            assert!(!unlisted.contains("atomicAdd(&mrsl_cq_n["), "nothing refined still lists pixels");
            for edit in [nothing_refined, no_fine_work, no_instrumentation] {
                let edited = edit(fine).expect("the compacted kernel has the lines");
                mrsl::validate_wgsl(&edited).unwrap();
            }
        }
    }

    /// Without a background rule (no `@background` input) the background
    /// variants have nothing to edit: they are listed as not applicable, not
    /// made into kernels that do not validate.
    #[test]
    fn the_background_variant_needs_a_background_rule() {
        let source = "in float3 normal;\n\
                      coarse effect float3 light { light = normal * 0.5; }\n\
                      fine out float4 color = float4(light, 1.0);";
        let program = mrsl::compile(source, &mrsl::Options::default()).unwrap();
        let fine = &program.kernel(KernelKind::Fine, 4).unwrap().wgsl;
        assert_eq!(as_background(fine), None);
        assert_eq!(background_channel_loaded(fine), None);
        assert!(nothing_refined(fine).is_some(), "the other variants still apply");
    }
}
