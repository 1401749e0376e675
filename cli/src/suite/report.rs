//! The suite's markdown: a summary per size (the geometric mean and the
//! worst scene of each mode, and of the best mode at MSSIM >= 0.99 per
//! scene), then a table per scene and size.

use super::{ModeRun, SceneRun, Suite};
use mrsl_runtime::Mode;
use std::fmt::Write as _;

/// The quality a mode must reach to count as a scene's best.
pub const MSSIM_BAR: f64 = 0.99;

/// The report.
pub fn markdown(suite: &Suite) -> String {
    let mut md = String::new();
    let d = &suite.device;
    let others: Vec<String> =
        suite.adapters.iter().map(|a| format!("{} ({}, {})", a.name, a.backend, a.device_type)).collect();
    let _ = writeln!(
        md,
        "# mrsl scene suite\n\nProgram `{}`, every mode at its defaults (no per-scene tuning), on {} ({}, {}{}); \
         adapters present: {}. Timed by {}. Each ratio is the median over {} pairs of a run of the mode and a run of the reference \
         beside it (alternately before and after); speedup = 1 / that ratio. Quality against the reference image of the \
         same program. Efficiency = speedup x coarse shaded fraction. Forced: every predicate true. Floor: the fixed \
         cost of the adaptive machinery (the block modes' fine or tile kernel with nothing refined; the hierarchical \
         kernel shading nothing past level 0). Reference ms: the median of the reference runs a row's runs were \
         paired with. From the plan: dispatches per frame, global bytes per pixel (each pass's bound resources, \
         G-buffer texels and outputs touched once; statistics off; in brackets the coarse-to-fine interface's share), the largest workgroup memory of the mode's \
         kernels, and the most evaluations of a coarse effect's body per coarse sample (with, for the tile kernel, \
         the samples a workgroup evaluates per sample it owns). A block mode's other plan (`(cpu plan)`, \
         `(gpu plan)`) is the one this kind of device does not run by default. Took {:.0} s.\n",
        suite.program,
        d.name,
        d.backend,
        d.device_type,
        if d.driver.is_empty() { String::new() } else { format!(", {}", d.driver) },
        if others.is_empty() { "none listed".into() } else { others.join("; ") },
        suite.clock,
        suite.runs,
        suite.seconds
    );
    for &(w, h) in &suite.sizes {
        let runs: Vec<&SceneRun> = suite.scenes.iter().filter(|s| (s.width, s.height) == (w, h)).collect();
        let _ = writeln!(md, "## {w}x{h}\n");
        summary(&mut md, &runs);
        for run in &runs {
            scene_table(&mut md, run);
        }
    }
    if !suite.skipped.is_empty() {
        let _ = writeln!(md, "## Not measured\n");
        for s in &suite.skipped {
            let _ = writeln!(md, "- {} at {}x{}: {}", s.scene, s.width, s.height, s.reason.replace('\n', " "));
        }
        md.push('\n');
    }
    md
}

/// What a row is called: the mode, and for a block mode's plan that is not
/// the device's own, which plan (`coarse4x4 (gpu plan)`).
pub fn label(run: &ModeRun) -> String {
    match run.other_plan {
        Some(device) => format!("{} ({} plan)", run.mode, device.name()),
        None => run.mode.to_string(),
    }
}

/// The rows of the tables, in order: each mode on the device's plans, then
/// the block modes' other plans.
fn labels(runs: &[&SceneRun]) -> Vec<String> {
    let mut labels: Vec<String> = vec![];
    for run in runs.iter().flat_map(|r| &r.modes) {
        let l = label(run);
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    labels
}

/// The fastest mode at MSSIM >= [`MSSIM_BAR`] on the device's own plans,
/// or the reference itself (`None`, 1x) when no such mode is faster than it.
pub fn best(run: &SceneRun) -> (Option<Mode>, f64) {
    run.modes
        .iter()
        .filter(|m| m.other_plan.is_none() && m.metrics.mssim >= MSSIM_BAR && m.speedup > 1.0)
        .max_by(|a, b| a.speedup.total_cmp(&b.speedup))
        .map_or((None, 1.0), |m| (Some(m.mode), m.speedup))
}

/// The geometric mean of `values` (NaN for none).
pub fn geomean(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    (values.iter().map(|v| v.ln()).sum::<f64>() / values.len() as f64).exp()
}

/// One mode's runs over the scenes of a size: (scene, run).
type Column<'a> = [(&'a str, &'a ModeRun)];

/// The summary of one size: per mode, the geometric mean and worst scene of
/// the speedup, the lowest MSSIM, the floor; and the best mode per scene.
fn summary(md: &mut String, runs: &[&SceneRun]) {
    if runs.is_empty() {
        let _ = writeln!(md, "No scene was measured at this size.\n");
        return;
    }
    let modes = labels(runs);
    let _ = writeln!(md, "| over {} scenes | {} | best at MSSIM >= {MSSIM_BAR} |", runs.len(), modes.join(" | "));
    let _ = writeln!(md, "|---|{}---|", "---|".repeat(modes.len()));
    let of = |l: &String| -> Vec<(&str, &ModeRun)> {
        runs.iter().filter_map(|r| r.modes.iter().find(|m| label(m) == *l).map(|m| (r.scene.as_str(), m))).collect()
    };
    let bests: Vec<(&str, f64)> = runs.iter().map(|r| (r.scene.as_str(), best(r).1)).collect();
    let mut row = |label: &str, cell: &dyn Fn(&Column) -> String, best_cell: String| {
        let cells: Vec<String> = modes.iter().map(|m| cell(&of(m))).collect();
        let _ = writeln!(md, "| {label} | {} | {best_cell} |", cells.join(" | "));
    };
    let worst = |v: &[(&str, f64)]| {
        v.iter().min_by(|a, b| a.1.total_cmp(&b.1)).map_or("-".into(), |(s, x)| format!("{x:.2}x ({s})"))
    };
    let speedups = |v: &[(&str, &ModeRun)]| -> Vec<f64> { v.iter().map(|(_, m)| m.speedup).collect() };
    let best_speedups: Vec<f64> = bests.iter().map(|b| b.1).collect();
    row(
        "geometric mean speedup",
        &|v| format!("{:.2}x", geomean(&speedups(v))),
        format!("{:.2}x", geomean(&best_speedups)),
    );
    row("worst scene", &|v| worst(&v.iter().map(|(s, m)| (*s, m.speedup)).collect::<Vec<_>>()), worst(&bests));
    let extreme = |v: Vec<f64>, pick: fn(f64, f64) -> f64, digits: usize| match v.into_iter().reduce(pick) {
        Some(x) => format!("{x:.digits$}"),
        None => "-".into(),
    };
    row("lowest MSSIM", &|v| extreme(v.iter().map(|(_, m)| m.metrics.mssim).collect(), f64::min, 4), String::new());
    row(
        "worst forced / reference",
        &|v| extreme(v.iter().map(|(_, m)| m.forced_ratio).collect(), f64::max, 2),
        String::new(),
    );
    row(
        "worst floor / reference",
        &|v| extreme(v.iter().filter_map(|(_, m)| m.floor_ratio).collect(), f64::max, 3),
        String::new(),
    );
    let per_scene: Vec<String> = runs
        .iter()
        .map(|r| match best(r) {
            (Some(m), x) => format!("{}: {m} {x:.2}x", r.scene),
            (None, _) => format!("{}: none faster than the reference", r.scene),
        })
        .collect();
    let _ = writeln!(md, "\nBest mode at MSSIM >= {MSSIM_BAR} per scene: {}.\n", per_scene.join("; "));
}

/// One scene's table.
fn scene_table(md: &mut String, run: &SceneRun) {
    let _ = writeln!(
        md,
        "### {} ({}x{})\n\nReference {} ms; background {:.1}% of the pixels.\n",
        run.scene,
        run.width,
        run.height,
        milliseconds(run.reference_ms),
        100.0 * run.background_fraction
    );
    let _ = writeln!(
        md,
        "| mode | speedup | ms | reference ms | MSSIM | PSNR dB | FLIP | shaded | coarse shaded | efficiency | \
         forced / reference | floor / reference | dispatches | global B/px (interface) | workgroup B | evaluations / sample |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for m in &run.modes {
        let floor = m.floor_ratio.map_or("-".into(), |f| format!("{f:.3}"));
        let f = &m.figures;
        let evaluations = match (f.sample_evaluations, f.tile_overlap) {
            (Some(e), Some(overlap)) => format!("{e} (x{overlap:.2} tile overlap)"),
            (Some(e), None) => e.to_string(),
            _ => "-".into(),
        };
        let _ = writeln!(
            md,
            "| {} | {:.2}x | {} | {} | {:.4} | {:.1} | {:.4} | {:.1}% | {:.1}% | {:.2} | {:.2} | {floor} | {} | {:.0} ({:.1}) | {} | {evaluations} |",
            label(m),
            m.speedup,
            milliseconds(m.wall_ms),
            milliseconds(m.reference_ms),
            m.metrics.mssim,
            m.metrics.psnr,
            m.metrics.flip,
            100.0 * m.shaded_fraction,
            100.0 * m.coarse_shaded_fraction,
            m.efficiency,
            m.forced_ratio,
            f.dispatches,
            f.global_bytes_per_pixel,
            f.interface_bytes_per_pixel,
            f.workgroup_bytes,
        );
    }
    for (mode, reason) in &run.unsupported {
        let _ = writeln!(md, "\n{mode} not run: {}", reason.replace('\n', " "));
    }
    md.push('\n');
}

/// A time in ms to three significant figures at least: a GPU's frame of
/// 1.234 ms as that, lavapipe's of 860.4 ms to a tenth.
fn milliseconds(ms: f64) -> String {
    match ms {
        ms if ms < 10.0 => format!("{ms:.3}"),
        ms if ms < 100.0 => format!("{ms:.2}"),
        ms => format!("{ms:.1}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_keep_three_figures() {
        assert_eq!(milliseconds(0.4412), "0.441");
        assert_eq!(milliseconds(12.345), "12.35");
        assert_eq!(milliseconds(860.42), "860.4");
    }

    #[test]
    fn the_geometric_mean_of_ratios() {
        assert!((geomean(&[2.0, 8.0]) - 4.0).abs() < 1e-12);
        assert!(geomean(&[]).is_nan());
    }
}
