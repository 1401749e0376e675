//! `mrslc render`: runs a program over a scene with the wgpu runtime and
//! writes the image, a refinement heatmap and statistics.

use crate::legend::{self, Legend};
use mrsl::Options;
use mrsl_lab::camera_path::CameraPath;
use mrsl_lab::color::linear_to_srgb8;
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
    /// Where files without an explicit path (`-o`, `--heatmap`) go.
    pub out_dir: PathBuf,
    pub stats: bool,
    pub force_refine: bool,
    /// Compare each mode's first output with the reference: metrics and an error image.
    pub compare: bool,
    /// The hierarchical mode's similarity threshold.
    pub similarity: f32,
    /// The rate-image mode's rate source.
    pub rates: mrsl_runtime::rate_source::RateOptions,
    /// The rate-image mode at one rate everywhere instead of the rate source's.
    pub uniform_rate: Option<mrsl_abi::ShadingRate>,
    /// With `--frames`: whether the rate source reads the motion vectors.
    pub motion: bool,
    /// `--frames N`: N frames along the scene's camera path (see
    /// [`crate::frames`]) instead of a still frame.
    pub frames: Option<usize>,
}

/// One mode's run, as written to the stats JSON.
#[derive(serde::Serialize)]
struct Run {
    #[serde(flatten)]
    stats: Stats,
    /// Against the reference image (with `--compare`).
    metrics: Option<mrsl_lab::metrics::Metrics>,
    /// Warm wall time from submission to idle, in ms (the median of the
    /// paired runs with `--compare`).
    wall_ms: f64,
    /// With `--compare`: the median over [`PAIRS`] runs of this mode's wall
    /// time divided by that of a reference run next to it.
    relative_to_reference: Option<f64>,
}

/// Runs of each mode paired with reference runs for the timing of
/// `--compare` (alternately before and after), so that the ratio is taken
/// between runs at the same moment of a shared machine.
pub(crate) const PAIRS: usize = 3;

/// One warm run of `options`, from encoding to idle: its wall time in ms.
pub(crate) fn time_run(
    gpu: &Gpu,
    shader: &mut Shader,
    bindings: &Bindings,
    options: DispatchOptions,
) -> Result<f64, String> {
    let start = Instant::now();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, options).map_err(|e| e.to_string())?;
    gpu.queue.submit([encoder.finish()]);
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| e.to_string())?;
    Ok(start.elapsed().as_secs_f64() * 1e3)
}

pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
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
    let options = Options { file_name: name.clone(), ..Options::for_modes(modes) };
    let program = mrsl::compile(&source, &options).map_err(|d| mrsl::render_all(&d, &name, &source))?;
    Ok((name, program))
}

/// Runs the render; returns the paths written.
pub fn render(args: &RenderArgs) -> Result<Vec<PathBuf>, String> {
    if args.frames.is_some() && (args.output.is_some() || args.heatmap.is_some()) {
        return Err("--frames names its files OUT/PROGRAM.MODE.fNNN.png: leave out -o and --heatmap".into());
    }
    let stem = args.program.as_ref().and_then(|p| p.file_stem()).and_then(|s| s.to_str()).unwrap_or("demo").to_string();
    let start = Instant::now();
    // The kernels of the modes that run: those asked for, and the reference to compare with.
    let mut modes = args.modes.clone();
    if args.compare && !modes.contains(&Mode::Reference) {
        modes.push(Mode::Reference);
    }
    if args.program.is_none() {
        eprintln!(
            "program: the built-in demo, examples/demo.mrsl (give a .mrsl file to render another; \
             examples/sponza_lights.mrsl uses the light rig of mesh scenes)"
        );
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
    if args.frames.is_some() && scene.path.is_none() {
        return Err(crate::frames::no_path(&args.scene));
    }
    let mut shader = Shader::new(&gpu.device, &program).map_err(|e| e.to_string())?;
    shader.set_timestamp_period(&gpu.queue);
    // The scene's uniforms, then the command line's.
    let textures = scene.prepare(&gpu, &mut shader).map_err(|e| format!("{}: {e}", args.scene))?.warn();
    let channels = std::mem::take(&mut scene.channels);
    for (name, values) in &args.sets {
        shader.set_uniform(name, values).map_err(|e| e.to_string())?;
    }
    let resources = Resources::new(&gpu, &program, size, textures, args.rates.tile)?;
    resources.note_fallbacks();
    // Created only now, so that a run that fails before rendering leaves nothing behind.
    std::fs::create_dir_all(&args.out_dir).map_err(|e| format!("cannot create {}: {e}", args.out_dir.display()))?;
    if let Some(n) = args.frames {
        let setup = crate::frames::Setup {
            gpu: &gpu,
            program: &program,
            name: &name,
            stem: &stem,
            scene: &scene,
            resources: &resources,
        };
        return crate::frames::render_frames(&setup, &mut shader, args, n);
    }
    let in_out = |file: String| args.out_dir.join(file);
    let outputs = &resources.outputs;
    let bindings = resources.bindings(&program, &channels);

    let mut written = vec![];
    let mut all_stats: Vec<Run> = vec![];
    let options = |mode| DispatchOptions {
        force_refine: args.force_refine,
        similarity: args.similarity,
        rate_tile: args.rates.tile,
        ..DispatchOptions::new(mode)
    };
    let first_output = &outputs.first().ok_or("the program has no output")?.1;
    let comparable = first_output.format() == wgpu::TextureFormat::Rgba32Float;
    if args.compare && !comparable {
        return Err("--compare needs the first output to be rgba32float".into());
    }
    // The reference image the other modes are compared with, rendered first
    // unless it is the first mode that runs.
    let mut reference: Option<Vec<[f32; 4]>> = None;
    if args.compare && args.modes.first() != Some(&Mode::Reference) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader
            .encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options(Mode::Reference))
            .map_err(|e| e.to_string())?;
        gpu.queue.submit([encoder.finish()]);
        reference = Some(gpu.read_rgba32f(first_output).map_err(|e| e.to_string())?);
    }
    // Per-pass timestamps mean nothing on a CPU device: lavapipe writes a
    // timestamp when its queue thread reaches it, so a pass reads as a few
    // microseconds. Wall times are shown instead.
    let cpu_device = gpu.adapter_info.device_type == wgpu::DeviceType::Cpu;
    if cpu_device && (args.stats || args.output.is_none()) {
        eprintln!(
            "note: {} is a CPU device, whose per-pass timestamps are not meaningful; times shown are warm wall times",
            gpu.adapter_info.name
        );
    }
    for &mode in &args.modes {
        match (mode, args.uniform_rate) {
            (Mode::RateImage, Some(rate)) => {
                crate::rates::fill(&gpu, &resources.shading_rate, rate);
                eprintln!("shading rate {rate} everywhere (--uniform-rate)");
            }
            (Mode::RateImage, None) => {
                let start = Instant::now();
                let settled =
                    crate::rates::settle(&gpu, &mut shader, &bindings, first_output, &args.rates, options(mode))?;
                progress(&settled.describe(), start);
            }
            _ => {}
        }
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options(mode)).map_err(|e| e.to_string())?;
        gpu.queue.submit([encoder.finish()]);
        let mut stats = shader.read_stats(&gpu.device).map_err(|e| e.to_string())?;
        if cpu_device {
            stats.timings = None;
        }
        progress(&format!("rendered {mode} (first run, pipelines warming up)"), start);
        // Warm wall time, without instrumentation (the statistics are the
        // first run's); with --compare, paired with reference runs.
        let timed = |mode| options(mode).uninstrumented();
        let (wall_ms, relative_to_reference) = if args.compare && mode != Mode::Reference {
            let (mut walls, mut ratios) = (vec![], vec![]);
            for pair in 0..PAIRS {
                let (wall, reference) = if pair % 2 == 0 {
                    let r = time_run(&gpu, &mut shader, &bindings, timed(Mode::Reference))?;
                    (time_run(&gpu, &mut shader, &bindings, timed(mode))?, r)
                } else {
                    let t = time_run(&gpu, &mut shader, &bindings, timed(mode))?;
                    (t, time_run(&gpu, &mut shader, &bindings, timed(Mode::Reference))?)
                };
                walls.push(wall);
                ratios.push(wall / reference);
            }
            // The images below are this mode's again (the rate image is still the first run's).
            time_run(&gpu, &mut shader, &bindings, timed(mode))?;
            (median(walls), Some(median(ratios)))
        } else {
            (time_run(&gpu, &mut shader, &bindings, timed(mode))?, None)
        };
        match relative_to_reference {
            Some(r) => eprintln!(
                "{mode}: {wall_ms:.1} ms warm wall time, {:.2}x the reference's speed (median of {PAIRS} runs paired with the reference)",
                1.0 / r
            ),
            None => eprintln!("{mode}: {wall_ms:.1} ms warm wall time"),
        }
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
                let path = in_out(format!("{stem}.{mode}.error.png"));
                let error =
                    image::RgbaImage::from_raw(size.0, size.1, error).ok_or("error image has the wrong size")?;
                let error = image::DynamicImage::ImageRgba8(error).to_rgb8();
                let scale = mrsl_lab::metrics::DEFAULT_ERROR_SCALE;
                legend::with_legend(&error, &Legend::Error { scale })?
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
                (None, 0) => in_out(format!("{stem}{suffix}.png")),
                (None, _) => in_out(format!("{stem}{suffix}.{name}.png")),
            };
            save_output(&gpu, texture, &path)?;
            written.push(path);
        }
        if mode != Mode::Reference && !shader.layout().stats.counters.is_empty() {
            let path = match &args.heatmap {
                Some(p) => with_suffix(p, if args.modes.len() > 1 { &suffix } else { "" }),
                None => in_out(format!("{stem}.{mode}.heatmap.png")),
            };
            if let Some(rate) = shader.refine_mask() {
                let counters = shader.layout().stats.counters.clone();
                save_heatmap(&gpu, rate, counters.len(), None, &path)?;
                written.push(path.clone());
                // One map per coarse effect: where that effect was evaluated per pixel.
                for (bit, effect) in counters.iter().enumerate().take(32) {
                    let per_effect = with_suffix(&path, &format!(".{effect}"));
                    save_heatmap(&gpu, rate, counters.len(), Some((bit as u32, effect)), &per_effect)?;
                    written.push(per_effect);
                }
            }
        }
        if args.stats || args.output.is_none() {
            println!("{}", stats.table());
        }
        all_stats.push(Run { stats, metrics, wall_ms, relative_to_reference });
    }
    let stats_path = match &args.output {
        Some(p) => p.with_extension("stats.json"),
        None => in_out(format!("{stem}.stats.json")),
    };
    std::fs::write(&stats_path, serde_json::to_string_pretty(&all_stats).map_err(|e| e.to_string())?)
        .map_err(|e| format!("cannot write {}: {e}", stats_path.display()))?;
    written.push(stats_path);
    Ok(written)
}

/// A scene ready to bind: its G-buffer textures, the image size, the
/// mesh scene (camera, light rig, shadow map) for scenes made of a mesh, and
/// the scene file, if any (its uniforms and images).
pub struct BoundScene {
    pub channels: Vec<(String, wgpu::Texture)>,
    pub size: (u32, u32),
    pub mesh: Option<MeshScene>,
    /// The camera path of `--frames`, if the scene has one.
    pub path: Option<CameraPath>,
    pub file: Option<SceneFile>,
}

impl BoundScene {
    /// Sets the uniforms the scene provides (the mesh scene's rig and
    /// camera, then the scene file's), by name and type, and renders the
    /// shadow map if the program samples `shadow_map`. Returns the textures
    /// to bind by name (the shadow map and the scene file's images) and the
    /// names the program declares with another type, left at its defaults.
    pub fn prepare(&mut self, gpu: &Gpu, shader: &mut Shader) -> Result<Prepared, String> {
        let mut textures = vec![];
        let mut warnings = vec![];
        if let Some(mesh) = &mut self.mesh {
            let applied = mesh.set_uniforms(shader, &mesh.camera.clone()).map_err(|e| e.to_string())?;
            if applied.set.iter().any(|name| name == "shadow_map") {
                textures.push(("shadow_map".to_string(), mesh.shadow_map(gpu).map_err(|e| e.to_string())?.clone()));
            }
            warnings.extend(applied.warnings);
        }
        if let Some(file) = &self.file {
            let bound = file.bind(gpu, shader).map_err(|e| e.to_string())?;
            warnings.extend(bound.applied.warnings);
            textures.extend(bound.textures);
        }
        Ok(Prepared { textures, warnings })
    }
}

/// What [`BoundScene::prepare`] provides besides uniform values.
pub struct Prepared {
    pub textures: Vec<(String, wgpu::Texture)>,
    pub warnings: Vec<mrsl_lab::uniforms::Mismatch>,
}

impl Prepared {
    /// Prints the warnings; returns the textures.
    pub fn warn(self) -> Vec<(String, wgpu::Texture)> {
        for warning in &self.warnings {
            eprintln!("warning: {warning}");
        }
        self.textures
    }
}

/// `--scene`: a built-in scene's name, or a `.toml` scene file (see
/// docs/scenes.md). A scene file's `size` applies unless `--size` was given.
/// What loading a mesh skipped or could not use is printed as warnings.
pub fn bind_scene(gpu: &Gpu, scene: &str, size: Option<(u32, u32)>) -> Result<BoundScene, String> {
    let bound = bind_scene_quietly(gpu, scene, size)?;
    for warning in bound.mesh.iter().flat_map(|m| &m.warnings) {
        eprintln!("warning: {scene}: {warning}");
    }
    Ok(bound)
}

fn bind_scene_quietly(gpu: &Gpu, scene: &str, size: Option<(u32, u32)>) -> Result<BoundScene, String> {
    if let Some(builtin) = Scene::parse(scene) {
        let size = size.unwrap_or(DEFAULT_SIZE);
        let mesh = builtin.mesh_scene(gpu).map_err(|e| e.to_string())?;
        let channels = match &mesh {
            Some(m) => m.gbuffer(gpu, &m.camera, size).map_err(|e| e.to_string())?,
            None => builtin.textures_on(gpu, size.0, size.1).map_err(|e| e.to_string())?,
        };
        return Ok(BoundScene { channels, size, mesh, path: builtin.camera_path(), file: None });
    }
    let path = Path::new(scene);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        let file = SceneFile::load(path).map_err(|e| e.to_string())?;
        // The command line's --size wins over the file's.
        let size = size.or(file.size).unwrap_or(DEFAULT_SIZE);
        let mesh = file.mesh_scene(gpu, size).map_err(|e| e.to_string())?;
        let channels = mesh.gbuffer(gpu, &mesh.camera, size).map_err(|e| format!("{scene}: {e}"))?;
        return Ok(BoundScene { channels, size, mesh: Some(mesh), path: file.path(), file: Some(file) });
    }
    Err(format!("unknown scene `{scene}` (expected {}, or a .toml scene file)", Scene::NAMES.join(", ")))
}

/// What a program binds besides the G-buffer: its outputs, and for each of
/// its textures the scene's texture of that name (the shadow map, a scene
/// file's image), else a procedural checker; every sampler is linear and
/// repeating.
pub struct Resources {
    pub size: (u32, u32),
    pub outputs: Vec<(String, wgpu::Texture)>,
    checker_view: wgpu::TextureView,
    views: Vec<(String, wgpu::TextureView)>,
    /// The program's textures that get the checker.
    checkered: Vec<String>,
    sampler: wgpu::Sampler,
    /// The rate-image mode's shading-rate image (full rate until a rate source writes it).
    pub shading_rate: wgpu::Texture,
}

impl Resources {
    pub fn new(
        gpu: &Gpu,
        program: &mrsl::Program,
        size: (u32, u32),
        textures: Vec<(String, wgpu::Texture)>,
        rate_tile: u32,
    ) -> Result<Resources, String> {
        let shading_rate =
            mrsl_runtime::rate_source::create_rate_image(&gpu.device, size, rate_tile).map_err(|e| e.to_string())?;
        let outputs = program
            .layout
            .outputs
            .iter()
            .map(|o| (o.name.clone(), gpu.output_texture(&o.name, size, mrsl_runtime::wgpu_format(o.format))))
            .collect();
        let views: Vec<(String, wgpu::TextureView)> =
            textures.iter().map(|(name, t)| (name.clone(), t.create_view(&Default::default()))).collect();
        let checkered = program
            .layout
            .textures
            .iter()
            .filter(|t| !views.iter().any(|(name, _)| *name == t.name))
            .map(|t| t.name.clone())
            .collect();
        Ok(Resources {
            size,
            outputs,
            checker_view: checker_texture(gpu).create_view(&Default::default()),
            views,
            checkered,
            sampler: linear_sampler(gpu),
            shading_rate,
        })
    }

    /// Says which textures get the procedural checker, and how to give them an image.
    pub fn note_fallbacks(&self) {
        for name in &self.checkered {
            eprintln!(
                "note: texture `{name}` gets a procedural 64x64 checker (a scene file binds an image to it: \
                 `{name} = \"FILE.png\"` under [uniforms])"
            );
        }
    }

    /// The bindings of `program` over the G-buffer `channels`.
    pub fn bindings<'a>(&'a self, program: &mrsl::Program, channels: &'a [(String, wgpu::Texture)]) -> Bindings<'a> {
        let mut bindings = Bindings { size: self.size, ..Default::default() };
        for (name, texture) in channels {
            bindings.channels.insert(name.clone(), texture);
        }
        for t in &program.layout.textures {
            let view = self.views.iter().find(|(name, _)| *name == t.name).map_or(&self.checker_view, |(_, v)| v);
            bindings.textures.insert(t.name.clone(), view);
        }
        for s in &program.layout.samplers {
            bindings.samplers.insert(s.name.clone(), &self.sampler);
        }
        for (name, texture) in &self.outputs {
            bindings.outputs.insert(name.clone(), texture);
        }
        bindings.shading_rate = Some(&self.shading_rate);
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

pub(crate) fn save_output(gpu: &Gpu, texture: &wgpu::Texture, path: &Path) -> Result<(), String> {
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
        img.put_pixel(
            i as u32 % w,
            i as u32 / w,
            image::Rgba([linear_to_srgb8(p[0]), linear_to_srgb8(p[1]), linear_to_srgb8(p[2]), 255]),
        );
    }
    img.save(path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Colours each pixel by the rate its coarse effects were shaded at, in the
/// style of He et al.'s heatmaps ([`legend::heat`]): blue = every coarse
/// effect resampled from the first (2x2 or 4x4) level, green = some taken
/// from the dynamic mode's 2x2 level, then yellow to red as the fraction
/// evaluated per pixel grows; `only`: one effect's bit (blue, green or red).
/// The key is drawn below the map.
fn save_heatmap(
    gpu: &Gpu,
    rate: &wgpu::Texture,
    effects: usize,
    only: Option<(u32, &str)>,
    path: &Path,
) -> Result<(), String> {
    let (w, h) = (rate.width(), rate.height());
    let bytes = gpu.read_texture(rate).map_err(|e| e.to_string())?;
    let mut img = image::RgbImage::new(w, h);
    let counted = effects.clamp(1, 32) as f32;
    for (i, b) in bytes.chunks_exact(8).enumerate() {
        let mut mask = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let mut level2 = u32::from_le_bytes([b[4], b[5], b[6], b[7]]);
        let mut counted = counted;
        if let Some((bit, _)) = only {
            // A single effect: red where it was evaluated per pixel.
            mask = (mask >> bit) & 1;
            level2 = (level2 >> bit) & 1;
            counted = 1.0;
        }
        let f = mask.count_ones() as f32 / counted;
        img.put_pixel(i as u32 % w, i as u32 / w, image::Rgb(legend::heat(f, level2 != 0)));
    }
    let key = match only {
        Some((_, effect)) => Legend::Effect(effect.to_string()),
        None => Legend::Fraction,
    };
    legend::with_legend(&img, &key)?.save(path).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The modes of `--mode`, in the order given, each once.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeList(pub Vec<Mode>);

/// Parses `--mode`: a comma-separated list of mode names, where `all`
/// stands for every mode in its usual order; every unknown name is
/// reported at once.
pub fn parse_modes(text: &str) -> Result<ModeList, String> {
    let mut modes = vec![];
    let mut unknown = vec![];
    for name in text.split(',').map(str::trim) {
        let named: Vec<Mode> = match name {
            "all" => Mode::ALL.to_vec(),
            _ => match name.parse() {
                Ok(mode) => vec![mode],
                Err(_) => {
                    unknown.push(format!("`{name}`"));
                    continue;
                }
            },
        };
        for mode in named {
            if !modes.contains(&mode) {
                modes.push(mode);
            }
        }
    }
    let expected = format!("{}, or all", Mode::ALL.map(Mode::name).join(", "));
    match unknown.len() {
        0 => Ok(ModeList(modes)),
        1 => Err(format!("unknown mode {} (expected a comma-separated list of {expected})", unknown[0])),
        _ => Err(format!("unknown modes {} (expected a comma-separated list of {expected})", unknown.join(", "))),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_are_a_comma_list_or_all() {
        assert_eq!(parse_modes("coarse4x4"), Ok(ModeList(vec![Mode::Coarse4x4])));
        assert_eq!(
            parse_modes("hierarchical, reference"),
            Ok(ModeList(vec![Mode::Hierarchical, Mode::Reference])),
            "in the order given"
        );
        assert_eq!(parse_modes("all"), Ok(ModeList(Mode::ALL.to_vec())));
        // Each mode once, where it first appears.
        assert_eq!(
            parse_modes("dynamic,all,dynamic"),
            Ok(ModeList(vec![
                Mode::Dynamic,
                Mode::Reference,
                Mode::Coarse2x2,
                Mode::Coarse4x4,
                Mode::Hierarchical,
                Mode::Checkerboard,
                Mode::RateImage
            ]))
        );
    }

    #[test]
    fn unknown_modes_are_named_together() {
        assert_eq!(
            parse_modes("reference,coarse8x8"),
            Err("unknown mode `coarse8x8` (expected a comma-separated list of reference, coarse2x2, coarse4x4, \
                 dynamic, hierarchical, checkerboard, rate-image, or all)"
                .into())
        );
        let e = parse_modes("fast,reference,,slow").unwrap_err();
        assert!(e.starts_with("unknown modes `fast`, ``, `slow` (expected"), "{e}");
    }

    #[test]
    fn outputs_named_after_a_path_take_the_suffix_before_the_extension() {
        assert_eq!(with_suffix(Path::new("out/heat.png"), ".dynamic"), PathBuf::from("out/heat.dynamic.png"));
        assert_eq!(with_suffix(Path::new("heat.png"), ""), PathBuf::from("heat.png"));
    }
}
