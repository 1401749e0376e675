//! `mrslc bench`: sweeps scenes x modes x refinement thresholds, measures
//! shaded fraction, wall and GPU time (medians) and quality against the
//! reference, runs the dynamic-threshold controller along a camera path,
//! and writes the markdown report, the CSV files and the plots.

use crate::output::save_image;
use crate::report::{self, ControllerFrame, Point};
use crate::setup::{BoundScene, DeviceProgram, Resources, WORKLOAD_PROGRAM, bind_scene, compile_for_device};
use crate::timing::{median, paired, time_run};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
use mrsl_lab::camera_path::CameraPath;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::metrics::Metrics;
use mrsl_runtime::controller::{Target, ThresholdController};
use mrsl_runtime::rate_source::{Preset, RateOptions};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader, Stats};
use std::path::{Path, PathBuf};

pub struct BenchArgs {
    pub program: Option<PathBuf>,
    pub scenes: Vec<String>,
    pub size: (u32, u32),
    pub modes: Vec<Mode>,
    /// The block and dynamic modes' knob: a program uniform and its values.
    pub knob: String,
    pub values: Vec<f64>,
    /// The hierarchical mode's knob: its similarity thresholds.
    pub similarities: Vec<f64>,
    pub runs: usize,
    pub out_dir: PathBuf,
    /// Frames of the controller's camera path (0: skip it).
    pub path_frames: usize,
    pub target_fraction: f64,
}

/// A value of the program's knob so large that its predicate never fires:
/// the hierarchical sweep turns the program's tolerance off so that DACS's
/// own similarity test is the knob (as in the paper).
const KNOB_OFF: f64 = 1e30;

/// A shader on a device, measured `runs` times per configuration.
struct Bench<'a> {
    gpu: &'a Gpu,
    shader: Shader,
    runs: usize,
}

/// One configuration's measurements.
struct Measured {
    stats: Stats,
    wall_ms: f64,
    /// The median over the runs of this configuration's wall time divided by
    /// that of the reference run paired with it (1 for the reference itself).
    relative: f64,
    /// Medians of the timestamp span, the coarse passes and the fine pass.
    gpu_ms: Option<f64>,
    coarse_pass_ms: Option<f64>,
    fine_pass_ms: Option<f64>,
}

impl Bench<'_> {
    /// Runs `options` once to warm up, then `runs` times, each run paired
    /// with a run of `reference` (when given, [`paired`]): the time that
    /// counts is the median of the per-pair ratios, not a ratio of medians
    /// taken at different moments. The statistics come from one more run of
    /// `options` after them.
    fn measure(
        &mut self,
        bindings: &Bindings,
        options: DispatchOptions,
        reference: Option<DispatchOptions>,
    ) -> Result<Measured> {
        let gpu = self.gpu;
        // Timed runs carry no instrumentation; the statistics come from the untimed run after them.
        let timed = options.uninstrumented();
        let reference = reference.map(DispatchOptions::uninstrumented);
        time_run(gpu, &mut self.shader, bindings, timed)?;
        if let Some(r) = reference {
            time_run(gpu, &mut self.shader, bindings, r)?;
        }
        let (mut walls, ratios) = match reference {
            Some(r) => {
                let p = paired(self.runs, timed, r, |o| time_run(gpu, &mut self.shader, bindings, o))?;
                (p.walls, p.ratios)
            }
            None => {
                let walls = (0..self.runs).map(|_| time_run(gpu, &mut self.shader, bindings, timed));
                (walls.collect::<Result<Vec<f64>>>()?, vec![])
            }
        };
        // The statistics (and the timestamps) of one more run of `options`
        // alone: the reference runs in between overwrote them.
        let wall = time_run(gpu, &mut self.shader, bindings, options)?;
        let stats = self.shader.read_stats(&gpu.device)?;
        if reference.is_none() {
            walls.push(wall);
        }
        let timings = stats.timings;
        Ok(Measured {
            stats,
            wall_ms: median(walls),
            relative: if reference.is_some() { median(ratios) } else { 1.0 },
            gpu_ms: timings.map(|t| t.total_ms),
            coarse_pass_ms: timings.map(|t| t.coarse_ms + t.coarse2_ms),
            fine_pass_ms: timings.map(|t| t.fine_ms),
        })
    }

    fn set(&mut self, name: &str, value: f64) -> Result<()> {
        Ok(self.shader.set_uniform(name, &[value])?)
    }
}

/// The shading operations of one frame by the compiler's cost model (the
/// layout's operations per evaluation, times the evaluations the
/// statistics count), and those of the reference, which evaluates every
/// effect once per pixel. Evaluations that decide refinement (the coarse
/// samples, the hierarchical levels) count `operations`; per-pixel
/// evaluations, where refinement is already decided, count
/// `value_operations`, as the kernels run them.
fn shading_operations(program: &mrsl::Program, mode: Mode, stats: &Stats) -> (f64, f64) {
    let pixels = f64::from(stats.width) * f64::from(stats.height);
    let per_pixel_decides = mode == Mode::Hierarchical;
    let mut ops = 0.0;
    let mut reference = 0.0;
    for e in &stats.effects {
        let Some(layout) = program.layout.effects.iter().find(|l| l.name == e.name) else { continue };
        let (Some(full), Some(value)) = (layout.operations, layout.value_operations) else { continue };
        let per_pixel = if per_pixel_decides { full } else { value };
        ops += full as f64 * e.coarse_evaluations as f64 + per_pixel as f64 * e.pixel_evaluations as f64;
        reference += value as f64 * pixels;
    }
    (ops, reference)
}

/// The program's uniform `name`, if it declares one.
fn uniform<'p>(program: &'p mrsl::Program, name: &str) -> Option<&'p mrsl_abi::Field> {
    program.layout.uniforms.as_ref()?.fields.iter().find(|f| f.name == name)
}

/// The rate-image mode's points: the rate source's sensitivity t of VALAR's presets
/// (Quality, Balanced, Performance).
const RATE_SENSITIVITIES: [f64; 3] = [0.25, 0.5, 0.75];

/// The configurations of one scene, in order.
fn plan(args: &BenchArgs, has_knob: bool) -> Vec<(Mode, Option<f64>, bool)> {
    let mut plan = vec![(Mode::Reference, None, false)];
    for &mode in &args.modes {
        match mode {
            Mode::Reference => {}
            Mode::Checkerboard => plan.push((mode, None, false)),
            Mode::Hierarchical => plan.extend(args.similarities.iter().map(|&s| (mode, Some(s), false))),
            // The rate source's presets (its sensitivity t), with the program's own knob at its default.
            Mode::RateImage => plan.extend(RATE_SENSITIVITIES.iter().map(|&t| (mode, Some(t), false))),
            _ if has_knob => plan.extend(args.values.iter().map(|&v| (mode, Some(v), false))),
            _ => plan.push((mode, None, false)),
        }
    }
    // The worst case: every predicate forced true.
    plan.extend(args.modes.iter().filter(|m| **m != Mode::Reference).map(|&m| (m, None, true)));
    plan
}

/// What every scene of a benchmark shares.
struct Workload<'a> {
    args: &'a BenchArgs,
    gpu: &'a Gpu,
    program: &'a mrsl::Program,
    /// Whether the program declares `--knob`, and its default.
    has_knob: bool,
    knob_default: Option<f64>,
}

/// Runs the benchmark; returns the files written.
pub fn bench(args: &BenchArgs) -> Result<Vec<PathBuf>> {
    // The kernels of the modes measured, and of the reference every point is compared with.
    let mut modes = vec![Mode::Reference];
    modes.extend(args.modes.iter().copied().filter(|m| *m != Mode::Reference));
    let DeviceProgram { name, program, gpu, .. } =
        compile_for_device(args.program.as_deref(), ("sponza_lights.mrsl", WORKLOAD_PROGRAM), &modes)?;
    let device_name = format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    eprintln!("bench: {name} on {device_name}, {}x{}, {} runs per point (median)", args.size.0, args.size.1, args.runs);
    std::fs::create_dir_all(&args.out_dir)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", args.out_dir.display()))?;

    let knob = uniform(&program, &args.knob);
    let workload = Workload {
        args,
        gpu: &gpu,
        program: &program,
        has_knob: knob.is_some(),
        knob_default: knob.and_then(|f| f.default.as_ref()).and_then(|d| d.first().copied()),
    };
    if !workload.has_knob
        && args.modes.iter().any(|m| !matches!(m, Mode::Reference | Mode::Checkerboard | Mode::Hierarchical))
    {
        eprintln!("bench: {name} has no uniform `{}`: the block modes run once at the program's defaults", args.knob);
    }
    let mut points: Vec<Point> = vec![];
    let mut frames: Vec<ControllerFrame> = vec![];
    for scene_name in &args.scenes {
        let mut scene = bind_scene(&gpu, scene_name, Some(args.size))?;
        let mut scene_points = workload.sweep(scene_name, &mut scene)?;
        // Every point's time is its paired ratio times one reference time.
        let reference_ms =
            scene_points.iter().find(|p| p.mode == Mode::Reference && !p.forced).map(|p| p.wall_ms).unwrap_or(f64::NAN);
        for p in &mut scene_points {
            p.reference_ms = reference_ms;
        }
        points.extend(scene_points);
        if args.path_frames > 0 && scene.mesh.is_some() && args.modes.contains(&Mode::Hierarchical) {
            frames = controller_run(&gpu, &program, &mut scene, args)?;
        }
    }
    write_report(args, &name, &device_name, &points, &frames)
}

/// A progress bar of `len` steps drawn with `template`.
fn progress_bar(len: usize, template: &str) -> Result<ProgressBar> {
    Ok(ProgressBar::new(len as u64).with_style(ProgressStyle::with_template(template)?.progress_chars("=> ")))
}

impl Workload<'_> {
    /// Every configuration of the [`plan`] over one scene, the reference first.
    fn sweep(&self, scene_name: &str, scene: &mut BoundScene) -> Result<Vec<Point>> {
        let (gpu, program) = (self.gpu, self.program);
        let mut shader = Shader::new(&gpu.device, program)?;
        shader.set_timestamp_period(&gpu.queue);
        let textures = scene.prepare(gpu, &mut shader).map_err(|e| anyhow::anyhow!("{scene_name}: {e}"))?.warn();
        let resources = Resources::new(gpu, program, scene.size, textures, DEFAULT_RATE_TILE)?;
        resources.note_fallbacks();
        let mut bench = Bench { gpu, shader, runs: self.args.runs.max(1) };
        let plan = plan(self.args, self.has_knob);
        let bar = progress_bar(plan.len(), "{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})")?;
        bar.set_prefix(scene_name.to_string());
        let bindings = resources.bindings(program, &scene.channels);
        let first_output = &resources.outputs.first().context("the program has no output")?.1;
        if first_output.format() != wgpu::TextureFormat::Rgba32Float {
            bail!("bench compares images: the program's first output must be rgba32float");
        }
        let mut reference: Option<Vec<[f32; 4]>> = None;
        let mut points = vec![];
        for (mode, value, forced) in plan {
            let knob = self.knob_name(mode, value);
            let what = format!(
                "{mode}{}{}",
                value.map(|v| format!(" {knob}={v:e}")).unwrap_or_default(),
                if forced { " (forced)" } else { "" }
            );
            // The bar draws only on a terminal; logs get a line per point.
            if bar.is_hidden() {
                eprintln!("{scene_name} [{}/{}] {what}", bar.position() + 1, bar.length().unwrap_or(0));
            }
            bar.set_message(what);
            let m = self.measure_point(&mut bench, &bindings, first_output, (mode, value, forced), &bar)?;
            let pixels = gpu.read_rgba32f(first_output)?;
            let metrics = match &reference {
                None => {
                    reference = Some(pixels);
                    Metrics { rmse: 0.0, psnr: f64::INFINITY, mssim: 1.0, flip: 0.0 }
                }
                Some(r) => mrsl_lab::metrics::compare(&pixels, r, scene.size.0, scene.size.1)?,
            };
            let (ops, reference_ops) = shading_operations(program, mode, &m.stats);
            points.push(Point {
                scene: scene_name.to_string(),
                mode,
                knob,
                value: value.unwrap_or(f64::NAN),
                forced,
                shaded_fraction: m.stats.shaded_fraction,
                coarse_fraction: m.stats.coarse_shaded_fraction,
                wall_ms: m.wall_ms,
                relative_time: m.relative,
                fewer_operations: reference_ops / ops,
                // Set by the caller, once the scene's reference is measured.
                reference_ms: f64::NAN,
                gpu_ms: m.gpu_ms,
                coarse_pass_ms: m.coarse_pass_ms,
                fine_pass_ms: m.fine_pass_ms,
                rmse: metrics.rmse,
                psnr: metrics.psnr,
                mssim: metrics.mssim,
                flip: metrics.flip,
            });
            bar.inc(1);
        }
        bar.finish_with_message("done");
        Ok(points)
    }

    /// What a point sweeps: the hierarchical mode's similarity, the
    /// rate-image mode's sensitivity, the program's knob, or `-`.
    fn knob_name(&self, mode: Mode, value: Option<f64>) -> String {
        match (mode, value) {
            (Mode::Hierarchical, Some(_)) => "similarity".to_string(),
            (Mode::RateImage, Some(_)) => "rate_sensitivity".to_string(),
            (_, Some(_)) => self.args.knob.clone(),
            _ => "-".to_string(),
        }
    }

    /// Sets one configuration's knob (and its rate image, settled over
    /// frames of a still camera, for the rate-image mode) and measures it,
    /// paired with the reference.
    fn measure_point(
        &self,
        bench: &mut Bench,
        bindings: &Bindings,
        first_output: &wgpu::Texture,
        (mode, value, forced): (Mode, Option<f64>, bool),
        bar: &ProgressBar,
    ) -> Result<Measured> {
        let mut options = DispatchOptions { force_refine: forced, ..DispatchOptions::new(mode) };
        if self.has_knob {
            let v = match (mode, value) {
                (Mode::Hierarchical, _) => KNOB_OFF,
                (Mode::RateImage, _) => self.knob_default.unwrap_or(KNOB_OFF),
                (_, Some(v)) => v,
                _ => self.knob_default.unwrap_or(KNOB_OFF),
            };
            bench.set(&self.args.knob, v)?;
        }
        if let (Mode::Hierarchical, Some(s)) = (mode, value) {
            options.similarity = s as f32;
        }
        if mode == Mode::RateImage {
            let rates = RateOptions {
                sensitivity: value.unwrap_or(Preset::Balanced.sensitivity() as f64) as f32,
                ..RateOptions::preset(Preset::Balanced)
            };
            let settled = crate::rates::settle(self.gpu, &mut bench.shader, bindings, first_output, &rates, options)?;
            if bar.is_hidden() {
                eprintln!("  {}", settled.describe());
            }
        }
        let paired = (mode != Mode::Reference || forced).then(|| DispatchOptions::new(Mode::Reference));
        bench.measure(bindings, options, paired)
    }
}

/// Writes bench.md, bench.csv, controller.csv and the plots; prints the
/// markdown report.
fn write_report(
    args: &BenchArgs,
    name: &str,
    device_name: &str,
    points: &[Point],
    frames: &[ControllerFrame],
) -> Result<Vec<PathBuf>> {
    let setup = format!(
        "Program `{name}`; scenes {}; {}x{}; device {device_name}; {} timed runs per point after one warm-up, each \
         paired with a reference run (alternately before and after it); times are the median of the per-pair ratios \
         times the reference's median wall time, so speedups are those medians' inverses. \
         Block and dynamic modes sweep the uniform `{}` over {:?}; the hierarchical mode sweeps `similarity` over {:?} \
         with `{}` off. Quality against the reference image of the same program: RMSE, PSNR, MSSIM (Wang 2004), FLIP.",
        args.scenes.join(", "),
        args.size.0,
        args.size.1,
        args.runs,
        args.knob,
        args.values,
        args.similarities,
        args.knob
    );
    let mut written = vec![];
    let mut write = |file: &str, bytes: &[u8]| -> Result<()> {
        let path = args.out_dir.join(file);
        crate::output::write(&path, bytes)?;
        written.push(path);
        Ok(())
    };
    let markdown = report::markdown(&setup, points, frames);
    write("bench.md", markdown.as_bytes())?;
    write("bench.csv", report::csv(points)?.as_bytes())?;
    if !frames.is_empty() {
        write("controller.csv", report::csv(frames)?.as_bytes())?;
    }
    let plot_size = (900, 600);
    for scene in &args.scenes {
        let rgb = report::plot_quality_vs_time(points, scene, plot_size)?;
        let path = args.out_dir.join(format!("quality_vs_time.{}.png", file_safe(scene)));
        save_rgb(&rgb, plot_size, &path)?;
        written.push(path);
    }
    if !frames.is_empty() {
        let rgb = report::plot_controller(frames, plot_size)?;
        let path = args.out_dir.join("controller.png");
        save_rgb(&rgb, plot_size, &path)?;
        written.push(path);
    }
    println!("{markdown}");
    Ok(written)
}

fn file_safe(name: &str) -> String {
    Path::new(name).file_stem().and_then(|s| s.to_str()).unwrap_or(name).replace(|c: char| !c.is_alphanumeric(), "_")
}

fn save_rgb(rgb: &[u8], size: (u32, u32), path: &Path) -> Result<()> {
    save_image(
        &image::RgbImage::from_raw(size.0, size.1, rgb.to_vec()).context("plot buffer has the wrong size")?,
        path,
    )
}
/// The dynamic threshold: the hierarchical mode's similarity steered to a
/// target shaded fraction, frame by frame along a camera path.
fn controller_run(
    gpu: &Gpu,
    program: &mrsl::Program,
    scene: &mut BoundScene,
    args: &BenchArgs,
) -> Result<Vec<ControllerFrame>> {
    let mut shader = Shader::new(&gpu.device, program)?;
    shader.set_timestamp_period(&gpu.queue);
    // The same bindings as the sweep's, whose warnings were printed there.
    let textures = scene.prepare(gpu, &mut shader)?.textures;
    let mesh = scene.mesh.as_ref().context("the controller needs a mesh scene")?;
    let resources = Resources::new(gpu, program, args.size, textures, DEFAULT_RATE_TILE)?;
    if uniform(program, &args.knob).is_some() {
        shader.set_uniform(&args.knob, &[KNOB_OFF])?;
    }
    let start = args.similarities.iter().copied().fold(f64::NAN, f64::min);
    let start = if start.is_finite() { start } else { DispatchOptions::DEFAULT_SIMILARITY as f64 };
    let mut controller = ThresholdController::new(Target::ShadedFraction(args.target_fraction), start, (1e-9, 1e3));
    let bar = progress_bar(args.path_frames, "controller [{bar:30}] {pos}/{len} {msg} ({elapsed})")?;
    let mut frames = vec![];
    // A CPU device's timestamps do not measure the shader work (docs/runtime.md, section 9).
    let timestamps_meaningful = crate::timing::clock(gpu) == crate::timing::Clock::GpuTimestamps;
    let mut bench = Bench { gpu, shader, runs: 1 };
    for i in 0..args.path_frames {
        let camera = CameraPath::Walk.camera(&mesh.camera, i, args.path_frames);
        let channels = mesh.gbuffer(gpu, &camera, args.size)?;
        mesh.set_uniforms(&mut bench.shader, &camera)?;
        let bindings = resources.bindings(program, &channels);
        let threshold = controller.threshold();
        let options = DispatchOptions { similarity: threshold as f32, ..DispatchOptions::new(Mode::Hierarchical) };
        let m = bench.measure(&bindings, options, None)?;
        frames.push(ControllerFrame {
            frame: i,
            mode: Mode::Hierarchical,
            knob: "similarity".into(),
            threshold,
            shaded_fraction: m.stats.shaded_fraction,
            time_ms: if timestamps_meaningful { m.gpu_ms.unwrap_or(m.wall_ms) } else { m.wall_ms },
            target: args.target_fraction,
        });
        controller.update(m.stats.shaded_fraction);
        let what = format!("similarity {threshold:.3e}: shaded {:.1}%", 100.0 * m.stats.shaded_fraction);
        if bar.is_hidden() {
            eprintln!("controller [{}/{}] {what}", i + 1, args.path_frames);
        }
        bar.set_message(what);
        bar.inc(1);
    }
    bar.finish();
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plan_sweeps_each_mode_and_forces_each_once() {
        let args = BenchArgs {
            program: None,
            scenes: vec!["demo".into()],
            size: (64, 64),
            modes: vec![Mode::Coarse4x4, Mode::Hierarchical, Mode::Checkerboard],
            knob: "k".into(),
            values: vec![1.0, 2.0],
            similarities: vec![0.1, 0.2, 0.3],
            runs: 1,
            out_dir: ".".into(),
            path_frames: 0,
            target_fraction: 0.5,
        };
        let plan = plan(&args, true);
        assert_eq!(plan[0], (Mode::Reference, None, false));
        assert_eq!(plan.iter().filter(|p| p.0 == Mode::Coarse4x4 && !p.2).count(), 2);
        assert_eq!(plan.iter().filter(|p| p.0 == Mode::Hierarchical && !p.2).count(), 3);
        assert_eq!(plan.iter().filter(|p| p.2).count(), 3);
        assert_eq!(plan.len(), 1 + 2 + 3 + 1 + 3);
    }
}
