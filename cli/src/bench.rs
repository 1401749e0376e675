//! `mrslc bench`: sweeps scenes x modes x refinement thresholds, measures
//! shaded fraction, wall and GPU time (medians) and quality against the
//! reference, runs the dynamic-threshold controller along a camera path,
//! and writes the markdown report, the CSV files and the plots.

use crate::render::{BoundScene, Resources, bind_scene, compile_program};
use crate::report::{self, ControllerFrame, Point};
use indicatif::{ProgressBar, ProgressStyle};
use mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
use mrsl_lab::camera_path::CameraPath;
use mrsl_lab::gpu::Gpu;
use mrsl_runtime::controller::{Target, ThresholdController};
use mrsl_runtime::rate_source::{Preset, RateOptions};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader, Stats};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The default workload (examples/sponza_lights.mrsl).
pub const WORKLOAD_PROGRAM: &str = include_str!("../../examples/sponza_lights.mrsl");

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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

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
    /// One run of `options`, from encoding to idle: its wall time in ms.
    fn time_once(&mut self, bindings: &Bindings, options: DispatchOptions) -> Result<f64, String> {
        let device = &self.gpu.device;
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&Default::default());
        self.shader.encode(device, &self.gpu.queue, &mut encoder, bindings, options).map_err(|e| e.to_string())?;
        self.gpu.queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| e.to_string())?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }

    /// Runs `options` once to warm up, then `runs` times, each run paired
    /// with a run of `reference` (when given) in alternating order (reference
    /// first, then second, ...), so that a slow moment of a shared machine
    /// weighs on both members of a pair: the time that counts is the median
    /// of the per-pair ratios, not a ratio of medians taken at different
    /// moments. The statistics come from the last run of `options`.
    fn measure(
        &mut self,
        bindings: &Bindings,
        options: DispatchOptions,
        reference: Option<DispatchOptions>,
    ) -> Result<Measured, String> {
        let device = &self.gpu.device;
        let mut walls = vec![];
        let mut ratios = vec![];
        let mut gpus = vec![];
        let mut coarse = vec![];
        let mut fine = vec![];
        // Timed runs carry no instrumentation; the statistics come from the untimed run after them.
        let timed = options.uninstrumented();
        let reference = reference.map(DispatchOptions::uninstrumented);
        self.time_once(bindings, timed)?;
        if let Some(r) = reference {
            self.time_once(bindings, r)?;
        }
        for run in 0..self.runs {
            let (wall, paired) = match reference {
                Some(r) if run % 2 == 0 => {
                    let t_ref = self.time_once(bindings, r)?;
                    (self.time_once(bindings, timed)?, t_ref)
                }
                Some(r) => {
                    let t = self.time_once(bindings, timed)?;
                    (t, self.time_once(bindings, r)?)
                }
                None => {
                    let t = self.time_once(bindings, timed)?;
                    (t, t)
                }
            };
            walls.push(wall);
            ratios.push(wall / paired);
        }
        // The statistics (and the timestamps) of one more run of `options`
        // alone: the reference runs in between overwrote them.
        let wall = self.time_once(bindings, options)?;
        let stats = self.shader.read_stats(device).map_err(|e| e.to_string())?;
        if reference.is_none() {
            walls.push(wall);
        }
        if let Some(t) = stats.timings {
            gpus.push(t.total_ms);
            coarse.push(t.coarse_ms + t.coarse2_ms);
            fine.push(t.fine_ms);
        }
        let timed = !gpus.is_empty();
        Ok(Measured {
            stats,
            wall_ms: median(walls),
            relative: if reference.is_some() { median(ratios) } else { 1.0 },
            gpu_ms: timed.then(|| median(gpus)),
            coarse_pass_ms: timed.then(|| median(coarse)),
            fine_pass_ms: timed.then(|| median(fine)),
        })
    }

    fn set(&mut self, name: &str, value: f64) -> Result<(), String> {
        self.shader.set_uniform(name, &[value]).map_err(|e| e.to_string())
    }
}

/// The shading operations of one frame by the compiler's cost model (the
/// layout's operations per evaluation, times the evaluations the
/// statistics count), and those of the reference, which evaluates every
/// effect once per pixel. Evaluations that decide refinement (the coarse
/// samples, the hierarchical levels) count `operations`; per-pixel
/// evaluations, where refinement is already decided, count
/// `value_operations`, as the kernels run them.
fn shading_operations(program: &mrsl::Program, stats: &Stats) -> (f64, f64) {
    let pixels = f64::from(stats.width) * f64::from(stats.height);
    let per_pixel_decides = stats.mode == Mode::Hierarchical.name();
    let mut mode = 0.0;
    let mut reference = 0.0;
    for e in &stats.effects {
        let Some(layout) = program.layout.effects.iter().find(|l| l.name == e.name) else { continue };
        let (Some(full), Some(value)) = (layout.operations, layout.value_operations) else { continue };
        let per_pixel = if per_pixel_decides { full } else { value };
        mode += full as f64 * e.coarse_evaluations as f64 + per_pixel as f64 * e.pixel_evaluations as f64;
        reference += value as f64 * pixels;
    }
    (mode, reference)
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

/// Runs the benchmark; returns the files written.
pub fn bench(args: &BenchArgs) -> Result<Vec<PathBuf>, String> {
    // The kernels of the modes measured, and of the reference every point is compared with.
    let mut modes = vec![Mode::Reference];
    modes.extend(args.modes.iter().copied().filter(|m| *m != Mode::Reference));
    let (name, program) = compile_program(args.program.as_deref(), ("sponza_lights.mrsl", WORKLOAD_PROGRAM), &modes)?;
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    let device_name = format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    eprintln!("bench: {name} on {device_name}, {}x{}, {} runs per point (median)", args.size.0, args.size.1, args.runs);
    std::fs::create_dir_all(&args.out_dir).map_err(|e| format!("cannot create {}: {e}", args.out_dir.display()))?;

    let knob = uniform(&program, &args.knob);
    let has_knob = knob.is_some();
    let knob_default = knob.and_then(|f| f.default.as_ref()).and_then(|d| d.first().copied());
    if !has_knob && args.modes.iter().any(|m| !matches!(m, Mode::Reference | Mode::Checkerboard | Mode::Hierarchical)) {
        eprintln!("bench: {name} has no uniform `{}`: the block modes run once at the program's defaults", args.knob);
    }
    let mut points: Vec<Point> = vec![];
    let mut frames: Vec<ControllerFrame> = vec![];
    for scene_name in &args.scenes {
        let mut scene = bind_scene(&gpu, scene_name, Some(args.size))?;
        let mut shader = Shader::new(&gpu.device, &program).map_err(|e| e.to_string())?;
        shader.set_timestamp_period(&gpu.queue);
        let textures = scene.prepare(&gpu, &mut shader).map_err(|e| format!("{scene_name}: {e}"))?.warn();
        let resources = Resources::new(&gpu, &program, scene.size, textures, DEFAULT_RATE_TILE)?;
        resources.note_fallbacks();
        let mut bench = Bench { gpu: &gpu, shader, runs: args.runs.max(1) };
        let plan = plan(args, has_knob);
        let bar = ProgressBar::new(plan.len() as u64).with_style(
            ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
                .map_err(|e| e.to_string())?
                .progress_chars("=> "),
        );
        bar.set_prefix(scene_name.clone());
        let bindings = resources.bindings(&program, &scene.channels);
        let first_output = &resources.outputs.first().ok_or("the program has no output")?.1;
        if first_output.format() != wgpu::TextureFormat::Rgba32Float {
            return Err("bench compares images: the program's first output must be rgba32float".into());
        }
        let mut reference: Option<Vec<[f32; 4]>> = None;
        for (mode, value, forced) in plan {
            let knob = match (mode, value) {
                (Mode::Hierarchical, Some(_)) => "similarity".to_string(),
                (Mode::RateImage, Some(_)) => "rate_sensitivity".to_string(),
                (_, Some(_)) => args.knob.clone(),
                _ => "-".to_string(),
            };
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
            let mut options = DispatchOptions { force_refine: forced, ..DispatchOptions::new(mode) };
            if has_knob {
                let v = match (mode, value) {
                    (Mode::Hierarchical, _) => KNOB_OFF,
                    (Mode::RateImage, _) => knob_default.unwrap_or(KNOB_OFF),
                    (_, Some(v)) => v,
                    _ => knob_default.unwrap_or(KNOB_OFF),
                };
                bench.set(&args.knob, v)?;
            }
            if let (Mode::Hierarchical, Some(s)) = (mode, value) {
                options.similarity = s as f32;
            }
            if mode == Mode::RateImage {
                // The rate image of this view and sensitivity, settled over frames of a still camera.
                let rates = RateOptions {
                    sensitivity: value.unwrap_or(Preset::Balanced.sensitivity() as f64) as f32,
                    ..RateOptions::preset(Preset::Balanced)
                };
                let settled = crate::rates::settle(&gpu, &mut bench.shader, &bindings, first_output, &rates, options)?;
                if bar.is_hidden() {
                    eprintln!("  {}", settled.describe());
                }
            }
            let paired = (mode != Mode::Reference || forced).then(|| DispatchOptions::new(Mode::Reference));
            let m = bench.measure(&bindings, options, paired)?;
            let pixels = gpu.read_rgba32f(first_output).map_err(|e| e.to_string())?;
            let metrics = match &reference {
                None => {
                    reference = Some(pixels);
                    mrsl_lab::metrics::Metrics { rmse: 0.0, psnr: f64::INFINITY, mssim: 1.0, flip: 0.0 }
                }
                Some(r) => {
                    mrsl_lab::metrics::compare(&pixels, r, scene.size.0, scene.size.1).map_err(|e| e.to_string())?
                }
            };
            points.push(Point {
                scene: scene_name.clone(),
                mode: mode.to_string(),
                knob,
                value: value.unwrap_or(f64::NAN),
                forced,
                shaded_fraction: m.stats.shaded_fraction,
                coarse_fraction: m.stats.coarse_shaded_fraction,
                wall_ms: m.wall_ms,
                relative_time: m.relative,
                fewer_operations: {
                    let (ops, reference) = shading_operations(&program, &m.stats);
                    reference / ops
                },
                // Set below, once the scene's reference is measured.
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
        // Every point's time is its paired ratio times one reference time.
        let reference_ms = points
            .iter()
            .find(|p| &p.scene == scene_name && p.mode == Mode::Reference.to_string() && !p.forced)
            .map(|p| p.wall_ms)
            .unwrap_or(f64::NAN);
        for p in points.iter_mut().filter(|p| &p.scene == scene_name) {
            p.reference_ms = reference_ms;
        }
        if args.path_frames > 0 && scene.mesh.is_some() && args.modes.contains(&Mode::Hierarchical) {
            frames = controller_run(&gpu, &program, &mut scene, args)?;
        }
    }

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
    let mut write = |file: &str, bytes: &[u8]| -> Result<(), String> {
        let path = args.out_dir.join(file);
        std::fs::write(&path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        written.push(path);
        Ok(())
    };
    let markdown = report::markdown(&setup, &points, &frames);
    write("bench.md", markdown.as_bytes())?;
    write("bench.csv", report::csv(&points)?.as_bytes())?;
    if !frames.is_empty() {
        write("controller.csv", report::csv(&frames)?.as_bytes())?;
    }
    let plot_size = (900, 600);
    for scene in &args.scenes {
        let rgb = report::plot_quality_vs_time(&points, scene, plot_size)?;
        let path = args.out_dir.join(format!("quality_vs_time.{}.png", file_safe(scene)));
        save_rgb(&rgb, plot_size, &path)?;
        written.push(path);
    }
    if !frames.is_empty() {
        let rgb = report::plot_controller(&frames, plot_size)?;
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

fn save_rgb(rgb: &[u8], size: (u32, u32), path: &Path) -> Result<(), String> {
    image::RgbImage::from_raw(size.0, size.1, rgb.to_vec())
        .ok_or("plot buffer has the wrong size")?
        .save(path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The dynamic threshold: the hierarchical mode's similarity steered to a
/// target shaded fraction, frame by frame along a camera path.
fn controller_run(
    gpu: &Gpu,
    program: &mrsl::Program,
    scene: &mut BoundScene,
    args: &BenchArgs,
) -> Result<Vec<ControllerFrame>, String> {
    let mut shader = Shader::new(&gpu.device, program).map_err(|e| e.to_string())?;
    shader.set_timestamp_period(&gpu.queue);
    // The same bindings as the sweep's, whose warnings were printed there.
    let textures = scene.prepare(gpu, &mut shader)?.textures;
    let mesh = scene.mesh.as_ref().ok_or("the controller needs a mesh scene")?;
    let resources = Resources::new(gpu, program, args.size, textures, DEFAULT_RATE_TILE)?;
    if uniform(program, &args.knob).is_some() {
        shader.set_uniform(&args.knob, &[KNOB_OFF]).map_err(|e| e.to_string())?;
    }
    let start = args.similarities.iter().copied().fold(f64::NAN, f64::min);
    let start = if start.is_finite() { start } else { DispatchOptions::DEFAULT_SIMILARITY as f64 };
    let mut controller = ThresholdController::new(Target::ShadedFraction(args.target_fraction), start, (1e-9, 1e3));
    let bar = ProgressBar::new(args.path_frames as u64).with_style(
        ProgressStyle::with_template("controller [{bar:30}] {pos}/{len} {msg} ({elapsed})")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    let mut frames = vec![];
    let mut bench = Bench { gpu, shader, runs: 1 };
    for i in 0..args.path_frames {
        let camera = CameraPath::Walk.camera(&mesh.camera, i, args.path_frames);
        let channels = mesh.gbuffer(gpu, &camera, args.size).map_err(|e| e.to_string())?;
        mesh.set_uniforms(&mut bench.shader, &camera).map_err(|e| e.to_string())?;
        let bindings = resources.bindings(program, &channels);
        let threshold = controller.threshold();
        let options = DispatchOptions { similarity: threshold as f32, ..DispatchOptions::new(Mode::Hierarchical) };
        let m = bench.measure(&bindings, options, None)?;
        frames.push(ControllerFrame {
            frame: i,
            mode: Mode::Hierarchical.to_string(),
            knob: "similarity".into(),
            threshold,
            shaded_fraction: m.stats.shaded_fraction,
            time_ms: m.gpu_ms.unwrap_or(m.wall_ms),
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
