//! `mrslc render --frames N`: N frames along the scene's camera path. Each
//! frame rasterises the G-buffer with motion vectors from the previous
//! frame's camera, renders every requested mode, and writes
//! `STEM.MODE.fNNN.png`; the rate-image mode takes its rates from the
//! runtime's rate source run on its own previous frame and that frame's
//! velocity (motion terms and reprojection on), as an engine would, and each
//! of its frames gets a visualisation of the rates it was shaded at,
//! `STEM.rate-image.rates.fNNN.png`. Per-frame statistics (shaded fraction,
//! warm wall time, with `--compare` the metrics against that frame's
//! reference, and the temporal-stability figure) go to `STEM.frames.json`.

use crate::args::RenderArgs;
use crate::legend::{self, Legend};
use crate::output::{save_image, save_output};
use crate::render::{Session, dispatch_options, no_path};
use crate::setup::Resources;
use crate::timing::{PAIRS, median, paired, time_run};
use anyhow::{Context, Result, anyhow, bail};
use mrsl_abi::ShadingRate;
use mrsl_lab::camera::Camera;
use mrsl_lab::color::linear_to_srgb8;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::mesh_scene::MeshScene;
use mrsl_lab::metrics::Metrics;
use mrsl_lab::uniforms::{Offered, Verdict};
use mrsl_runtime::rate_source::{RateInputs, RateOptions, RateSource, rate_fraction, read_rate_image};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The most frames `--frames` takes (file names have three digits).
pub const MAX_FRAMES: usize = 1000;

/// Parses `--frames`: a whole number of frames from 1 to [`MAX_FRAMES`].
pub fn parse_frames(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_FRAMES).contains(&n) => Ok(n),
        _ => Err(format!("expected a number of frames from 1 to {MAX_FRAMES}, got `{text}`")),
    }
}

/// The mean absolute difference between two frames over linear R, G, B,
/// each clamped to [0, 1] (as the metrics clamp them): how much the image
/// changed from one frame to the next.
pub fn mean_change(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    if a.is_empty() || a.len() != b.len() {
        return 0.0;
    }
    let clamp = |v: f32| if v.is_finite() { f64::from(v.clamp(0.0, 1.0)) } else { 0.0 };
    let sum: f64 = a.iter().zip(b).flat_map(|(p, q)| (0..3).map(move |c| (clamp(p[c]) - clamp(q[c])).abs())).sum();
    sum / (3 * a.len()) as f64
}

/// One mode's frame, as written to `frames.json`.
#[derive(serde::Serialize)]
struct ModeFrame {
    mode: Mode,
    shaded_fraction: f64,
    /// Warm wall time of the frame's run, from encoding to idle, in ms.
    wall_ms: f64,
    /// The reference's speed relative to this mode's on this frame: the
    /// inverse of the median over [`PAIRS`] runs of this mode's wall time
    /// divided by that of a reference run beside it (alternately before and
    /// after), so that both are timed at the same moment of a shared machine.
    speed_vs_reference: Option<f64>,
    /// Against this frame's reference (with `--compare`).
    metrics: Option<Metrics>,
    /// FLIP's weighted quartiles (the errors below which 25, 50 and 75% of
    /// the summed error lies) and its histogram in 20 bins over [0, 1], as
    /// FLIP's tool and VALAR report them (with `--compare`).
    flip_weighted_quartiles: Option<[f32; 3]>,
    flip_histogram: Option<Vec<u64>>,
    /// [`mean_change`] from this mode's previous frame (none on frame 0).
    change: Option<f64>,
    /// `change` minus the reference's own change over the same frames:
    /// above 0, the mode changes more from frame to frame than the
    /// reference does (flicker); below 0, less (it smooths the motion).
    flicker: Option<f64>,
    /// Rate-image mode: the rates this frame was shaded at.
    rates: Option<RateFrame>,
}

#[derive(serde::Serialize)]
struct RateFrame {
    /// Tiles at each rate, finest first.
    histogram: Vec<(String, usize)>,
    /// Shading cells per pixel the rate image asks for.
    fraction: f64,
    /// Wall time of the rate source's pass that made them, in ms (none:
    /// the first frame, which has no previous frame and shades at full rate).
    source_ms: Option<f64>,
}

#[derive(serde::Serialize)]
struct Frame {
    frame: usize,
    eye: [f32; 3],
    target: [f32; 3],
    /// Mean and largest length of the velocity channel, in pixels.
    mean_speed_px: f64,
    max_speed_px: f64,
    modes: Vec<ModeFrame>,
}

/// Means over frames, per mode.
#[derive(serde::Serialize)]
struct Summary {
    mode: Mode,
    shaded_fraction: f64,
    wall_ms: f64,
    psnr: Option<f64>,
    mssim: Option<f64>,
    flip: Option<f64>,
    /// Over frames 1 to N − 1.
    flicker: Option<f64>,
}

#[derive(serde::Serialize)]
struct FramesFile {
    program: String,
    scene: String,
    size: (u32, u32),
    frames: usize,
    camera_path: String,
    /// The rate source's options (motion and reprojection on).
    rate_sensitivity: f32,
    rate_tile: u32,
    per_frame: Vec<Frame>,
    summary: Vec<Summary>,
}

/// Renders `n` frames along the scene's camera path; returns the paths written.
pub fn render_frames(session: &mut Session, args: &RenderArgs, n: usize) -> Result<Vec<PathBuf>> {
    let Session { gpu, program, name, stem, scene, shader, resources, .. } = session;
    let path = scene.path.as_ref().ok_or_else(|| anyhow!(no_path(&args.scene)))?;
    let mesh = scene.mesh.as_ref().ok_or_else(|| anyhow!(no_path(&args.scene)))?;
    let first_output = &resources.outputs.first().context("the program has no output")?.1;
    let float_output = first_output.format() == wgpu::TextureFormat::Rgba32Float;
    if (args.compare || args.modes.contains(&Mode::RateImage)) && !float_output {
        bail!("--frames with --compare or the rate-image mode needs the first output to be rgba32float");
    }
    // The eye follows the camera where the program takes it, unless the
    // scene file or `--set` gave `camera_pos` a value of its own.
    let camera_pos_fixed = args.sets.iter().any(|(n, _)| n == "camera_pos")
        || scene.file.as_ref().is_some_and(|f| f.uniforms.iter().any(|(n, _)| n == "camera_pos"));
    let follow_eye = !camera_pos_fixed
        && matches!(
            mrsl_lab::uniforms::check(shader.layout(), "the camera path", "camera_pos", &Offered::float3()),
            Ok(Verdict::Bind)
        );
    let modes = crate::render::runnable_modes(args, shader)?;
    let mut sequence = Sequence::new(gpu, args, &modes, stem, resources, first_output, mesh)?;
    sequence.follow_eye = follow_eye;
    sequence.float_output = float_output;
    let size = resources.size;
    eprintln!(
        "{n} frames of {name} along the {} camera path of {} at {}x{}{}",
        path.describe(),
        args.scene,
        size.0,
        size.1,
        if args.modes.contains(&Mode::RateImage) {
            " (rate-image: rates from the previous frame and its motion vectors; frames 0 and 1 are full rate: \
             no previous frame, then the rate source's first decision)"
        } else {
            ""
        }
    );
    let mut frames: Vec<Frame> = vec![];
    for k in 0..n {
        let camera = path.camera(&mesh.camera, k, n);
        frames.push(sequence.frame(shader, program, camera, k, n)?);
    }
    let summary = summarise(&frames);
    print_summary(&summary, n);
    let file = FramesFile {
        program: name.to_string(),
        scene: args.scene.clone(),
        size,
        frames: n,
        camera_path: path.describe(),
        rate_sensitivity: sequence.rate_options.sensitivity,
        rate_tile: sequence.rate_options.tile,
        per_frame: frames,
        summary,
    };
    let json_path = args.out_dir.join(format!("{stem}.frames.json"));
    crate::output::write(&json_path, serde_json::to_string_pretty(&file)?)?;
    let mut written = sequence.written;
    written.push(json_path);
    Ok(written)
}

/// The frame loop's state: what every frame shares, and what the next one
/// takes from the last (its camera for the motion vectors, its G-buffer's
/// velocity and output for the rate source, each mode's image for the change).
struct Sequence<'a> {
    gpu: &'a Gpu,
    args: &'a RenderArgs,
    stem: &'a str,
    resources: &'a Resources,
    mesh: &'a MeshScene,
    first_output: &'a wgpu::Texture,
    float_output: bool,
    follow_eye: bool,
    /// The modes in the order they run: the reference first when it is
    /// compared with or asked for.
    order: Vec<Mode>,
    /// The rate source's options: motion and reprojection as the command line says.
    rate_options: RateOptions,
    source: RateSource,
    /// The rate-image mode's previous output, kept apart from the shared
    /// output textures that the other modes overwrite.
    history: wgpu::Texture,
    previous_camera: Option<Camera>,
    previous_channels: Option<Vec<(String, wgpu::Texture)>>,
    previous_pixels: Vec<(Mode, Vec<[f32; 4]>)>,
    written: Vec<PathBuf>,
}

/// The reference's run of the frame being rendered: its image, its wall
/// time and its change from the previous frame.
type ReferenceRun = (Vec<[f32; 4]>, f64, Option<f64>);

impl<'a> Sequence<'a> {
    fn new(
        gpu: &'a Gpu,
        args: &'a RenderArgs,
        modes: &[Mode],
        stem: &'a str,
        resources: &'a Resources,
        first_output: &'a wgpu::Texture,
        mesh: &'a MeshScene,
    ) -> Result<Sequence<'a>> {
        let with_reference = args.compare || modes.contains(&Mode::Reference);
        let mut order: Vec<Mode> = modes.iter().copied().filter(|m| *m != Mode::Reference).collect();
        if with_reference {
            order.insert(0, Mode::Reference);
        }
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
        let history =
            gpu.texture_2d("mrsl previous rate-image frame", resources.size, wgpu::TextureFormat::Rgba32Float, usage);
        Ok(Sequence {
            gpu,
            args,
            stem,
            resources,
            mesh,
            first_output,
            float_output: true,
            follow_eye: false,
            order,
            rate_options: RateOptions { motion: args.motion, reproject: args.motion, ..args.rates },
            source: RateSource::new(&gpu.device)?,
            history,
            previous_camera: None,
            previous_channels: None,
            previous_pixels: vec![],
            written: vec![],
        })
    }

    /// Frame `k` of `n` from `camera`: its G-buffer with motion vectors, and every mode over it.
    fn frame(
        &mut self,
        shader: &mut Shader,
        program: &mrsl::Program,
        camera: Camera,
        k: usize,
        n: usize,
    ) -> Result<Frame> {
        let (gpu, size) = (self.gpu, self.resources.size);
        let start = Instant::now();
        let channels = self
            .mesh
            .gbuffer_moving(gpu, &camera, self.previous_camera.as_ref(), size)
            .map_err(|e| anyhow!("frame {k}: {e}"))?;
        let velocity = &channels.iter().find(|(n, _)| n == "velocity").context("the G-buffer has no velocity")?.1;
        let (mean_speed_px, max_speed_px) = speeds(gpu, velocity)?;
        if self.follow_eye {
            shader.set_uniform("camera_pos", &camera.eye.map(f64::from))?;
        }
        let bindings = self.resources.bindings(program, &channels);
        let mut runs: Vec<ModeFrame> = vec![];
        let mut reference: Option<ReferenceRun> = None;
        let mut pixels_now: Vec<(Mode, Vec<[f32; 4]>)> = vec![];
        for mode in self.order.clone() {
            let (run, pixels) = self.mode_frame(shader, &bindings, mode, k, &mut reference)?;
            pixels_now.push((mode, pixels));
            runs.push(run);
        }
        eprintln!("{}", progress_line(k, n, &runs, mean_speed_px, start));
        let asked_for_reference = self.args.modes.contains(&Mode::Reference);
        let modes = runs.into_iter().filter(|r| r.mode != Mode::Reference || asked_for_reference).collect();
        self.previous_pixels = pixels_now;
        self.previous_camera = Some(camera);
        self.previous_channels = Some(channels);
        Ok(Frame { frame: k, eye: camera.eye, target: camera.target, mean_speed_px, max_speed_px, modes })
    }

    /// One mode's run of frame `k`: its rates (the rate-image mode), its
    /// timing (paired with the reference's when that ran first), its images,
    /// and its figures against `reference` (which the reference mode sets).
    /// Returns the figures and the image.
    fn mode_frame(
        &mut self,
        shader: &mut Shader,
        bindings: &Bindings,
        mode: Mode,
        k: usize,
        reference: &mut Option<ReferenceRun>,
    ) -> Result<(ModeFrame, Vec<[f32; 4]>)> {
        let gpu = self.gpu;
        let source_ms = if mode == Mode::RateImage && k > 0 { self.decide_rates()? } else { None };
        let dispatch = dispatch_options(self.args, mode);
        let (wall_ms, paired_speed) = self.wall_time(shader, bindings, dispatch, k, reference.is_some())?;
        // The image and statistics below are this mode's, from an untimed run.
        time_run(gpu, shader, bindings, dispatch)?;
        let stats = shader.read_stats(&gpu.device)?;
        let pixels = if self.float_output { gpu.read_rgba32f(self.first_output)? } else { vec![] };
        let rates = if mode == Mode::RateImage { Some(self.record_rates(&pixels, k, source_ms)?) } else { None };
        if mode != Mode::Reference || self.args.modes.contains(&Mode::Reference) {
            self.save_outputs(mode, k)?;
        }
        let change = self.previous_pixels.iter().find(|(m, _)| *m == mode).map(|(_, p)| mean_change(&pixels, p));
        let (metrics, speed_vs_reference, flicker) = match reference.as_ref() {
            Some((reference, reference_ms, reference_change)) if mode != Mode::Reference => {
                let metrics = if self.args.compare {
                    let size = self.resources.size;
                    Some(mrsl_lab::metrics::compare_with_flip_map(&pixels, reference, size.0, size.1)?)
                } else {
                    None
                };
                let flicker = change.zip(*reference_change).map(|(c, r)| c - r);
                (metrics, paired_speed.or(Some(reference_ms / wall_ms)), flicker)
            }
            _ => (None, None, None),
        };
        let (metrics, flip_weighted_quartiles, flip_histogram) = match metrics {
            Some((m, map)) => (Some(m), Some(map.weighted_quartiles()), Some(map.histogram(20))),
            None => (None, None, None),
        };
        if mode == Mode::Reference {
            *reference = Some((pixels.clone(), wall_ms, change));
        }
        let run = ModeFrame {
            mode,
            shaded_fraction: stats.shaded_fraction,
            wall_ms,
            speed_vs_reference,
            metrics,
            flip_weighted_quartiles,
            flip_histogram,
            change,
            flicker,
            rates,
        };
        Ok((run, pixels))
    }

    /// This frame's rates, from the previous frame's output and the motion
    /// that frame had (the estimate of this one's); the rate source's wall
    /// time in ms. `None` before there is a previous frame.
    fn decide_rates(&mut self) -> Result<Option<f64>> {
        let gpu = self.gpu;
        let Some(previous) = &self.previous_channels else { return Ok(None) };
        let previous_velocity = &previous.iter().find(|(n, _)| n == "velocity").expect("checked above").1;
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let inputs = RateInputs { velocity: Some(previous_velocity), ..RateInputs::new(&self.history) };
        self.source.encode(&gpu.device, &mut encoder, &inputs, &self.rate_options, &self.resources.shading_rate)?;
        gpu.queue.submit([encoder.finish()]);
        gpu.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(Some(start.elapsed().as_secs_f64() * 1e3))
    }

    /// Warm wall time without instrumentation (the first frame's first run
    /// builds pipelines and is not timed); with the reference run first on
    /// this frame, the median of [`PAIRS`] runs paired with it, and the
    /// reference's speed relative to this mode's.
    fn wall_time(
        &self,
        shader: &mut Shader,
        bindings: &Bindings,
        dispatch: DispatchOptions,
        k: usize,
        reference_ran: bool,
    ) -> Result<(f64, Option<f64>)> {
        let gpu = self.gpu;
        let timed = dispatch.uninstrumented();
        if k == 0 {
            time_run(gpu, shader, bindings, timed)?;
        }
        let wall_ms = time_run(gpu, shader, bindings, timed)?;
        if dispatch.mode == Mode::Reference || !reference_ran {
            return Ok((wall_ms, None));
        }
        let reference = DispatchOptions { mode: Mode::Reference, ..timed };
        let p = paired(PAIRS, timed, reference, |o| time_run(gpu, shader, bindings, o))?;
        Ok((median(p.walls), Some(1.0 / median(p.ratios))))
    }

    /// Keeps the rate-image mode's output for the next frame's rate source,
    /// writes the rates it was shaded at over it, and counts them.
    fn record_rates(&mut self, pixels: &[[f32; 4]], k: usize, source_ms: Option<f64>) -> Result<RateFrame> {
        let (gpu, size, tile) = (self.gpu, self.resources.size, self.rate_options.tile);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_texture(
            self.first_output.as_image_copy(),
            self.history.as_image_copy(),
            self.first_output.size(),
        );
        gpu.queue.submit([encoder.finish()]);
        let tiles = read_rate_image(&gpu.device, &gpu.queue, &self.resources.shading_rate)?;
        let file = self.args.out_dir.join(format!("{}.rate-image.rates.f{k:03}.png", self.stem));
        save_rates(pixels, size, &tiles, tile, &file)?;
        self.written.push(file);
        let histogram =
            ShadingRate::ALL.iter().map(|&r| (r.to_string(), tiles.iter().filter(|t| **t == r).count())).collect();
        let fraction = rate_fraction(&tiles, size, tile).unwrap_or(f64::NAN);
        Ok(RateFrame { histogram, fraction, source_ms })
    }

    /// The mode's outputs of frame `k`: `STEM.MODE.fNNN.png`, outputs after
    /// the first with their name.
    fn save_outputs(&mut self, mode: Mode, k: usize) -> Result<()> {
        for (j, (output, texture)) in self.resources.outputs.iter().enumerate() {
            let file = match j {
                0 => self.args.out_dir.join(format!("{}.{mode}.f{k:03}.png", self.stem)),
                _ => self.args.out_dir.join(format!("{}.{mode}.f{k:03}.{output}.png", self.stem)),
            };
            save_output(self.gpu, texture, &file)?;
            self.written.push(file);
        }
        Ok(())
    }
}

/// One line per mode: its means over the frames.
fn print_summary(summary: &[Summary], n: usize) {
    for s in summary {
        let metric = |name: &str, v: Option<f64>, digits: usize| v.map(|v| format!(", {name} {v:.digits$}"));
        eprintln!(
            "{} over {n} frames: shaded {:.1}%, {:.1} ms{}{}{}{}",
            s.mode,
            100.0 * s.shaded_fraction,
            s.wall_ms,
            metric("PSNR", s.psnr, 2).unwrap_or_default(),
            metric("MSSIM", s.mssim, 4).unwrap_or_default(),
            metric("FLIP", s.flip, 4).unwrap_or_default(),
            metric("flicker", s.flicker, 5).unwrap_or_default(),
        );
    }
}

/// Mean and largest length of a velocity texture (`Rg32Float`), in pixels.
fn speeds(gpu: &Gpu, velocity: &wgpu::Texture) -> Result<(f64, f64)> {
    let v: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(velocity)?);
    let lengths: Vec<f64> = v.iter().map(|p| f64::from(p[0]).hypot(f64::from(p[1]))).collect();
    let mean = lengths.iter().sum::<f64>() / lengths.len().max(1) as f64;
    Ok((mean, lengths.iter().copied().fold(0.0, f64::max)))
}

/// `frame 3/8 (12.5 px/frame): rate-image shaded 41.2%, 812 ms, ...`.
fn progress_line(k: usize, n: usize, runs: &[ModeFrame], speed: f64, start: Instant) -> String {
    let parts: Vec<String> = runs
        .iter()
        .map(|r| {
            let mut s = format!("{} shaded {:.1}%, {:.1} ms", r.mode, 100.0 * r.shaded_fraction, r.wall_ms);
            if let Some(m) = &r.metrics {
                s += &format!(", PSNR {:.2} dB, MSSIM {:.4}, FLIP {:.4}", m.psnr, m.mssim, m.flip);
            }
            if let Some(f) = r.flicker {
                s += &format!(", flicker {f:+.5}");
            }
            if let Some(rates) = &r.rates {
                s += &format!(", rates ask {:.1}% of the cells", 100.0 * rates.fraction);
            }
            s
        })
        .collect();
    format!(
        "frame {}/{n} (mean motion {speed:.1} px, {:.0} ms): {}",
        k + 1,
        start.elapsed().as_secs_f64() * 1e3,
        parts.join("; ")
    )
}

fn summarise(frames: &[Frame]) -> Vec<Summary> {
    let Some(first) = frames.first() else { return vec![] };
    let mean = |values: Vec<f64>| (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64);
    first
        .modes
        .iter()
        .map(|m| {
            let runs: Vec<&ModeFrame> =
                frames.iter().flat_map(|f| f.modes.iter().filter(|r| r.mode == m.mode)).collect();
            let metric = |f: fn(&Metrics) -> f64| mean(runs.iter().filter_map(|r| r.metrics.as_ref().map(f)).collect());
            Summary {
                mode: m.mode,
                shaded_fraction: mean(runs.iter().map(|r| r.shaded_fraction).collect()).unwrap_or(f64::NAN),
                wall_ms: mean(runs.iter().map(|r| r.wall_ms).collect()).unwrap_or(f64::NAN),
                // Identical frames have an infinite PSNR: the mean of the finite ones.
                psnr: mean(
                    runs.iter().filter_map(|r| r.metrics.as_ref().map(|m| m.psnr)).filter(|p| p.is_finite()).collect(),
                ),
                mssim: metric(|m| m.mssim),
                flip: metric(|m| m.flip),
                flicker: mean(runs.iter().filter_map(|r| r.flicker).collect()),
            }
        })
        .collect()
}

/// The rate visualisation: the frame dimmed to half its brightness, each
/// tile not at 1x1 tinted half-way to its rate's colour
/// ([`legend::rate_color`]), and the key below.
fn save_rates(pixels: &[[f32; 4]], size: (u32, u32), tiles: &[ShadingRate], tile: u32, path: &Path) -> Result<()> {
    let columns = size.0.div_ceil(tile);
    let image = image::RgbImage::from_fn(size.0, size.1, |x, y| {
        let p = pixels.get((y * size.0 + x) as usize).copied().unwrap_or([0.0; 4]);
        let dimmed = [0, 1, 2].map(|c| linear_to_srgb8(p[c]) / 2);
        let rate = tiles.get(((y / tile) * columns + x / tile) as usize).copied().unwrap_or(ShadingRate::R1x1);
        image::Rgb(match legend::rate_color(rate) {
            None => dimmed,
            Some(color) => [0, 1, 2].map(|c| ((u16::from(dimmed[c]) + u16::from(color[c])) / 2) as u8),
        })
    });
    save_image(&legend::with_legend(&image, &Legend::Rates { tile })?, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_a_whole_number_from_one() {
        assert_eq!(parse_frames("8"), Ok(8));
        assert_eq!(parse_frames("1"), Ok(1));
        assert_eq!(parse_frames(&MAX_FRAMES.to_string()), Ok(MAX_FRAMES));
        for bad in ["0", "-3", "2.5", "", "eight", "1001"] {
            let e = parse_frames(bad).unwrap_err();
            assert!(e.contains("from 1 to 1000") && e.contains(&format!("`{bad}`")), "{bad}: {e}");
        }
    }

    #[test]
    fn change_is_the_mean_absolute_difference_over_rgb() {
        let a = vec![[0.0, 0.5, 1.0, 1.0]; 4];
        assert_eq!(mean_change(&a, &a), 0.0);
        // One channel of one pixel moves by 0.6: 0.6 / 12. Alpha does not count.
        let mut b = a.clone();
        b[2][1] = 1.1; // clamped to 1: a change of 0.5
        b[3][3] = 0.0;
        assert!((mean_change(&a, &b) - 0.5 / 12.0).abs() < 1e-12);
    }

    #[test]
    fn scenes_without_a_path_are_named_with_the_way_out() {
        let e = no_path("demo");
        assert!(e.contains("`demo`") && e.contains("--scene sponza") && e.contains("camera_path"), "{e}");
    }
}
