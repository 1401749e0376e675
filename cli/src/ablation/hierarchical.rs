//! The hierarchical (DACS) mode's ablation variants: edits of the
//! hierarchical kernel, each removing one part of the machinery (level 0,
//! the classification, the work lists and their shading, the outputs).
//!
//! The edits match the lines `compiler/src/codegen/hierarchical.rs` and its
//! templates write: the classification's `if (disc ...) {` per effect, the
//! level entry points' calls of `mrsl_classify` and `mrsl_shade`, the calls
//! of `mrsl_finish` that write a pixel's outputs.

use super::block::{background_channel_loaded, no_instrumentation};
use super::{Variant, edit_lines, indent};
use mrsl_abi::{CompiledProgram, KernelKind};

/// The classification's test per effect (`if (disc || ... ) {`), made false:
/// every pixel of levels 1 to 4 interpolates every effect, nothing is
/// queued, the work-list shading dispatches are empty. The tests' own work
/// goes too (nothing reads their results).
pub(super) fn nothing_shaded(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        (t.starts_with("if (disc") && t.ends_with(") {")).then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// The same tests kept but made false at run time (no image is zero pixels
/// wide): the classification's key, flag and variance tests are paid, and
/// still nothing is queued.
fn nothing_shaded_at_run_time(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        let cond = t.strip_prefix("if (disc")?.strip_suffix(") {")?;
        Some(format!("{}if ((disc{cond}) && mrsl_ctl.size.x == 0u) {{", indent(l)))
    })
}

/// Level 0's shading (its record's mask is still written).
fn no_level0_shading(w: &str) -> Option<String> {
    edit_lines(w, |l| (l.trim_start() == "mrsl_shade(p);").then(String::new))
}

/// The classification of levels 1 to 4, and so their pixels' outputs:
/// their entry points do nothing but the statistics' flush.
fn no_classification(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        t.starts_with("if (mrsl_classify(p, array<vec2<i32>, 4>(").then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// The shading of the work lists (pixels are still queued and counted, and
/// their outputs written).
fn no_work_list_shading(w: &str) -> Option<String> {
    edit_lines(w, |l| matches!(l.trim_start(), "mrsl_shade(listed);" | "mrsl_shade_last(listed);").then(String::new))
}

/// The pixels' outputs: no call of `mrsl_finish` (their fine effects,
/// outputs, refine mask and counts), wherever a pixel's record is completed.
fn no_outputs(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        (t.starts_with("mrsl_finish(") && t.ends_with(");")).then(String::new)
    })
}

/// The shading function's test of the pixel's mask, per effect
/// (`if ((mrsl_pmaskW & M) != 0u) {`), made true: a listed pixel
/// evaluates every coarse effect, whichever its classification named.
fn every_effect_listed(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        (t.starts_with("if ((mrsl_pmask") && t.ends_with(") != 0u) {")).then(|| format!("{}if (true) {{", indent(l)))
    })
}

/// Everything: every entry point returns at once, so what is left is the
/// launches (passes, dispatches, indirect arguments) and their barriers.
fn launches_only(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        (t.starts_with("fn hier_") && t.ends_with(" {"))
            .then(|| format!("{l}\n    if (mrsl_ctl.size.x != 0u) {{ return; }}"))
    })
}

/// The variants. "Nothing shaded" is the mode's floor: what it costs where
/// no pixel past level 0 needs shading; the ones after it take a further
/// part out of that floor.
pub(super) const VARIANTS: [Variant; 13] = [
    Variant {
        name: "no instrumentation",
        removes: "the statistics atomics, their barrier and the refine-mask store (`DispatchOptions::statistics` off)",
        edits: &[no_instrumentation],
    },
    Variant {
        name: "no work-list shading",
        removes: "the shading of the pixels levels 1-4 queue (they are still classified, queued and counted)",
        edits: &[no_work_list_shading],
    },
    Variant {
        name: "nothing shaded (floor)",
        removes: "every shading past level 0: levels 1-4 interpolate every effect, nothing is queued",
        edits: &[nothing_shaded],
    },
    Variant {
        name: "floor with its tests",
        removes: "the same shading, but the classification's key, flag and variance tests are still paid",
        edits: &[nothing_shaded_at_run_time],
    },
    Variant {
        name: "floor, no level 0",
        removes: "also level 0's shading (1/16 of the pixels)",
        edits: &[nothing_shaded, no_level0_shading],
    },
    Variant {
        name: "floor, no classification",
        removes: "also the classification of levels 1-4 and their pixels' outputs (left: level 0 and its outputs)",
        edits: &[nothing_shaded, no_classification],
    },
    Variant {
        name: "every effect at listed pixels (added)",
        removes: "nothing; adds work: a listed pixel evaluates every coarse effect, whichever its classification named (what a SIMD group whose pixels name different effects pays)",
        edits: &[every_effect_listed],
    },
    Variant {
        name: "no outputs",
        removes: "every pixel's outputs: its fine effects, output stores, refine mask and counts (`mrsl_finish`)",
        edits: &[no_outputs],
    },
    Variant {
        name: "background channel loaded (added)",
        removes: "nothing; adds work: the background tiles' pixels load the background channel instead of taking the rule's value, so what the program computes only where something was drawn no longer folds away there (statistics off, as timed runs)",
        edits: &[background_channel_loaded, no_instrumentation],
    },
    Variant {
        name: "launches only",
        removes: "all the work: every entry point returns at once (left: passes, dispatches, indirect arguments)",
        edits: &[launches_only],
    },
    // The floor's parts as timed runs pay them: statistics off. ("No
    // outputs" needs no such twin: it removes `mrsl_finish`, which holds the
    // statistics.)
    Variant {
        name: "floor, no instrumentation",
        removes: "every shading past level 0, statistics off: the floor as timed runs pay it",
        edits: &[nothing_shaded, no_instrumentation],
    },
    Variant {
        name: "floor, no level 0, no instrumentation",
        removes: "also level 0's shading, statistics off",
        edits: &[nothing_shaded, no_level0_shading, no_instrumentation],
    },
    Variant {
        name: "floor, no classification, no instrumentation",
        removes: "also the classification of levels 1-4 and their pixels' outputs, statistics off",
        edits: &[nothing_shaded, no_classification, no_instrumentation],
    },
];

/// `program` with the hierarchical kernel shading nothing past level 0
/// ([`nothing_shaded`]): the mode's fixed cost, which `bench --suite`
/// reports as its floor. `None` when the program has no hierarchical kernel.
pub fn shading_nothing(program: &CompiledProgram) -> Option<CompiledProgram> {
    let kernel = program.kernels.iter().find(|k| k.kind == KernelKind::Hierarchical)?;
    let wgsl = nothing_shaded(&kernel.wgsl)?;
    Some(super::with_kernel(program, (KernelKind::Hierarchical, None), &wgsl))
}

#[cfg(test)]
mod tests {
    use super::super::apply;
    use super::*;
    use crate::setup::WORKLOAD_PROGRAM;

    /// Every variant edits the hierarchical kernel the code generator writes
    /// for the workload into valid WGSL, so a template change that breaks an
    /// edit fails here.
    #[test]
    fn every_variant_edits_the_workload_kernel() {
        // Both record layouts: the CLI packs records where the device can.
        for packed_records in [false, true] {
            let options = mrsl::Options { packed_records, ..mrsl::Options::default() };
            let program = mrsl::compile(WORKLOAD_PROGRAM, &options).unwrap();
            let kernel = &program.kernels.iter().find(|k| k.kind == KernelKind::Hierarchical).unwrap().wgsl;
            edits_apply(kernel);
        }
    }

    fn edits_apply(kernel: &str) {
        for v in &VARIANTS {
            let edited = apply(v, kernel).unwrap_or_else(|| panic!("{}: no line to edit", v.name));
            assert_ne!(edited, kernel, "{}", v.name);
            mrsl::validate_wgsl(&edited).unwrap_or_else(|e| panic!("{}: {e}", v.name));
        }
        // Each edit finds the lines of its own part and no other's: level 0
        // shades at one call, the work lists at one per level.
        assert_eq!(kernel.matches("mrsl_shade(p);").count(), 1);
        assert_eq!(kernel.matches("mrsl_shade(listed);").count(), 3);
        assert_eq!(kernel.matches("mrsl_shade_last(listed);").count(), 1);
        assert_eq!(kernel.matches("if (mrsl_classify(p, ").count(), 4);
        // The predicates take every derivative from the levels' neighbours:
        // no effect is evaluated at a quad partner.
        assert_eq!(kernel.matches("fn mrsl_at_").count(), 0);
        let floor = nothing_shaded(kernel).unwrap();
        assert!(!floor.contains("if (disc"), "the floor still tests an effect");
    }
}
