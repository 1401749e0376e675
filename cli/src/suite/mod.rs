//! `mrslc bench --suite`: every mode at its defaults (no per-scene tuning)
//! over a suite of scenes, at one or more sizes, against the reference of
//! the same program: the paired speedup, quality, shaded fractions, the
//! forced worst case and the block modes' fixed cost (nothing refined).
//! Writes `suite.md` and `suite.json` and nothing else.
//!
//! A scene whose files are missing (not fetched) is reported as skipped
//! with the reason, so that a machine without every asset (a lent GPU
//! machine cannot download) still measures the rest; an unknown scene name
//! is an error before anything runs.

mod report;

use crate::ablation::{refining_nothing, shading_nothing};
use crate::setup::{DeviceProgram, Resources, WORKLOAD_PROGRAM, bind_scene, compile_for_device};
use crate::timing::{Clock, median, paired, time_run, warm_up};
use anyhow::{Context, Result, anyhow, bail};
use mrsl_abi::CompiledProgram;
use mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
use mrsl_lab::figures::PlanFigures;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::metrics::Metrics;
use mrsl_lab::scene::Scene;
use mrsl_runtime::rate_source::{Preset, RateOptions};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// The scenes `--suite` runs unless `--scene` names others: the names of
/// `mrsl_lab::scene::Scene::SUITE`.
pub const SUITE: [&str; 5] = ["sponza", "dungeon", "outdoor", "small", "generated"];

pub struct SuiteArgs {
    pub program: Option<PathBuf>,
    pub scenes: Vec<String>,
    pub sizes: Vec<(u32, u32)>,
    /// Pairs of runs behind each ratio.
    pub runs: usize,
    pub out_dir: PathBuf,
}

/// An adapter as the report names it.
#[derive(Debug, Clone, Serialize)]
pub struct Device {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
}

impl Device {
    fn of(info: &wgpu::AdapterInfo) -> Device {
        Device {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: [info.driver.as_str(), info.driver_info.as_str()].join(" ").trim().to_string(),
        }
    }
}

/// One mode over one scene.
#[derive(Debug, Clone, Serialize)]
pub struct ModeRun {
    pub mode: Mode,
    /// The block modes' plan that ran ([`mrsl_abi::Device`]) when it is not
    /// the one the device runs by default (`None`: the default).
    pub other_plan: Option<mrsl_abi::Device>,
    /// The median wall time of the reference runs it was paired with.
    pub reference_ms: f64,
    /// What the plan run does, from its data ([`PlanFigures`]).
    pub figures: PlanFigures,
    /// Median over the pairs of this mode's wall time / the reference's.
    pub time_ratio: f64,
    pub speedup: f64,
    /// Median wall time of the timed (uninstrumented) runs.
    pub wall_ms: f64,
    pub metrics: Metrics,
    pub shaded_fraction: f64,
    pub coarse_shaded_fraction: f64,
    /// Speedup x coarse shaded fraction: 1 when time follows the coarse work.
    pub efficiency: f64,
    /// Every predicate forced true: its time / the reference's.
    pub forced_ratio: f64,
    /// With none of the adaptive work (block and hierarchical modes, the fixed cost): time / the reference's.
    pub floor_ratio: Option<f64>,
}

/// Every mode over one scene at one size.
#[derive(Debug, Clone, Serialize)]
pub struct SceneRun {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference_ms: f64,
    /// Pixels the program's background rule made background.
    pub background_fraction: f64,
    pub modes: Vec<ModeRun>,
    /// Modes the device cannot run for this program, and why.
    pub unsupported: Vec<(Mode, String)>,
}

/// A scene that could not be measured.
#[derive(Debug, Clone, Serialize)]
pub struct Skipped {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reason: String,
}

/// The whole run, as `suite.json` holds it.
#[derive(Debug, Clone, Serialize)]
pub struct Suite {
    pub format: &'static str,
    pub program: String,
    pub device: Device,
    pub adapters: Vec<Device>,
    /// What the times and ratios measure ([`crate::timing::Clock::describe`]).
    pub clock: &'static str,
    pub runs: usize,
    pub sizes: Vec<(u32, u32)>,
    pub scenes: Vec<SceneRun>,
    pub skipped: Vec<Skipped>,
    pub seconds: f64,
}

/// Runs the suite; returns the files written.
pub fn suite(args: &SuiteArgs) -> Result<Vec<PathBuf>> {
    for scene in &args.scenes {
        if Scene::parse(scene).is_none() && !scene.ends_with(".toml") {
            bail!("unknown scene `{scene}` (expected {}, or a .toml scene file)", Scene::NAMES.join(", "));
        }
    }
    let start = Instant::now();
    let DeviceProgram { name, program, gpu, .. } =
        compile_for_device(args.program.as_deref(), ("sponza_lights.mrsl", WORKLOAD_PROGRAM), &Mode::ALL)?;
    let device = Device::of(&gpu.adapter_info);
    let adapters: Vec<Device> = mrsl_lab::gpu::adapters().iter().map(Device::of).collect();
    let clock = crate::timing::clock(&gpu).describe();
    eprintln!(
        "suite: {name} on {} ({}, {}), timed by {clock}; adapters present: {}",
        device.name,
        device.backend,
        device.device_type,
        adapters.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", ")
    );
    std::fs::create_dir_all(&args.out_dir).map_err(|e| anyhow!("cannot create {}: {e}", args.out_dir.display()))?;
    let (mut scenes, mut skipped) = (vec![], vec![]);
    for &size in &args.sizes {
        for scene in &args.scenes {
            let at = Instant::now();
            match measure_scene(&gpu, &program, scene, size, args.runs.max(1)) {
                Ok(run) => {
                    eprintln!("suite: {scene} at {}x{} ({:.0} s)", size.0, size.1, at.elapsed().as_secs_f64());
                    scenes.push(run);
                }
                Err(e) => {
                    eprintln!("suite: skipped {scene} at {}x{}: {e:#}", size.0, size.1);
                    skipped.push(Skipped {
                        scene: scene.clone(),
                        width: size.0,
                        height: size.1,
                        reason: format!("{e:#}"),
                    });
                }
            }
        }
    }
    let suite = Suite {
        format: "mrsl-suite/2",
        program: name,
        device,
        adapters,
        clock,
        runs: args.runs.max(1),
        sizes: args.sizes.clone(),
        scenes,
        skipped,
        seconds: start.elapsed().as_secs_f64(),
    };
    let markdown = report::markdown(&suite);
    let (md_path, json_path) = (args.out_dir.join("suite.md"), args.out_dir.join("suite.json"));
    crate::output::write(&md_path, &markdown)?;
    crate::output::write(&json_path, serde_json::to_string_pretty(&suite)?)?;
    println!("{markdown}");
    Ok(vec![md_path, json_path])
}

/// A scene bound for one program: its shader, resources and reference image.
struct Bound<'a> {
    gpu: &'a Gpu,
    shader: Shader,
    bindings: Bindings<'a>,
    first_output: &'a wgpu::Texture,
    reference: Vec<[f32; 4]>,
    size: (u32, u32),
    runs: usize,
}

/// Every mode over `scene_name` at `size`.
fn measure_scene(
    gpu: &Gpu,
    program: &mrsl::Program,
    scene_name: &str,
    size: (u32, u32),
    runs: usize,
) -> Result<SceneRun> {
    let mut scene = bind_scene(gpu, scene_name, Some(size))?;
    let mut shader = Shader::new(&gpu.device, program)?;
    shader.set_timestamp_period(&gpu.queue);
    let textures = scene.prepare(gpu, &mut shader).map_err(|e| anyhow!("{scene_name}: {e}"))?.warn();
    let resources = Resources::new(gpu, program, scene.size, textures, DEFAULT_RATE_TILE)?;
    let first_output = &resources.outputs.first().context("the program has no output")?.1;
    if first_output.format() != wgpu::TextureFormat::Rgba32Float {
        bail!("the suite compares images: the program's first output must be rgba32float");
    }
    // The block modes' floors, made before the bindings borrow the scene.
    let mut floors = vec![];
    for mode in Mode::ALL {
        if let Some(floor) = floor_program(program, mode) {
            floors.push((mode, floor_shader(gpu, &floor, &mut scene)?));
        }
    }
    let bindings = resources.bindings(program, &scene.channels);
    let reference_options = DispatchOptions::new(Mode::Reference);
    time_run(gpu, &mut shader, &bindings, reference_options)?;
    let reference = gpu.read_rgba32f(first_output)?;
    warm_up(|| time_run(gpu, &mut shader, &bindings, reference_options.uninstrumented()))?;
    let reference_walls: Vec<f64> = (0..runs)
        .map(|_| time_run(gpu, &mut shader, &bindings, reference_options.uninstrumented()))
        .collect::<Result<_>>()?;
    let mut bound = Bound { gpu, shader, bindings, first_output, reference, size: scene.size, runs };
    let (mut modes, mut unsupported, mut background) = (vec![], vec![], 0);
    let own = bound.shader.device();
    // Every mode on the device's plan, then the block modes' other plan.
    let other_plans = program.layout.plan.modes.iter().filter(|m| m.device.is_some_and(|d| d != own));
    let runs_of: Vec<(Mode, Option<mrsl_abi::Device>)> = Mode::ALL
        .into_iter()
        .filter(|m| *m != Mode::Reference)
        .map(|m| (m, None))
        .chain(other_plans.map(|m| (m.mode, m.device)))
        .collect();
    for (mode, other_plan) in runs_of {
        let device = other_plan.unwrap_or(own);
        if let Err(e) = bound.shader.supports_size_on(mode, device, bound.size) {
            unsupported.push((mode, e.to_string()));
            continue;
        }
        let floor = floors.iter_mut().find(|(m, _)| *m == mode).map(|(_, s)| s);
        let at = Instant::now();
        let (run, background_pixels) = bound.measure_mode(mode, other_plan, floor)?;
        eprintln!(
            "suite: {scene_name} {}x{} {}: {:.2}x, MSSIM {:.4}, forced {:.2} ({:.0} s)",
            size.0,
            size.1,
            report::label(&run),
            run.speedup,
            run.metrics.mssim,
            run.forced_ratio,
            at.elapsed().as_secs_f64()
        );
        background = background.max(background_pixels);
        modes.push(run);
    }
    let pixels = f64::from(size.0) * f64::from(size.1);
    Ok(SceneRun {
        scene: scene_name.to_string(),
        width: size.0,
        height: size.1,
        reference_ms: median(reference_walls),
        background_fraction: background as f64 / pixels,
        modes,
        unsupported,
    })
}

/// The program with `mode` doing none of its adaptive work, where the
/// suite measures a floor: the block modes' fine kernel refining nothing
/// ([`refining_nothing`]), the hierarchical kernel shading nothing past
/// level 0 ([`shading_nothing`]). (The other modes decide refinement in
/// several kernels; their floors are not measured.)
fn floor_program(program: &CompiledProgram, mode: Mode) -> Option<CompiledProgram> {
    match mode {
        Mode::Coarse2x2 => refining_nothing(program, 2),
        Mode::Coarse4x4 => refining_nothing(program, 4),
        Mode::Hierarchical => shading_nothing(program),
        _ => None,
    }
}

/// [`floor_program`]'s shader for `mode`, on the scene's uniforms.
fn floor_shader(gpu: &Gpu, floor: &CompiledProgram, scene: &mut crate::setup::BoundScene) -> Result<Shader> {
    let mut shader = Shader::new(&gpu.device, floor)?;
    scene.prepare(gpu, &mut shader)?;
    Ok(shader)
}

impl Bound<'_> {
    /// One mode: its rate image (the rate-image mode, settled over a still
    /// camera), paired timings at its defaults, forced and (block modes)
    /// with nothing refined, and its image against the reference. Also the
    /// background pixels its statistics counted.
    fn measure_mode(
        &mut self,
        mode: Mode,
        other_plan: Option<mrsl_abi::Device>,
        floor: Option<&mut Shader>,
    ) -> Result<(ModeRun, u64)> {
        let gpu = self.gpu;
        let options = DispatchOptions { device: other_plan, ..DispatchOptions::new(mode) };
        if mode == Mode::RateImage {
            let rates = RateOptions::preset(Preset::Balanced);
            crate::rates::settle(gpu, &mut self.shader, &self.bindings, self.first_output, &rates, options)?;
        }
        let reference = DispatchOptions::new(Mode::Reference).uninstrumented();
        // The median ratio to the reference, the median wall time and the reference's.
        let ratio = |shader: &mut Shader,
                     bindings: &Bindings,
                     options: DispatchOptions,
                     runs: usize|
         -> Result<(f64, f64, f64)> {
            warm(gpu, || time_run(gpu, shader, bindings, options))?;
            let p = paired(runs, options, reference, |o| time_run(gpu, shader, bindings, o))?;
            Ok((median(p.ratios), median(p.walls), median(p.reference_walls)))
        };
        let (time_ratio, wall_ms, reference_ms) =
            ratio(&mut self.shader, &self.bindings, options.uninstrumented(), self.runs)?;
        let forced = DispatchOptions { force_refine: true, ..options }.uninstrumented();
        let (forced_ratio, ..) = ratio(&mut self.shader, &self.bindings, forced, self.runs)?;
        let device = other_plan.unwrap_or(self.shader.device());
        let layout = self.shader.layout();
        let plan = layout.plan.mode_on(mode, device).context("the mode has a plan")?;
        let figures = PlanFigures::of(layout, plan, self.size);
        let floor_ratio = match floor {
            Some(floor) => Some(self.floor_ratio(floor, options.uninstrumented())?),
            None => None,
        };
        // The statistics and the image of one more run at the defaults.
        time_run(gpu, &mut self.shader, &self.bindings, options)?;
        let stats = self.shader.read_stats(&gpu.device)?;
        let pixels = gpu.read_rgba32f(self.first_output)?;
        let metrics = mrsl_lab::metrics::compare(&pixels, &self.reference, self.size.0, self.size.1)?;
        let speedup = 1.0 / time_ratio;
        let run = ModeRun {
            mode,
            other_plan,
            reference_ms,
            figures,
            time_ratio,
            speedup,
            wall_ms,
            metrics,
            shaded_fraction: stats.shaded_fraction,
            coarse_shaded_fraction: stats.coarse_shaded_fraction,
            efficiency: speedup * stats.coarse_shaded_fraction,
            forced_ratio,
            floor_ratio,
        };
        Ok((run, stats.background_pixels))
    }

    /// The floor program's time / the reference's (the reference runs on
    /// the full program's shader), median over the pairs.
    fn floor_ratio(&mut self, floor: &mut Shader, options: DispatchOptions) -> Result<f64> {
        let (gpu, bindings) = (self.gpu, &self.bindings);
        warm(gpu, || time_run(gpu, floor, bindings, options))?;
        let reference = DispatchOptions::new(Mode::Reference).uninstrumented();
        let shader = &mut self.shader;
        let p = paired(self.runs, options, reference, |o| match o.mode {
            Mode::Reference => time_run(gpu, shader, bindings, o),
            _ => time_run(gpu, floor, bindings, o),
        })?;
        Ok(median(p.ratios))
    }
}

/// Before a mode's timed pairs: on a GPU, [`warm_up`], since a GPU lowers
/// its clock while the suite compares images on the CPU between modes (an
/// H200 idles at 345 MHz and runs at up to 1980), and runs of a millisecond
/// or two would otherwise be timed before it climbs back; on a CPU device
/// one run, as the suite's time there is minutes per scene.
fn warm(gpu: &Gpu, mut time: impl FnMut() -> Result<f64>) -> Result<()> {
    match crate::timing::clock(gpu) {
        Clock::GpuTimestamps => warm_up(time),
        Clock::Wall => time().map(|_| ()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_suite_is_the_labs() {
        let scenes: Vec<Scene> = SUITE.iter().map(|name| Scene::parse(name).unwrap()).collect();
        assert_eq!(scenes, Scene::SUITE);
    }
}
