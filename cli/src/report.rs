//! The benchmark's analysis and outputs: sweep points, the figures
//! interpolated from them (speedup at equal quality, quality at a shading
//! rate, DACS against checkerboard), the markdown report, the CSV and the plots.
//!
//! Everything here is pure (no GPU), so it is unit-tested on made-up sweeps.

use anyhow::Result;
use mrsl_runtime::Mode;
use std::fmt::Write as _;

/// One measured configuration: a scene, a mode and a threshold value.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Point {
    pub scene: String,
    pub mode: Mode,
    /// What was swept (`light_tolerance`, `similarity`, or `-` for none).
    pub knob: String,
    /// The knob's value (NaN where nothing was swept).
    pub value: f64,
    /// Every refine predicate forced true (the worst case).
    pub forced: bool,
    pub shaded_fraction: f64,
    /// Over the coarse effects only ([`mrsl_runtime::Stats::coarse_shaded_fraction`]):
    /// the shading rate the rate figures and the efficiency use.
    pub coarse_fraction: f64,
    /// Median wall time of submit-to-idle over the runs.
    pub wall_ms: f64,
    /// Median over the runs of the wall time divided by that of the
    /// reference run paired with it (1 for the reference itself).
    pub relative_time: f64,
    /// The scene's reference time (its median wall time) that
    /// [`Point::time_ms`] scales `relative_time` by.
    pub reference_ms: f64,
    /// The reference's shading operations over this point's, by the
    /// compiler's cost model (the layout's `operations` per evaluation times
    /// the evaluations counted): how many times fewer operations it shades.
    pub fewer_operations: f64,
    /// Median GPU time of the shading passes (timestamp span), if the device
    /// has timestamps. Only a GPU's measure the shader work: on a CPU device
    /// such as lavapipe they do not (docs/runtime.md, section 9), and the
    /// wall times are what to compare.
    pub gpu_ms: Option<f64>,
    /// Medians of the per-pass timestamps ([`mrsl_runtime::Timings`]): the
    /// coarse passes (4x4 and the dynamic mode's 2x2, or the hierarchical
    /// levels) and the fine or final pass; meaningful where `gpu_ms` is.
    pub coarse_pass_ms: Option<f64>,
    pub fine_pass_ms: Option<f64>,
    pub rmse: f64,
    pub psnr: f64,
    pub mssim: f64,
    pub flip: f64,
}

impl Point {
    /// The time speedups are computed from: the paired ratio to the
    /// reference times the reference's wall time (from submission to idle,
    /// which holds only mrsl's passes and their clears and copies), so that
    /// a speedup is the inverse of the median per-pair ratio. (The
    /// timestamp span is reported beside it, but on lavapipe it misses part of
    /// the block modes' work: see docs/eval/evaluation.md.)
    pub fn time_ms(&self) -> f64 {
        self.relative_time * self.reference_ms
    }
}

/// An interpolated figure: exact where the sweep brackets the point asked
/// for; a bound (the nearest end of the sweep) where it does not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Figure {
    At(f64),
    /// The sweep never reached the point: this is the value at its nearest
    /// end, so the true figure is at least (or at most) this.
    Beyond(f64),
    Missing,
}

impl Figure {
    pub fn value(self) -> Option<f64> {
        match self {
            Figure::At(v) | Figure::Beyond(v) => Some(v),
            Figure::Missing => None,
        }
    }
    fn map(self, f: impl Fn(f64) -> f64) -> Figure {
        match self {
            Figure::At(v) => Figure::At(f(v)),
            Figure::Beyond(v) => Figure::Beyond(f(v)),
            Figure::Missing => Figure::Missing,
        }
    }
    /// `3.21`, or `3.21*` for a bound, or `n/a`.
    pub fn show(self, decimals: usize) -> String {
        match self {
            Figure::At(v) => format!("{v:.decimals$}"),
            Figure::Beyond(v) => format!("{v:.decimals$}*"),
            Figure::Missing => "n/a".into(),
        }
    }
}

/// Linear interpolation of `y` at `x` over `(x, y)` pairs sorted by `x`.
/// Outside the pairs: the nearest end, as [`Figure::Beyond`].
fn interpolate(pairs: &[(f64, f64)], x: f64) -> Figure {
    let (Some(first), Some(last)) = (pairs.first(), pairs.last()) else { return Figure::Missing };
    if x < first.0 {
        return Figure::Beyond(first.1);
    }
    if x > last.0 {
        return Figure::Beyond(last.1);
    }
    for w in pairs.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x >= x0 && x <= x1 {
            let t = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
            return Figure::At(y0 + t * (y1 - y0));
        }
    }
    Figure::At(last.1)
}

/// The quality/time Pareto frontier of `points`: by increasing time, each
/// point better than every cheaper one (a slower point that is no better is
/// never the one to pick).
fn frontier<'a>(points: &[&'a Point], quality: impl Fn(&Point) -> f64) -> Vec<&'a Point> {
    let mut sorted: Vec<&Point> = points.to_vec();
    sorted.sort_by(|a, b| a.time_ms().total_cmp(&b.time_ms()));
    let mut out: Vec<&Point> = vec![];
    for p in sorted {
        if out.last().is_none_or(|best| quality(p) > quality(best)) {
            out.push(p);
        }
    }
    out
}

/// The time a mode needs to reach quality `q` (e.g. MSSIM 0.99), on its
/// frontier. Reached by the cheapest point already: that point's time, as a
/// bound (the true time is at most that). Never reached: [`Figure::Missing`].
pub fn time_at_quality(points: &[&Point], q: f64, quality: impl Fn(&Point) -> f64 + Copy) -> Figure {
    let front = frontier(points, quality);
    let pairs: Vec<(f64, f64)> = front.iter().map(|p| (quality(p), p.time_ms())).collect();
    match interpolate(&pairs, q) {
        Figure::Beyond(_) if pairs.last().is_some_and(|l| q > l.0) => Figure::Missing,
        other => other,
    }
}

/// A metric at equal time `t`, on the frontier of `quality`.
pub fn metric_at_time(points: &[&Point], t: f64, metric: impl Fn(&Point) -> f64 + Copy) -> Figure {
    // The frontier by the metric's goodness: lower RMSE is better.
    let front = frontier(points, |p| -metric(p));
    let pairs: Vec<(f64, f64)> = front.iter().map(|p| (p.time_ms(), metric(p))).collect();
    interpolate(&pairs, t)
}

/// A metric at coarse shading rate `f`, interpolated over the sweep sorted by rate.
pub fn metric_at_fraction(points: &[&Point], f: f64, metric: impl Fn(&Point) -> f64) -> Figure {
    let mut pairs: Vec<(f64, f64)> = points.iter().map(|p| (p.coarse_fraction, metric(p))).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    interpolate(&pairs, f)
}

/// The figures the evaluation reports for one adaptive mode of one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeSummary {
    pub mode: Mode,
    /// Reference time / time at MSSIM 0.99 and 0.993.
    pub speedup_mssim_990: Figure,
    pub speedup_mssim_993: Figure,
    /// Speedup at MSSIM 0.99 divided by the ideal 1 / shaded fraction there.
    pub efficiency_990: Figure,
    /// (PSNR, MSSIM) at 20%, 50% and 80% shaded fraction.
    pub at_rates: [(Figure, Figure); 3],
    /// Forced-refine time / reference time.
    pub worst_case_overhead: Option<f64>,
    /// Reference shading operations / the mode's at MSSIM 0.99 (cost model).
    pub fewer_operations_990: Figure,
}

/// The shading rates of DACS's Table 1.
pub const RATES: [f64; 3] = [0.2, 0.5, 0.8];

pub fn summarize_mode(points: &[Point], scene: &str, mode: Mode) -> Option<ModeSummary> {
    let reference = points.iter().find(|p| p.scene == scene && p.mode == Mode::Reference && !p.forced)?;
    let sweep: Vec<&Point> = points.iter().filter(|p| p.scene == scene && p.mode == mode && !p.forced).collect();
    if sweep.is_empty() {
        return None;
    }
    // A bound on the time (reached by the cheapest point) is a lower bound on the speedup.
    let speedup = |q: f64| time_at_quality(&sweep, q, |p| p.mssim).map(|t| reference.time_ms() / t);
    let s990 = speedup(0.99);
    // The shaded fraction at MSSIM 0.99, interpolated along the same frontier.
    let front = frontier(&sweep, |p| p.mssim);
    let fractions: Vec<(f64, f64)> = front.iter().map(|p| (p.mssim, p.coarse_fraction)).collect();
    let efficiency = match (s990, interpolate(&fractions, 0.99)) {
        (Figure::Missing, _) | (_, Figure::Missing) => Figure::Missing,
        (s, f) => {
            let value = s.value().unwrap_or(0.0) * f.value().unwrap_or(1.0);
            if matches!(s, Figure::At(_)) && matches!(f, Figure::At(_)) {
                Figure::At(value)
            } else {
                Figure::Beyond(value)
            }
        }
    };
    let operations: Vec<(f64, f64)> = front.iter().map(|p| (p.mssim, p.fewer_operations)).collect();
    let fewer_operations_990 = match s990 {
        Figure::Missing => Figure::Missing,
        _ => interpolate(&operations, 0.99),
    };
    let at_rates =
        RATES.map(|r| (metric_at_fraction(&sweep, r, |p| p.psnr), metric_at_fraction(&sweep, r, |p| p.mssim)));
    let worst = points
        .iter()
        .find(|p| p.scene == scene && p.mode == mode && p.forced)
        .map(|p| p.time_ms() / reference.time_ms());
    Some(ModeSummary {
        mode,
        speedup_mssim_990: s990,
        speedup_mssim_993: speedup(0.993),
        efficiency_990: efficiency,
        at_rates,
        worst_case_overhead: worst,
        fewer_operations_990,
    })
}

/// DACS (the hierarchical mode) against the checkerboard baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VersusCheckerboard {
    /// Checkerboard time / hierarchical time at the checkerboard's MSSIM.
    pub speedup_equal_mssim: Figure,
    /// Hierarchical RMSE / checkerboard RMSE at the checkerboard's time.
    pub rmse_ratio_equal_time: Figure,
}

pub fn versus_checkerboard(points: &[Point], scene: &str) -> Option<VersusCheckerboard> {
    let cb = points.iter().find(|p| p.scene == scene && p.mode == Mode::Checkerboard && !p.forced)?;
    let dacs: Vec<&Point> =
        points.iter().filter(|p| p.scene == scene && p.mode == Mode::Hierarchical && !p.forced).collect();
    if dacs.is_empty() {
        return None;
    }
    Some(VersusCheckerboard {
        speedup_equal_mssim: time_at_quality(&dacs, cb.mssim, |p| p.mssim).map(|t| cb.time_ms() / t),
        rmse_ratio_equal_time: metric_at_time(&dacs, cb.time_ms(), |p| p.rmse).map(|r| r / cb.rmse),
    })
}

/// One frame of the dynamic-threshold run along a camera path.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ControllerFrame {
    pub frame: usize,
    pub mode: Mode,
    pub knob: String,
    pub threshold: f64,
    pub shaded_fraction: f64,
    pub time_ms: f64,
    pub target: f64,
}

/// Rows ([`Point`]s or [`ControllerFrame`]s) as CSV: a header from the
/// field names, one row each, empty cells for missing values.
pub fn csv<T: serde::Serialize>(rows: &[T]) -> Result<String> {
    let mut writer = csv::Writer::from_writer(vec![]);
    for row in rows {
        writer.serialize(row)?;
    }
    Ok(String::from_utf8(writer.into_inner().map_err(|e| e.into_error())?)?)
}

/// The distinct items, in order of first appearance.
fn unique<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = vec![];
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

fn dash(v: Option<f64>, decimals: usize) -> String {
    v.map(|v| format!("{v:.decimals$}")).unwrap_or_else(|| "-".into())
}

/// The markdown report: the setup, the summaries and every point.
pub fn markdown(setup: &str, points: &[Point], frames: &[ControllerFrame]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# mrsl benchmark\n\n{setup}\n");
    for scene in unique(points.iter().map(|p| p.scene.as_str())) {
        let _ = writeln!(out, "## {scene}\n");
        summaries_markdown(&mut out, points, scene);
        points_markdown(&mut out, points, scene);
        let _ = writeln!(out);
    }
    if !frames.is_empty() {
        controller_markdown(&mut out, frames);
    }
    out
}

/// A scene's summaries: speedups, quality at the rates of DACS's Table 1,
/// and DACS against checkerboard.
fn summaries_markdown(out: &mut String, points: &[Point], scene: &str) {
    let modes = unique(
        points
            .iter()
            .filter(|p| p.scene == scene && !matches!(p.mode, Mode::Reference | Mode::Checkerboard))
            .map(|p| p.mode),
    );
    let _ = writeln!(
        out,
        "Speedup is reference time / mode time, interpolated along each mode's quality/time frontier; \
         fewer shading operations is the reference's / the mode's by the compiler's cost model (operations per \
         evaluation times evaluations, docs/eval/evaluation.md), along the same frontier; \
         `*` marks a bound (the sweep's cheapest point already exceeds the quality: the speedup is at least this). \
         Efficiency = speedup / (1 / coarse shading rate) at MSSIM 0.99. \
         Times are paired with reference runs: speedup = 1 / median(mode time / reference time) over the pairs.\n"
    );
    let _ = writeln!(
        out,
        "| mode | speedup @ MSSIM 0.99 | speedup @ MSSIM 0.993 | efficiency @ 0.99 | fewer shading operations @ 0.99 | worst case (forced) / reference |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    let summaries: Vec<ModeSummary> = modes.iter().filter_map(|&m| summarize_mode(points, scene, m)).collect();
    for s in &summaries {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} |",
            s.mode,
            s.speedup_mssim_990.show(2),
            s.speedup_mssim_993.show(2),
            s.efficiency_990.show(2),
            s.fewer_operations_990.show(2),
            dash(s.worst_case_overhead, 2)
        );
    }
    let _ = writeln!(
        out,
        "\nQuality at the coarse shading rates of DACS Table 1 (PSNR dB / MSSIM; `*`: outside the sweep, nearest end):\n"
    );
    let _ = writeln!(out, "| mode | 20% | 50% | 80% |");
    let _ = writeln!(out, "|---|---|---|---|");
    for s in &summaries {
        let cells: Vec<String> = s.at_rates.iter().map(|(p, m)| format!("{} / {}", p.show(1), m.show(4))).collect();
        let _ = writeln!(out, "| {} | {} |", s.mode, cells.join(" | "));
    }
    if let Some(v) = versus_checkerboard(points, scene) {
        let _ = writeln!(
            out,
            "\nHierarchical (DACS) against checkerboard: {}x faster at the checkerboard's MSSIM; {}x the checkerboard's RMSE at the checkerboard's time.",
            v.speedup_equal_mssim.show(2),
            v.rmse_ratio_equal_time.show(3)
        );
    }
}

/// Every point of a scene.
fn points_markdown(out: &mut String, points: &[Point], scene: &str) {
    let _ = writeln!(out, "\n### Every point\n");
    let _ = writeln!(
        out,
        "| mode | knob | value | forced | shaded | coarse rate | wall ms | paired speedup | fewer ops | RMSE | PSNR dB | MSSIM | FLIP |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for p in points.iter().filter(|p| p.scene == scene) {
        let value = if p.value.is_nan() { "-".to_string() } else { format!("{:.3e}", p.value) };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.1}% | {:.1}% | {:.1} | {:.2} | {:.2} | {:.5} | {:.2} | {:.5} | {:.5} |",
            p.mode,
            p.knob,
            value,
            if p.forced { "yes" } else { "" },
            100.0 * p.shaded_fraction,
            100.0 * p.coarse_fraction,
            p.wall_ms,
            1.0 / p.relative_time,
            p.fewer_operations,
            p.rmse,
            p.psnr,
            p.mssim,
            p.flip
        );
    }
}

/// The controller run, frame by frame.
fn controller_markdown(out: &mut String, frames: &[ControllerFrame]) {
    let _ = writeln!(out, "## Dynamic threshold along a camera path\n");
    let _ = writeln!(out, "| frame | mode | {} | shaded | target | time ms |", frames[0].knob);
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    for f in frames {
        let _ = writeln!(
            out,
            "| {} | {} | {:.4e} | {:.1}% | {:.1}% | {:.1} |",
            f.frame,
            f.mode,
            f.threshold,
            100.0 * f.shaded_fraction,
            100.0 * f.target,
            f.time_ms
        );
    }
}

/// Registers the plots' font once (plotters draws text with ab_glyph from a
/// font it is given; the machines CI runs on have no system fonts).
pub(crate) fn register_font() -> Result<()> {
    static ONCE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    ONCE.get_or_init(|| {
        plotters::style::register_font(
            "sans-serif",
            plotters::style::FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        )
        .map_err(|_| "the plot font is invalid".to_string())
    })
    .clone()
    .map_err(anyhow::Error::msg)
}

/// Draws a chart with `draw` on a white `size` canvas; returns its RGB bytes.
fn draw_rgb(
    size: (u32, u32),
    draw: impl FnOnce(
        &plotters::drawing::DrawingArea<plotters::prelude::BitMapBackend, plotters::coord::Shift>,
    ) -> Result<()>,
) -> Result<Vec<u8>> {
    use plotters::prelude::*;
    register_font()?;
    let mut buffer = vec![255u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(buffer)
}

const PALETTE: [plotters::style::RGBColor; 6] = [
    plotters::style::RGBColor(31, 119, 180),
    plotters::style::RGBColor(255, 127, 14),
    plotters::style::RGBColor(44, 160, 44),
    plotters::style::RGBColor(214, 39, 40),
    plotters::style::RGBColor(148, 103, 189),
    plotters::style::RGBColor(140, 86, 75),
];

/// Quality (MSSIM, as -log10(1 - MSSIM) so that 0.99 and 0.999 are apart)
/// against time per mode, one PNG of `size` pixels per scene; returns RGB bytes.
pub fn plot_quality_vs_time(points: &[Point], scene: &str, size: (u32, u32)) -> Result<Vec<u8>> {
    use plotters::prelude::*;
    draw_rgb(size, |root| {
        let pts: Vec<&Point> = points.iter().filter(|p| p.scene == scene && !p.forced).collect();
        let nines = |m: f64| -(1.0 - m).max(1e-6).log10();
        let t_max = pts.iter().map(|p| p.time_ms()).fold(1.0, f64::max) * 1.1;
        let q_max = pts.iter().filter(|p| p.mode != Mode::Reference).map(|p| nines(p.mssim)).fold(2.5, f64::max) * 1.1;
        let mut chart = ChartBuilder::on(root)
            .caption(format!("{scene}: quality vs time"), ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_max, 1.0..q_max)?;
        chart
            .configure_mesh()
            .x_desc("wall time of mrsl's passes (ms, median)")
            .y_desc("MSSIM")
            .y_label_formatter(&|v| format!("{:.4}", 1.0 - 10f64.powf(-v)))
            .draw()?;
        let modes = unique(pts.iter().map(|p| p.mode));
        for (k, mode) in modes.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let mut series: Vec<(f64, f64)> =
                pts.iter().filter(|p| p.mode == *mode).map(|p| (p.time_ms(), nines(p.mssim).min(q_max))).collect();
            series.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))?
                .label(mode.name())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
            chart.draw_series(series.iter().map(|&(x, y)| Circle::new((x, y), 4, color.filled())))?;
        }
        for q in [0.99, 0.993] {
            chart.draw_series(LineSeries::new([(0.0, nines(q)), (t_max, nines(q))], BLACK.mix(0.3)))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()?;
        Ok(())
    })
}

/// The controller run: shaded fraction per frame and the target; RGB bytes.
pub fn plot_controller(frames: &[ControllerFrame], size: (u32, u32)) -> Result<Vec<u8>> {
    use plotters::prelude::*;
    draw_rgb(size, |root| {
        let n = frames.len().max(2) as f64;
        let mut chart = ChartBuilder::on(root)
            .caption("dynamic threshold: shaded fraction per frame", ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..n, 0.0..1.0)?;
        chart.configure_mesh().x_desc("frame along the camera path").y_desc("shaded fraction").draw()?;
        let measured: Vec<(f64, f64)> = frames.iter().map(|f| (f.frame as f64, f.shaded_fraction)).collect();
        let target: Vec<(f64, f64)> = frames.iter().map(|f| (f.frame as f64, f.target)).collect();
        chart
            .draw_series(LineSeries::new(measured.clone(), PALETTE[0].stroke_width(2)))?
            .label("measured")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], PALETTE[0].stroke_width(2)));
        chart.draw_series(measured.iter().map(|&(x, y)| Circle::new((x, y), 3, PALETTE[0].filled())))?;
        chart
            .draw_series(LineSeries::new(target, PALETTE[3].stroke_width(1)))?
            .label("target")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], PALETTE[3].stroke_width(1)));
        chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The adaptive mode of the made-up sweeps.
    const M: Mode = Mode::Coarse4x4;

    fn point(mode: Mode, time: f64, mssim: f64, fraction: f64) -> Point {
        Point {
            scene: "s".into(),
            mode,
            knob: "k".into(),
            value: f64::NAN,
            forced: false,
            shaded_fraction: fraction,
            coarse_fraction: fraction,
            wall_ms: time,
            relative_time: time / 100.0,
            reference_ms: 100.0,
            fewer_operations: 1.0 / fraction,
            gpu_ms: None,
            coarse_pass_ms: None,
            fine_pass_ms: None,
            rmse: 1.0 - mssim,
            psnr: 10.0 + 100.0 * mssim,
            mssim,
            flip: 0.0,
        }
    }

    #[test]
    fn interpolates_time_at_quality_on_the_frontier() {
        let pts = [
            point(M, 10.0, 0.98, 0.2),
            point(M, 20.0, 0.99, 0.4),
            // Slower and worse: off the frontier, never used.
            point(M, 25.0, 0.985, 0.5),
            point(M, 40.0, 0.995, 0.8),
        ];
        let refs: Vec<&Point> = pts.iter().collect();
        assert_eq!(time_at_quality(&refs, 0.99, |p| p.mssim), Figure::At(20.0));
        let t = time_at_quality(&refs, 0.993, |p| p.mssim).value().unwrap();
        assert!((t - 32.0).abs() < 1e-9, "{t}");
        // Reached by the cheapest point: a bound. Never reached: missing.
        assert_eq!(time_at_quality(&refs, 0.9, |p| p.mssim), Figure::Beyond(10.0));
        assert_eq!(time_at_quality(&refs, 0.999, |p| p.mssim), Figure::Missing);
    }

    #[test]
    fn summarises_a_mode_against_the_reference() {
        let mut pts = vec![point(Mode::Reference, 100.0, 1.0, 1.0)];
        pts.extend([point(M, 20.0, 0.98, 0.2), point(M, 40.0, 0.99, 0.4), point(M, 80.0, 0.998, 0.8)]);
        let mut forced = point(M, 110.0, 1.0, 1.0);
        forced.forced = true;
        pts.push(forced);
        let s = summarize_mode(&pts, "s", M).unwrap();
        assert_eq!(s.speedup_mssim_990, Figure::At(2.5));
        // Efficiency: 2.5x at 40% shaded, ideal 2.5x.
        assert!((s.efficiency_990.value().unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(s.at_rates[0].1, Figure::At(0.98));
        let m50 = s.at_rates[1].1.value().unwrap();
        assert!((m50 - 0.992).abs() < 1e-12, "{m50}");
        assert!((s.worst_case_overhead.unwrap() - 1.1).abs() < 1e-12);
        // 40% of the operations shaded at MSSIM 0.99: 2.5 times fewer.
        assert!((s.fewer_operations_990.value().unwrap() - 2.5).abs() < 1e-12);
    }

    #[test]
    fn compares_dacs_with_checkerboard_at_equal_quality_and_time() {
        let pts = vec![
            point(Mode::Checkerboard, 50.0, 0.98, 0.5),
            point(Mode::Hierarchical, 10.0, 0.97, 0.1),
            point(Mode::Hierarchical, 20.0, 0.99, 0.2),
        ];
        let v = versus_checkerboard(&pts, "s").unwrap();
        // MSSIM 0.98 at 15 ms: 50 / 15.
        assert!((v.speedup_equal_mssim.value().unwrap() - 50.0 / 15.0).abs() < 1e-9);
        // At 50 ms the sweep has ended (20 ms): the best RMSE, as a bound.
        assert_eq!(v.rmse_ratio_equal_time, Figure::Beyond((1.0 - 0.99) / (1.0 - 0.98)));
    }

    #[test]
    fn writes_csv_markdown_and_plots() {
        let pts = vec![point(Mode::Reference, 100.0, 1.0, 1.0), point(M, 20.0, 0.98, 0.2), point(M, 60.0, 0.995, 0.6)];
        let text = csv(&pts).unwrap();
        assert_eq!(text.lines().count(), 4);
        assert!(text.starts_with(
            "scene,mode,knob,value,forced,shaded_fraction,coarse_fraction,wall_ms,relative_time,reference_ms,fewer_operations,gpu_ms,coarse_pass_ms,fine_pass_ms,rmse,psnr,mssim,flip"
        ));
        let md = markdown("setup", &pts, &[]);
        // MSSIM 0.99 at 46.7 ms: 100 / 46.7.
        assert!(md.contains("| coarse4x4 | 2.14 |"), "{md}");
        let png = plot_quality_vs_time(&pts, "s", (320, 240)).unwrap();
        assert_eq!(png.len(), 320 * 240 * 3);
        // Something other than the white background was drawn.
        assert!(png.iter().filter(|&&b| b != 255).count() > 1000);
    }
}
