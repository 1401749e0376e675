//! `mrslc render`: runs a program over a scene with the wgpu runtime and
//! writes the image, a refinement heatmap and statistics; with `--frames`,
//! a sequence along the scene's camera path ([`crate::frames`]).

use crate::args::RenderArgs;
use crate::legend::{self, Legend};
use crate::output::{save_heatmap, save_image, save_texels, with_suffix};
use crate::setup::{
    BoundProgram, BoundScene, DEMO_PROGRAM, DeviceProgram, Resources, bind_program, bind_scene, compile_for_device,
};
use crate::timing::{PAIRS, median, paired, time_run};
use anyhow::{Context, Result, anyhow, bail};
use mrsl_abi::ChannelAccess;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::metrics::Metrics;
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader, Stats};
use std::path::PathBuf;
use std::time::Instant;

/// One mode's run, as written to the stats JSON.
#[derive(serde::Serialize)]
struct Run {
    #[serde(flatten)]
    stats: Stats,
    /// Against the reference image (with `--compare`).
    metrics: Option<Metrics>,
    /// Warm wall time from submission to idle, in ms (the median of the
    /// paired runs with `--compare`).
    wall_ms: f64,
    /// With `--compare`: the median over [`PAIRS`] runs of this mode's wall
    /// time divided by that of a reference run next to it.
    relative_to_reference: Option<f64>,
}

/// A step's message with the time it took.
pub fn progress(what: &str, start: Instant) {
    eprintln!("{what} ({:.0} ms)", start.elapsed().as_secs_f64() * 1e3);
}

/// What every run of a render shares: the program on its device, over its scene.
pub struct Session {
    pub gpu: Gpu,
    pub program: mrsl::Program,
    /// The program's name for messages, and the stem of the files written.
    pub name: String,
    pub stem: String,
    pub scene: BoundScene,
    /// The G-buffer (taken out of `scene`).
    pub channels: Vec<(String, wgpu::Texture)>,
    pub shader: Shader,
    pub resources: Resources,
}

/// The error for a scene without a camera path.
pub fn no_path(scene: &str) -> String {
    format!(
        "--frames needs a camera path, and scene `{scene}` has none: use --scene sponza (its default walk) or a \
         scene file with `camera_path = \"walk\"` or [[camera_path]] keyframes (docs/scenes.md)"
    )
}

/// Renders a still frame of every mode asked for; returns the paths
/// written. (`--frames` goes to [`crate::frames::render_frames`] over the
/// same [`Session`].)
pub fn render(args: &RenderArgs) -> Result<Vec<PathBuf>> {
    render_still(&mut open(args)?, args)
}

/// Compiles the program for the modes that run, makes the device, binds the
/// scene and the command line's uniforms, and creates the output directory.
pub fn open(args: &RenderArgs) -> Result<Session> {
    if args.frames.is_some() && (args.output.is_some() || args.heatmap.is_some()) {
        bail!("--frames names its files OUT/PROGRAM.MODE.fNNN.png: leave out -o and --heatmap");
    }
    let stem = args.program.as_ref().and_then(|p| p.file_stem()).and_then(|s| s.to_str()).unwrap_or("demo").to_string();
    let start = Instant::now();
    // The kernels of the modes that run: those asked for, and the reference to
    // compare with and to settle the rate-image mode's rates from (its first
    // frame, `rates::settle`) unless one rate is given everywhere.
    let mut modes = args.modes.clone();
    let settles_rates = modes.contains(&Mode::RateImage) && args.uniform_rate.is_none();
    if (args.compare || settles_rates) && !modes.contains(&Mode::Reference) {
        modes.push(Mode::Reference);
    }
    if args.program.is_none() {
        eprintln!(
            "program: the built-in demo, examples/demo.mrsl (give a .mrsl file to render another; \
             examples/sponza_lights.mrsl uses the light rig of mesh scenes)"
        );
    }
    let DeviceProgram { name, source, program, gpu } =
        compile_for_device(args.program.as_deref(), ("demo.mrsl", DEMO_PROGRAM), &modes)?;
    let access = match program.layout.channels.iter().any(|c| c.access == ChannelAccess::Storage) {
        true => "storage",
        false => "sampled",
    };
    progress(
        &format!(
            "compiled {name}: {} kernels, G-buffer read through {access} bindings; device: {} ({:?})",
            program.kernels.len(),
            gpu.adapter_info.name,
            gpu.adapter_info.backend
        ),
        start,
    );
    let start = Instant::now();
    let mut scene = bind_scene(&gpu, &args.scene, args.size)?;
    let size = scene.size;
    progress(&format!("built the {} G-buffer at {}x{}", args.scene, size.0, size.1), start);
    crate::scene_check::check_channels(&name, &source, &program.layout, &args.scene, &scene.channels)
        .map_err(|diagnostics| anyhow!(diagnostics))?;
    if args.frames.is_some() && scene.path.is_none() {
        bail!(no_path(&args.scene));
    }
    // The scene's uniforms, then the command line's.
    let BoundProgram { mut shader, resources, warnings } =
        bind_program(&gpu, &mut scene, &args.scene, &program, &args.sets, args.rates.tile)?;
    for warning in &warnings {
        eprintln!("warning: {warning}");
    }
    crate::scene_check::check_uniforms(&name, &source, &shader, &args.scene)
        .map_err(|diagnostics| anyhow!(diagnostics))?;
    shader.set_timestamp_period(&gpu.queue);
    let channels = std::mem::take(&mut scene.channels);
    resources.note_fallbacks();
    // Created only now, so that a run that fails before rendering leaves nothing behind.
    std::fs::create_dir_all(&args.out_dir).map_err(|e| anyhow!("cannot create {}: {e}", args.out_dir.display()))?;
    Ok(Session { gpu, program, name, stem, scene, channels, shader, resources })
}

/// The modes asked for that the program and device run, in order. Of a
/// list of modes (`--mode all`, say), one the device cannot run (the
/// dynamic mode's 2x2 level where storage is short, a kernel left out of
/// the program) is skipped with a note saying why; a mode asked for on its
/// own is kept, so that rendering it fails with the runtime's error.
pub fn runnable_modes(args: &RenderArgs, shader: &Shader) -> Result<Vec<Mode>> {
    if args.modes.len() == 1 {
        return Ok(args.modes.clone());
    }
    let mut modes = vec![];
    for &mode in &args.modes {
        match shader.supports(mode) {
            Ok(()) => modes.push(mode),
            Err(e) => eprintln!("skipped {mode}: {e}"),
        }
    }
    if modes.is_empty() {
        bail!("none of the modes asked for can run on this device");
    }
    Ok(modes)
}

/// What the plan `options` run does, from its data
/// ([`mrsl_lab::figures::PlanFigures`]), as a line of the render summary.
fn plan_summary(shader: &Shader, options: DispatchOptions, size: (u32, u32)) -> String {
    let device = options.device.unwrap_or(shader.device());
    let layout = shader.layout();
    let Some(plan) = layout.plan.mode_on(options.mode, device) else { return String::new() };
    let f = mrsl_lab::figures::PlanFigures::of(layout, plan, size);
    let which = match plan.device {
        Some(d) => format!("{} plan", d.name()),
        None => "plan".to_string(),
    };
    let mut line = format!(
        "{} {which}: {} dispatches, {:.0} bytes of global memory per pixel (modelled; {:.1} of them the \
         interface), {} bytes of workgroup memory",
        options.mode, f.dispatches, f.global_bytes_per_pixel, f.interface_bytes_per_pixel, f.workgroup_bytes
    );
    if let Some(e) = f.sample_evaluations {
        line.push_str(&format!(", at most {e} evaluation(s) of a coarse effect per coarse sample"));
    }
    if let Some(overlap) = f.tile_overlap {
        line.push_str(&format!(" (a tile evaluates {overlap:.2} samples per sample it owns)"));
    }
    line
}

/// The dispatch options of `mode` under the command line's.
pub fn dispatch_options(args: &RenderArgs, mode: Mode) -> DispatchOptions {
    DispatchOptions {
        force_refine: args.force_refine,
        similarity: args.similarity,
        rate_tile: args.rates.tile,
        device: args.plan,
        ..DispatchOptions::new(mode)
    }
}

/// What the modes of a still frame share.
struct Still<'a> {
    gpu: &'a Gpu,
    args: &'a RenderArgs,
    stem: &'a str,
    resources: &'a Resources,
    bindings: Bindings<'a>,
    first_output: &'a wgpu::Texture,
    /// Per-pass timestamps mean nothing on a CPU device (see [`render_still`]).
    cpu_device: bool,
}

/// Renders each mode of `args` once over the still frame; returns the paths written.
fn render_still(session: &mut Session, args: &RenderArgs) -> Result<Vec<PathBuf>> {
    let Session { gpu, program, stem, channels, shader, resources, .. } = session;
    let first_output = &resources.outputs.first().context("the program has no output")?.1;
    if args.compare && first_output.format() != wgpu::TextureFormat::Rgba32Float {
        bail!("--compare needs the first output to be rgba32float");
    }
    let still = Still {
        gpu,
        args,
        stem,
        resources,
        bindings: resources.bindings(program, channels),
        first_output,
        // Lavapipe writes a timestamp when its queue thread reaches it, so a
        // pass reads as a few microseconds: wall times are shown instead.
        cpu_device: gpu.adapter_info.device_type == wgpu::DeviceType::Cpu,
    };
    // The reference image the other modes are compared with, rendered first
    // unless it is the first mode that runs.
    let mut reference: Option<Vec<[f32; 4]>> = None;
    if args.compare && args.modes.first() != Some(&Mode::Reference) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let options = dispatch_options(args, Mode::Reference);
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &still.bindings, options)?;
        gpu.queue.submit([encoder.finish()]);
        reference = Some(gpu.read_rgba32f(first_output)?);
    }
    if still.cpu_device && (args.stats || args.output.is_none()) {
        eprintln!(
            "note: {} is a CPU device, whose per-pass timestamps are not meaningful; times shown are warm wall times",
            gpu.adapter_info.name
        );
    }
    let mut written = vec![];
    let mut runs: Vec<Run> = vec![];
    for mode in runnable_modes(args, shader)? {
        runs.push(still.render_mode(shader, mode, &mut reference, &mut written)?);
    }
    let stats_path = match &args.output {
        Some(p) => p.with_extension("stats.json"),
        None => args.out_dir.join(format!("{stem}.stats.json")),
    };
    crate::output::write(&stats_path, serde_json::to_string_pretty(&runs)?)?;
    written.push(stats_path);
    Ok(written)
}

impl Still<'_> {
    /// One mode: its rate image (the rate-image mode), a first run for the
    /// statistics, warm timed runs, the comparison with `reference` (which
    /// the reference mode sets), and its images.
    fn render_mode(
        &self,
        shader: &mut Shader,
        mode: Mode,
        reference: &mut Option<Vec<[f32; 4]>>,
        written: &mut Vec<PathBuf>,
    ) -> Result<Run> {
        let (gpu, args) = (self.gpu, self.args);
        if mode == Mode::RateImage {
            self.set_rate_image(shader)?;
        }
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &self.bindings, dispatch_options(args, mode))?;
        gpu.queue.submit([encoder.finish()]);
        let mut stats = shader.read_stats(&gpu.device)?;
        if self.cpu_device {
            stats.timings = None;
        }
        progress(&format!("rendered {mode} (first run, pipelines warming up)"), start);
        let (wall_ms, relative_to_reference) = self.wall_time(shader, mode)?;
        match relative_to_reference {
            Some((r, reference_ms)) => eprintln!(
                "{mode}: {wall_ms:.1} ms {}, {:.2}x the reference's speed (median of {PAIRS} runs paired with \
                 reference runs of median {reference_ms:.1} ms)",
                crate::timing::clock(self.gpu).short(),
                1.0 / r
            ),
            None => eprintln!("{mode}: {wall_ms:.1} ms {}", crate::timing::clock(self.gpu).short()),
        }
        eprintln!("{}", plan_summary(shader, dispatch_options(args, mode), self.resources.size));
        let mut metrics = None;
        if args.compare {
            let pixels = gpu.read_rgba32f(self.first_output)?;
            if mode == Mode::Reference {
                *reference = Some(pixels);
            } else if let Some(reference) = reference {
                let (m, path) = self.compare(mode, &pixels, reference)?;
                written.push(path);
                metrics = Some(m);
            }
        }
        self.save_outputs(mode, written)?;
        if mode != Mode::Reference && !shader.layout().stats.counters.is_empty() {
            self.save_heatmaps(shader, mode, written)?;
        }
        if args.stats || args.output.is_none() {
            println!("{}", stats.table());
            print!("{}", crate::why::verdicts(shader.layout(), &stats));
        }
        Ok(Run { stats, metrics, wall_ms, relative_to_reference: relative_to_reference.map(|(r, _)| r) })
    }

    /// The rate-image mode's rates: one everywhere (`--uniform-rate`), else
    /// the rate source's, settled over frames of a still camera.
    fn set_rate_image(&self, shader: &mut Shader) -> Result<()> {
        let args = self.args;
        match args.uniform_rate {
            Some(rate) => {
                crate::rates::fill(self.gpu, &self.resources.shading_rate, rate);
                eprintln!("shading rate {rate} everywhere (--uniform-rate)");
            }
            None => {
                let start = Instant::now();
                let options = dispatch_options(args, Mode::RateImage);
                let settled =
                    crate::rates::settle(self.gpu, shader, &self.bindings, self.first_output, &args.rates, options)?;
                progress(&settled.describe(), start);
            }
        }
        Ok(())
    }

    /// Warm wall time, without instrumentation (the statistics are the first
    /// run's); with `--compare`, the median of [`PAIRS`] runs paired with the
    /// reference, and the median ratio to it.
    fn wall_time(&self, shader: &mut Shader, mode: Mode) -> Result<(f64, Option<(f64, f64)>)> {
        let (gpu, bindings) = (self.gpu, &self.bindings);
        let timed = |mode| dispatch_options(self.args, mode).uninstrumented();
        if !self.args.compare || mode == Mode::Reference {
            return Ok((time_run(gpu, shader, bindings, timed(mode))?, None));
        }
        let p = paired(PAIRS, timed(mode), timed(Mode::Reference), |o| time_run(gpu, shader, bindings, o))?;
        // The images below are this mode's again (the rate image is still the first run's).
        time_run(gpu, shader, bindings, timed(mode))?;
        Ok((median(p.walls), Some((median(p.ratios), median(p.reference_walls)))))
    }

    /// The metrics of `pixels` against the reference, and the error image written.
    fn compare(&self, mode: Mode, pixels: &[[f32; 4]], reference: &[[f32; 4]]) -> Result<(Metrics, PathBuf)> {
        let size = self.resources.size;
        let start = Instant::now();
        let m = mrsl_lab::metrics::compare(pixels, reference, size.0, size.1)?;
        progress(
            &format!(
                "{mode} vs reference: RMSE {:.5}, PSNR {:.2} dB, MSSIM {:.5}, FLIP {:.5}",
                m.rmse, m.psnr, m.mssim, m.flip
            ),
            start,
        );
        let scale = mrsl_lab::metrics::DEFAULT_ERROR_SCALE;
        let error = mrsl_lab::metrics::error_image(pixels, reference, size.0, size.1, scale)?;
        let error = image::RgbaImage::from_raw(size.0, size.1, error).context("error image has the wrong size")?;
        let error = image::DynamicImage::ImageRgba8(error).to_rgb8();
        let path = self.args.out_dir.join(format!("{}.{mode}.error.png", self.stem));
        save_image(&legend::with_legend(&error, &Legend::Error { scale })?, &path)?;
        Ok((m, path))
    }

    /// The mode's outputs: `-o`'s path (with the mode when several run),
    /// else `OUT/STEM.MODE.png`; outputs after the first add their name.
    /// With `--raw`, each output's texels too, as `OUT/STEM.MODE.OUTPUT.bin`.
    fn save_outputs(&self, mode: Mode, written: &mut Vec<PathBuf>) -> Result<()> {
        let args = self.args;
        let suffix = if args.modes.len() > 1 || args.output.is_none() { format!(".{mode}") } else { String::new() };
        for (k, (name, texture)) in self.resources.outputs.iter().enumerate() {
            let path = match (&args.output, k) {
                (Some(p), 0) => with_suffix(p, &suffix),
                (Some(p), _) => with_suffix(p, &format!("{suffix}.{name}")),
                (None, 0) => args.out_dir.join(format!("{}{suffix}.png", self.stem)),
                (None, _) => args.out_dir.join(format!("{}{suffix}.{name}.png", self.stem)),
            };
            let texels = self.gpu.read_texture(texture)?;
            save_texels(texture, &texels, &path)?;
            written.push(path);
            if args.raw {
                let raw = args.out_dir.join(format!("{}.{mode}.{name}.bin", self.stem));
                crate::output::write(&raw, &texels)?;
                written.push(raw);
            }
        }
        Ok(())
    }

    /// The refinement heatmap (`--heatmap`, else `OUT/STEM.MODE.heatmap.png`)
    /// and one map per coarse effect: where that effect was evaluated per pixel.
    fn save_heatmaps(&self, shader: &Shader, mode: Mode, written: &mut Vec<PathBuf>) -> Result<()> {
        let args = self.args;
        let suffix = if args.modes.len() > 1 { format!(".{mode}") } else { String::new() };
        let path = match &args.heatmap {
            Some(p) => with_suffix(p, &suffix),
            None => args.out_dir.join(format!("{}.{mode}.heatmap.png", self.stem)),
        };
        let Some(rate) = shader.refine_mask() else { return Ok(()) };
        let counters = &shader.layout().stats.counters;
        save_heatmap(self.gpu, rate, counters.len(), None, &path)?;
        written.push(path.clone());
        for (bit, effect) in counters.iter().enumerate().take(32) {
            let per_effect = with_suffix(&path, &format!(".{effect}"));
            save_heatmap(self.gpu, rate, counters.len(), Some((bit as u32, effect)), &per_effect)?;
            written.push(per_effect);
        }
        Ok(())
    }
}
