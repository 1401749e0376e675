//! `mrslc render`: runs a program over a scene with the wgpu runtime and
//! writes the image, a refinement heatmap and statistics.

use mrsl::Options;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::mesh_scene::MeshScene;
use mrsl_lab::scene::Scene;
use mrsl_lab::scene_file::SceneFile;
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader, Stats};

use std::path::{Path, PathBuf};
use std::time::Instant;

/// Image size when neither `--size` nor a scene file gives one.
pub const DEFAULT_SIZE: (u32, u32) = (960, 540);

/// The built-in demo program (examples/demo.mrsl).
pub const DEMO_PROGRAM: &str = include_str!("../../examples/demo.mrsl");

pub struct RenderArgs {
    pub program: Option<PathBuf>,
    pub scene: String,
    pub modes: Vec<Mode>,
    /// `--size`, if given; else the scene file's size, else 960x540.
    pub size: Option<(u32, u32)>,
    pub sets: Vec<(String, Vec<f64>)>,
    pub output: Option<PathBuf>,
    pub heatmap: Option<PathBuf>,
    pub stats: bool,
    pub force_refine: bool,
    /// Compare each mode's first output with the reference: metrics and an error image.
    pub compare: bool,
    /// The hierarchical mode's similarity threshold.
    pub similarity: f32,
}

/// One mode's run, as written to the stats JSON.
#[derive(serde::Serialize)]
struct Run {
    #[serde(flatten)]
    stats: Stats,
    /// Against the reference image (with `--compare`).
    metrics: Option<mrsl_lab::metrics::Metrics>,
}

fn progress(what: &str, start: Instant) {
    eprintln!("{what} ({:.0} ms)", start.elapsed().as_secs_f64() * 1e3);
}

/// Reads and compiles the program at `path`, or the built-in `(name,
/// source)`, to the kernels of `modes` alone; returns its name for messages
/// and the program, or the diagnostics rendered.
pub fn compile_program(
    path: Option<&Path>,
    builtin: (&str, &str),
    modes: &[Mode],
) -> Result<(String, mrsl::Program), String> {
    let (name, source) = match path {
        Some(path) => (path.display().to_string(), crate::read_source(path)?),
        None => (format!("{} (built in)", builtin.0), builtin.1.to_string()),
    };
    let options = Options { file_name: name.clone(), ..mrsl_runtime::compile_options(modes) };
    let program = mrsl::compile(&source, &options).map_err(|d| mrsl::render_all(&d, &name, &source))?;
    Ok((name, program))
}

/// Runs the render; returns the paths written.
pub fn render(args: &RenderArgs) -> Result<Vec<PathBuf>, String> {
    let stem = args.program.as_ref().and_then(|p| p.file_stem()).and_then(|s| s.to_str()).unwrap_or("demo").to_string();
    let start = Instant::now();
    // The kernels of the modes that run: those asked for, and the reference to compare with.
    let mut modes = args.modes.clone();
    if args.compare && !modes.contains(&Mode::Reference) {
        modes.push(Mode::Reference);
    }
    let (name, program) = compile_program(args.program.as_deref(), ("demo.mrsl", DEMO_PROGRAM), &modes)?;
    progress(&format!("compiled {name}: {} kernels", program.kernels.len()), start);

    let start = Instant::now();
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    progress(&format!("device: {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend), start);
    let start = Instant::now();
    let mut scene = bind_scene(&gpu, &args.scene, args.size)?;
    let size = scene.size;
    progress(&format!("built the {} G-buffer at {}x{}", args.scene, size.0, size.1), start);
    let mut shader = Shader::new(&gpu.device, &program).map_err(|e| e.to_string())?;
    shader.set_timestamp_period(&gpu.queue);
    // The scene's uniforms, then the command line's.
    let shadow_map = scene.prepare(&gpu, &mut shader).map_err(|e| format!("{}: {e}", args.scene))?;
    let channels = scene.channels;
    for (name, values) in &args.sets {
        shader.set_uniform(name, values).map_err(|e| e.to_string())?;
    }
    let resources = Resources::new(&gpu, &program, size, shadow_map);
    let outputs = &resources.outputs;
    let bindings = resources.bindings(&program, &channels);

    let mut written = vec![];
    let mut all_stats: Vec<Run> = vec![];
    let options = |mode| DispatchOptions {
        force_refine: args.force_refine,
        similarity: args.similarity,
        ..DispatchOptions::new(mode)
    };
    let first_output = &outputs.first().ok_or("the program has no output")?.1;
    let comparable = first_output.format() == wgpu::TextureFormat::Rgba32Float;
    if args.compare && !comparable {
        return Err("--compare needs the first output to be rgba32float".into());
    }
    // The reference image the other modes are compared with.
    let mut reference: Option<Vec<[f32; 4]>> = None;
    if args.compare && !args.modes.contains(&Mode::Reference) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader
            .encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options(Mode::Reference))
            .map_err(|e| e.to_string())?;
        gpu.queue.submit([encoder.finish()]);
        reference = Some(gpu.read_rgba32f(first_output).map_err(|e| e.to_string())?);
    }
    for &mode in &args.modes {
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options(mode)).map_err(|e| e.to_string())?;
        gpu.queue.submit([encoder.finish()]);
        let stats = shader.read_stats(&gpu.device).map_err(|e| e.to_string())?;
        progress(&format!("rendered {mode}"), start);
        let mut metrics = None;
        if args.compare {
            let pixels = gpu.read_rgba32f(first_output).map_err(|e| e.to_string())?;
            if mode == Mode::Reference {
                reference = Some(pixels);
            } else if let Some(reference) = &reference {
                let start = Instant::now();
                let m = mrsl_lab::metrics::compare(&pixels, reference, size.0, size.1).map_err(|e| e.to_string())?;
                progress(
                    &format!(
                        "{mode} vs reference: RMSE {:.5}, PSNR {:.2} dB, MSSIM {:.5}, FLIP {:.5}",
                        m.rmse, m.psnr, m.mssim, m.flip
                    ),
                    start,
                );
                let error = mrsl_lab::metrics::error_image(
                    &pixels,
                    reference,
                    size.0,
                    size.1,
                    mrsl_lab::metrics::DEFAULT_ERROR_SCALE,
                )
                .map_err(|e| e.to_string())?;
                let path = PathBuf::from(format!("{stem}.{mode}.error.png"));
                image::RgbaImage::from_raw(size.0, size.1, error)
                    .ok_or("error image has the wrong size")?
                    .save(&path)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                written.push(path);
                metrics = Some(m);
            }
        }
        let suffix = if args.modes.len() > 1 || args.output.is_none() { format!(".{mode}") } else { String::new() };
        for (k, (name, texture)) in outputs.iter().enumerate() {
            let path = match (&args.output, k) {
                (Some(p), 0) => with_suffix(p, &suffix),
                (Some(p), _) => with_suffix(p, &format!("{suffix}.{name}")),
                (None, 0) => PathBuf::from(format!("{stem}{suffix}.png")),
                (None, _) => PathBuf::from(format!("{stem}{suffix}.{name}.png")),
            };
            save_output(&gpu, texture, &path)?;
            written.push(path);
        }
        if mode != Mode::Reference && !shader.layout().stats.counters.is_empty() {
            let path = match &args.heatmap {
                Some(p) => with_suffix(p, if args.modes.len() > 1 { &suffix } else { "" }),
                None => PathBuf::from(format!("{stem}.{mode}.heatmap.png")),
            };
            if let Some(rate) = shader.rate_image() {
                let counters = shader.layout().stats.counters.clone();
                save_heatmap(&gpu, rate, counters.len(), None, &path)?;
                written.push(path.clone());
                // One map per coarse effect: where that effect was evaluated per pixel.
                for (bit, effect) in counters.iter().enumerate().take(32) {
                    let per_effect = with_suffix(&path, &format!(".{effect}"));
                    save_heatmap(&gpu, rate, counters.len(), Some(bit as u32), &per_effect)?;
                    written.push(per_effect);
                }
            }
        }
        if args.stats || args.output.is_none() {
            println!("{}", stats.table());
        }
        all_stats.push(Run { stats, metrics });
    }
    let stats_path = match &args.output {
        Some(p) => p.with_extension("stats.json"),
        None => PathBuf::from(format!("{stem}.stats.json")),
    };
    std::fs::write(&stats_path, serde_json::to_string_pretty(&all_stats).map_err(|e| e.to_string())?)
        .map_err(|e| format!("cannot write {}: {e}", stats_path.display()))?;
    written.push(stats_path);
    Ok(written)
}

/// A scene ready to bind: its G-buffer textures, the image size, the
/// mesh scene (camera, light rig, shadow map) for scenes made of a mesh, and
/// a scene file's uniforms.
pub struct BoundScene {
    pub channels: Vec<(String, wgpu::Texture)>,
    pub size: (u32, u32),
    pub mesh: Option<MeshScene>,
    pub uniforms: Vec<(String, Vec<f64>)>,
}

impl BoundScene {
    /// Sets the uniforms the scene provides (the mesh scene's rig and
    /// camera, then the scene file's), and renders the shadow map if the
    /// program samples `shadow_map`; returns it.
    pub fn prepare(&mut self, gpu: &Gpu, shader: &mut Shader) -> Result<Option<wgpu::Texture>, String> {
        let mut shadow_map = None;
        if let Some(mesh) = &mut self.mesh {
            mesh.set_uniforms(shader, &mesh.camera.clone()).map_err(|e| e.to_string())?;
            if shader.layout().textures.iter().any(|t| t.name == "shadow_map") {
                shadow_map = Some(mesh.shadow_map(gpu).map_err(|e| e.to_string())?.clone());
            }
        }
        for (name, values) in &self.uniforms {
            shader.set_uniform(name, values).map_err(|e| format!("`uniforms.{name}`: {e}"))?;
        }
        Ok(shadow_map)
    }
}

/// `--scene`: a built-in scene's name, or a `.toml` scene file (see
/// docs/scenes.md). A scene file's `size` applies unless `--size` was given.
pub fn bind_scene(gpu: &Gpu, scene: &str, size: Option<(u32, u32)>) -> Result<BoundScene, String> {
    if let Some(builtin) = Scene::parse(scene) {
        let size = size.unwrap_or(DEFAULT_SIZE);
        let mesh = builtin.mesh_scene(gpu).map_err(|e| e.to_string())?;
        let channels = match &mesh {
            Some(m) => m.gbuffer(gpu, &m.camera, size).map_err(|e| e.to_string())?,
            None => builtin.textures_on(gpu, size.0, size.1).map_err(|e| e.to_string())?,
        };
        return Ok(BoundScene { channels, size, mesh, uniforms: vec![] });
    }
    let path = Path::new(scene);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        let file = SceneFile::load(path).map_err(|e| e.to_string())?;
        // The command line's --size wins over the file's.
        let size = size.or(file.size).unwrap_or(DEFAULT_SIZE);
        let mesh = file.mesh_scene(gpu, size).map_err(|e| e.to_string())?;
        let channels = mesh.gbuffer(gpu, &mesh.camera, size).map_err(|e| format!("{scene}: {e}"))?;
        return Ok(BoundScene { channels, size, mesh: Some(mesh), uniforms: file.uniforms.clone() });
    }
    Err(format!("unknown scene `{scene}` (expected {}, or a .toml scene file)", Scene::NAMES.join(", ")))
}

/// What a program binds besides the G-buffer: its outputs, and for its
/// textures the scene's shadow map as `shadow_map` and a procedural checker
/// for any other, with a linear, repeating sampler (scenes carry no
/// material textures yet).
pub struct Resources {
    pub size: (u32, u32),
    pub outputs: Vec<(String, wgpu::Texture)>,
    checker_view: wgpu::TextureView,
    shadow_view: Option<wgpu::TextureView>,
    sampler: wgpu::Sampler,
}

impl Resources {
    pub fn new(gpu: &Gpu, program: &mrsl::Program, size: (u32, u32), shadow_map: Option<wgpu::Texture>) -> Resources {
        let outputs = program
            .layout
            .outputs
            .iter()
            .map(|o| (o.name.clone(), gpu.output_texture(&o.name, size, mrsl_runtime::wgpu_format(o.format))))
            .collect();
        Resources {
            size,
            outputs,
            checker_view: checker_texture(gpu).create_view(&Default::default()),
            shadow_view: shadow_map.map(|t| t.create_view(&Default::default())),
            sampler: linear_sampler(gpu),
        }
    }

    /// The bindings of `program` over the G-buffer `channels`.
    pub fn bindings<'a>(&'a self, program: &mrsl::Program, channels: &'a [(String, wgpu::Texture)]) -> Bindings<'a> {
        let mut bindings = Bindings { size: self.size, ..Default::default() };
        for (name, texture) in channels {
            bindings.channels.insert(name.clone(), texture);
        }
        for t in &program.layout.textures {
            let view = match &self.shadow_view {
                Some(shadow) if t.name == "shadow_map" => shadow,
                _ => &self.checker_view,
            };
            bindings.textures.insert(t.name.clone(), view);
        }
        for s in &program.layout.samplers {
            bindings.samplers.insert(s.name.clone(), &self.sampler);
        }
        for (name, texture) in &self.outputs {
            bindings.outputs.insert(name.clone(), texture);
        }
        bindings
    }
}

/// A linear, repeating sampler (what programs' `sampler` uniforms get).
pub fn linear_sampler(gpu: &Gpu) -> wgpu::Sampler {
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    if suffix.is_empty() {
        return path.to_path_buf();
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    let ext = path.extension().and_then(|s| s.to_str()).unwrap_or("png");
    path.with_file_name(format!("{stem}{suffix}.{ext}"))
}

fn checker_texture(gpu: &Gpu) -> wgpu::Texture {
    let n = 64u32;
    let mut data = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let odd = ((x / 8) + (y / 8)) % 2 == 1;
            let (r, g, b) = if odd { (200, 80, 60) } else { (235, 225, 200) };
            data.extend_from_slice(&[r, g, b, 255]);
        }
    }
    gpu.texture_with_data("checker", (n, n), wgpu::TextureFormat::Rgba8UnormSrgb, &data)
}

/// Linear [0, 1] to an 8-bit sRGB value (the outputs are linear radiance).
fn to_srgb8(v: f32) -> u8 {
    let v = if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 };
    let s = if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

fn save_output(gpu: &Gpu, texture: &wgpu::Texture, path: &Path) -> Result<(), String> {
    let (w, h) = (texture.width(), texture.height());
    let bytes = gpu.read_texture(texture).map_err(|e| e.to_string())?;
    let pixels: Vec<[f32; 4]> = match texture.format() {
        wgpu::TextureFormat::Rgba32Float => gpu.read_rgba32f(texture).map_err(|e| e.to_string())?,
        wgpu::TextureFormat::R32Float => bytes
            .chunks_exact(4)
            .map(|b| {
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                [v, v, v, 1.0]
            })
            .collect(),
        wgpu::TextureFormat::Rgba8Unorm => bytes
            .chunks_exact(4)
            .map(|b| [b[0] as f32 / 255.0, b[1] as f32 / 255.0, b[2] as f32 / 255.0, 1.0])
            .collect(),
        other => return Err(format!("cannot write an output of format {other:?} as PNG yet")),
    };
    let mut img = image::RgbaImage::new(w, h);
    for (i, p) in pixels.iter().enumerate() {
        img.put_pixel(i as u32 % w, i as u32 / w, image::Rgba([to_srgb8(p[0]), to_srgb8(p[1]), to_srgb8(p[2]), 255]));
    }
    img.save(path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Colours each pixel by the rate its coarse effects were shaded at, in the
/// style of He et al.'s heatmaps: blue = every coarse effect resampled from
/// the first (2x2 or 4x4) level, green = some taken from the dynamic mode's
/// 2x2 level, then yellow to red as the fraction evaluated per pixel grows.
fn save_heatmap(gpu: &Gpu, rate: &wgpu::Texture, effects: usize, only: Option<u32>, path: &Path) -> Result<(), String> {
    let (w, h) = (rate.width(), rate.height());
    let bytes = gpu.read_texture(rate).map_err(|e| e.to_string())?;
    let mut img = image::RgbImage::new(w, h);
    let counted = effects.clamp(1, 32) as f32;
    for (i, b) in bytes.chunks_exact(8).enumerate() {
        let mut mask = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let mut level2 = u32::from_le_bytes([b[4], b[5], b[6], b[7]]);
        let mut counted = counted;
        if let Some(bit) = only {
            // A single effect: red where it was evaluated per pixel.
            mask = (mask >> bit) & 1;
            level2 = (level2 >> bit) & 1;
            counted = 1.0;
        }
        let f = mask.count_ones() as f32 / counted;
        let (r, g, bl) = if f <= 0.0 && level2 != 0 {
            (60, 190, 80)
        } else if f <= 0.0 {
            (40, 70, 200)
        } else if f < 0.5 {
            let t = f / 0.5;
            ((40.0 + t * 215.0) as u8, (70.0 + t * 150.0) as u8, (200.0 - t * 160.0) as u8)
        } else {
            let t = (f - 0.5) / 0.5;
            (255, (220.0 - t * 180.0) as u8, 40)
        };
        img.put_pixel(i as u32 % w, i as u32 / w, image::Rgb([r, g, bl]));
    }
    img.save(path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Parses `name=v1,v2,...`.
pub fn parse_set(text: &str) -> Result<(String, Vec<f64>), String> {
    let (name, values) = text.split_once('=').ok_or_else(|| format!("expected NAME=VALUE[,VALUE...], got `{text}`"))?;
    let values = values
        .split(',')
        .map(|v| match v.trim() {
            "true" => Ok(1.0),
            "false" => Ok(0.0),
            v => v.parse::<f64>().map_err(|_| format!("`{v}` is not a number (in `{text}`)")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((name.trim().to_string(), values))
}

/// Parses `WxH`.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{text}`"))?;
    let w: u32 = w.parse().map_err(|_| format!("bad width in `{text}`"))?;
    let h: u32 = h.parse().map_err(|_| format!("bad height in `{text}`"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size `{text}` must be between 1x1 and 16384x16384"));
    }
    Ok((w, h))
}
