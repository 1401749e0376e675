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

use crate::legend::{self, Legend};
use crate::render::{BoundScene, PAIRS, RenderArgs, Resources, median, save_output, time_run};
use mrsl_abi::ShadingRate;
use mrsl_lab::camera::Camera;
use mrsl_lab::color::linear_to_srgb8;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::metrics::Metrics;
use mrsl_lab::uniforms::{Offered, Verdict};
use mrsl_runtime::rate_source::{RateInputs, RateOptions, RateSource, rate_fraction, read_rate_image};
use mrsl_runtime::{DispatchOptions, Mode, Shader};
use std::path::PathBuf;
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
    mode: String,
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
    mode: String,
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

/// What the frame loop needs from `render`'s set-up.
pub struct Setup<'a> {
    pub gpu: &'a Gpu,
    pub program: &'a mrsl::Program,
    pub name: &'a str,
    pub stem: &'a str,
    pub scene: &'a BoundScene,
    pub resources: &'a Resources,
}

/// Renders `n` frames along the scene's camera path; returns the paths written.
pub fn render_frames(setup: &Setup, shader: &mut Shader, args: &RenderArgs, n: usize) -> Result<Vec<PathBuf>, String> {
    let Setup { gpu, program, name, stem, scene, resources } = *setup;
    let path = scene.path.as_ref().ok_or_else(|| no_path(&args.scene))?;
    let mesh = scene.mesh.as_ref().ok_or_else(|| no_path(&args.scene))?;
    let size = resources.size;
    let base = mesh.camera;
    let in_out = |file: String| args.out_dir.join(file);
    let first_output = &resources.outputs.first().ok_or("the program has no output")?.1;
    let float_output = first_output.format() == wgpu::TextureFormat::Rgba32Float;
    if (args.compare || args.modes.contains(&Mode::RateImage)) && !float_output {
        return Err("--frames with --compare or the rate-image mode needs the first output to be rgba32float".into());
    }
    // The reference runs first when it is compared with or asked for.
    let with_reference = args.compare || args.modes.contains(&Mode::Reference);
    let mut order: Vec<Mode> = args.modes.iter().copied().filter(|m| *m != Mode::Reference).collect();
    if with_reference {
        order.insert(0, Mode::Reference);
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
    let rate_options = RateOptions { motion: args.motion, reproject: args.motion, ..args.rates };
    let mut source = RateSource::new(&gpu.device).map_err(|e| e.to_string())?;
    // The rate-image mode's previous output, kept apart from the shared
    // output textures that the other modes overwrite.
    let history = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("mrsl previous rate-image frame"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
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
    let mut written = vec![];
    let mut frames: Vec<Frame> = vec![];
    let mut previous_camera: Option<Camera> = None;
    let mut previous_channels: Option<Vec<(String, wgpu::Texture)>> = None;
    let mut previous_pixels: Vec<(Mode, Vec<[f32; 4]>)> = vec![];
    for k in 0..n {
        let start = Instant::now();
        let camera = path.camera(&base, k, n);
        let channels =
            mesh.gbuffer_moving(gpu, &camera, previous_camera.as_ref(), size).map_err(|e| format!("frame {k}: {e}"))?;
        let velocity = &channels.iter().find(|(n, _)| n == "velocity").ok_or("the G-buffer has no velocity")?.1;
        let (mean_speed_px, max_speed_px) = speeds(gpu, velocity)?;
        if follow_eye {
            shader.set_uniform("camera_pos", &camera.eye.map(f64::from)).map_err(|e| e.to_string())?;
        }
        let bindings = resources.bindings(program, &channels);
        let mut runs: Vec<ModeFrame> = vec![];
        let mut reference: Option<(Vec<[f32; 4]>, f64, Option<f64>)> = None;
        let mut pixels_now: Vec<(Mode, Vec<[f32; 4]>)> = vec![];
        for &mode in &order {
            let dispatch = DispatchOptions {
                force_refine: args.force_refine,
                similarity: args.similarity,
                rate_tile: rate_options.tile,
                ..DispatchOptions::new(mode)
            };
            let mut source_ms = None;
            if mode == Mode::RateImage
                && let (Some(previous), true) = (&previous_channels, k > 0)
            {
                // This frame's rates, from the previous frame's output and
                // the motion that frame had (the estimate of this one's).
                let previous_velocity = &previous.iter().find(|(n, _)| n == "velocity").expect("checked above").1;
                let start = Instant::now();
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                let inputs = RateInputs { velocity: Some(previous_velocity), ..RateInputs::new(&history) };
                source
                    .encode(&gpu.device, &mut encoder, &inputs, &rate_options, &resources.shading_rate)
                    .map_err(|e| e.to_string())?;
                gpu.queue.submit([encoder.finish()]);
                gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| e.to_string())?;
                source_ms = Some(start.elapsed().as_secs_f64() * 1e3);
            }
            // Timed runs carry no instrumentation; the statistics come from one more run after them.
            let timed = dispatch.uninstrumented();
            if k == 0 {
                // The first run builds pipelines: time the second.
                time_run(gpu, shader, &bindings, timed)?;
            }
            let mut wall_ms = time_run(gpu, shader, &bindings, timed)?;
            // Paired with reference runs of the same frame, when the reference runs too.
            let mut paired = None;
            if mode != Mode::Reference && reference.is_some() {
                let reference_dispatch = DispatchOptions { mode: Mode::Reference, ..timed };
                let (mut walls, mut ratios) = (vec![], vec![]);
                for pair in 0..PAIRS {
                    let (wall, reference_wall) = if pair % 2 == 0 {
                        let r = time_run(gpu, shader, &bindings, reference_dispatch)?;
                        (time_run(gpu, shader, &bindings, timed)?, r)
                    } else {
                        let w = time_run(gpu, shader, &bindings, timed)?;
                        (w, time_run(gpu, shader, &bindings, reference_dispatch)?)
                    };
                    walls.push(wall);
                    ratios.push(wall / reference_wall);
                }
                wall_ms = median(walls);
                paired = Some(1.0 / median(ratios));
            }
            // The image and statistics below are this mode's, from an untimed run.
            time_run(gpu, shader, &bindings, dispatch)?;
            let stats = shader.read_stats(&gpu.device).map_err(|e| e.to_string())?;
            let pixels = if float_output { gpu.read_rgba32f(first_output).map_err(|e| e.to_string())? } else { vec![] };
            let mut rates = None;
            if mode == Mode::RateImage {
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                encoder.copy_texture_to_texture(
                    first_output.as_image_copy(),
                    history.as_image_copy(),
                    first_output.size(),
                );
                gpu.queue.submit([encoder.finish()]);
                let tiles =
                    read_rate_image(&gpu.device, &gpu.queue, &resources.shading_rate).map_err(|e| e.to_string())?;
                let file = in_out(format!("{stem}.rate-image.rates.f{k:03}.png"));
                save_rates(&pixels, size, &tiles, rate_options.tile, &file)?;
                written.push(file);
                let histogram = ShadingRate::ALL
                    .iter()
                    .map(|&r| (r.to_string(), tiles.iter().filter(|t| **t == r).count()))
                    .collect();
                let fraction = rate_fraction(&tiles, size, rate_options.tile).unwrap_or(f64::NAN);
                rates = Some(RateFrame { histogram, fraction, source_ms });
            }
            if mode != Mode::Reference || args.modes.contains(&Mode::Reference) {
                for (j, (output, texture)) in resources.outputs.iter().enumerate() {
                    let file = match j {
                        0 => in_out(format!("{stem}.{mode}.f{k:03}.png")),
                        _ => in_out(format!("{stem}.{mode}.f{k:03}.{output}.png")),
                    };
                    save_output(gpu, texture, &file)?;
                    written.push(file);
                }
            }
            let change = previous_pixels.iter().find(|(m, _)| *m == mode).map(|(_, p)| mean_change(&pixels, p));
            let (metrics, speed_vs_reference, flicker) = match (&reference, mode) {
                (Some((reference, reference_ms, reference_change)), m) if m != Mode::Reference => {
                    let metrics = if args.compare {
                        Some(
                            mrsl_lab::metrics::compare_with_flip_map(&pixels, reference, size.0, size.1)
                                .map_err(|e| e.to_string())?,
                        )
                    } else {
                        None
                    };
                    let flicker = change.zip(*reference_change).map(|(c, r)| c - r);
                    (metrics, paired.or(Some(reference_ms / wall_ms)), flicker)
                }
                _ => (None, None, None),
            };
            let (metrics, flip_weighted_quartiles, flip_histogram) = match metrics {
                Some((m, map)) => (Some(m), Some(map.weighted_quartiles()), Some(map.histogram(20))),
                None => (None, None, None),
            };
            if mode == Mode::Reference {
                reference = Some((pixels.clone(), wall_ms, change));
            }
            pixels_now.push((mode, pixels));
            runs.push(ModeFrame {
                mode: mode.to_string(),
                shaded_fraction: stats.shaded_fraction,
                wall_ms,
                speed_vs_reference,
                metrics,
                flip_weighted_quartiles,
                flip_histogram,
                change,
                flicker,
                rates,
            });
        }
        eprintln!("{}", progress_line(k, n, &runs, mean_speed_px, start));
        frames.push(Frame {
            frame: k,
            eye: camera.eye,
            target: camera.target,
            mean_speed_px,
            max_speed_px,
            modes: runs
                .into_iter()
                .filter(|r| r.mode != "reference" || args.modes.contains(&Mode::Reference))
                .collect(),
        });
        previous_pixels = pixels_now;
        previous_camera = Some(camera);
        previous_channels = Some(channels);
    }
    let summary = summarise(&frames);
    for s in &summary {
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
    let file = FramesFile {
        program: name.to_string(),
        scene: args.scene.clone(),
        size,
        frames: n,
        camera_path: path.describe(),
        rate_sensitivity: rate_options.sensitivity,
        rate_tile: rate_options.tile,
        per_frame: frames,
        summary,
    };
    let json_path = in_out(format!("{stem}.frames.json"));
    std::fs::write(&json_path, serde_json::to_string_pretty(&file).map_err(|e| e.to_string())?)
        .map_err(|e| format!("cannot write {}: {e}", json_path.display()))?;
    written.push(json_path);
    Ok(written)
}

/// The error for a scene without a camera path.
pub fn no_path(scene: &str) -> String {
    format!(
        "--frames needs a camera path, and scene `{scene}` has none: use --scene sponza (its default walk) or a \
         scene file with `camera_path = \"walk\"` or [[camera_path]] keyframes (docs/scenes.md)"
    )
}

/// Mean and largest length of a velocity texture (`Rg32Float`), in pixels.
fn speeds(gpu: &Gpu, velocity: &wgpu::Texture) -> Result<(f64, f64), String> {
    let bytes = gpu.read_texture(velocity).map_err(|e| e.to_string())?;
    let v: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    let lengths: Vec<f64> = v.chunks_exact(2).map(|p| f64::from(p[0]).hypot(f64::from(p[1]))).collect();
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
                mode: m.mode.clone(),
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
fn save_rates(
    pixels: &[[f32; 4]],
    size: (u32, u32),
    tiles: &[ShadingRate],
    tile: u32,
    path: &std::path::Path,
) -> Result<(), String> {
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
    legend::with_legend(&image, &Legend::Rates { tile })?
        .save(path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
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
