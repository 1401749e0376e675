//! Shared device and a `run` helper: one program, one G-buffer, one mode.

use mrsl_abi::KernelRef;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::GBuffer;
use mrsl_runtime::{Bindings, CompiledProgram, DispatchOptions, Error, Mode, Shader, Stats};
use std::sync::OnceLock;

/// The shared device, or `None` when there is no adapter outside CI, after
/// printing why and how many GPU tests will be reported as skipped. Under
/// `CI=true` a missing adapter panics: a failure, not a skip. It also tells
/// the evaluation kit where cargo unpacked the Sponza model.
pub fn gpu(gpu_tests: usize) -> Option<&'static Gpu> {
    static GPU: OnceLock<Option<Gpu>> = OnceLock::new();
    mrsl_lab::fixtures::locate_sponza();
    let gpu = GPU.get_or_init(|| match Gpu::new() {
        Ok(gpu) => {
            println!("render tests on {}", describe_adapter(&gpu.adapter_info));
            Some(gpu)
        }
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => panic!("CI=true but no GPU adapter: {e}"),
        Err(e) => {
            println!(
                "SKIPPING {gpu_tests} render tests (reported as ignored below): no GPU adapter ({e}). \
                 Install Mesa's software Vulkan driver to run them: apt-get install mesa-vulkan-drivers libvulkan1"
            );
            None
        }
    });
    gpu.as_ref()
}

/// The device for a run that must have one (the second-driver subset): a
/// missing adapter is a failure wherever it runs.
pub fn gpu_or_fail() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    mrsl_lab::fixtures::locate_sponza();
    GPU.get_or_init(|| {
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("the requested driver gives no adapter: {e}"));
        println!("render tests on {}", describe_adapter(&gpu.adapter_info));
        gpu
    })
}

/// The adapter's name, driver and backend, as the test output names it.
fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    match info.driver_info.as_str() {
        "" => format!("{} ({:?})", info.name, info.backend),
        driver => format!("{} ({driver}, {:?})", info.name, info.backend),
    }
}

/// What one dispatch produced.
pub struct Output {
    /// The first output, as RGBA floats.
    pub pixels: Vec<[f32; 4]>,
    pub stats: Stats,
    pub width: u32,
}

/// Every mode but the reference, in `Mode::ALL`'s order: what the tests
/// compare with the reference.
pub fn adaptive_modes() -> impl Iterator<Item = Mode> {
    Mode::ALL.into_iter().filter(|m| *m != Mode::Reference)
}

pub fn compile(source: &str) -> mrsl::Program {
    mrsl::compile(source, &mrsl::Options::default())
        .unwrap_or_else(|d| panic!("test program does not compile:\n{}", mrsl::render_all(&d, "test.mrsl", source)))
}

/// Runs `program` over `gbuffer`; uniforms without defaults get `fill`
/// values (a deterministic ramp) so that every example can run. The
/// rate-image mode gets 8x8 tiles with every rate beside every other
/// ([`mrsl_lab::shading_rate::pattern`]).
pub fn run(
    gpu: &Gpu,
    program: &CompiledProgram,
    gbuffer: &GBuffer,
    mode: Mode,
    force_refine: bool,
) -> Result<Output, Error> {
    let size = (gbuffer.width, gbuffer.height);
    let tile = mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
    let rates = mrsl_lab::shading_rate::pattern(mrsl_abi::shading_rate::rate_image_size(size, tile));
    run_at_rates(gpu, program, gbuffer, mode, force_refine, tile, &rates)
}

/// [`run`] with the rate-image mode's tile size and rates (one per tile, row-major) given.
pub fn run_at_rates(
    gpu: &Gpu,
    program: &CompiledProgram,
    gbuffer: &GBuffer,
    mode: Mode,
    force_refine: bool,
    tile: u32,
    rates: &[mrsl_abi::ShadingRate],
) -> Result<Output, Error> {
    let options = DispatchOptions { force_refine, rate_tile: tile, ..DispatchOptions::new(mode) };
    let [dispatch] = dispatch_in_turn(gpu, program, gbuffer, rates, [options])?;
    let Dispatched { pixels, stats, .. } = dispatch;
    Ok(Output { pixels, stats: stats?, width: gbuffer.width })
}

/// Renders `mode` with `shader` over a scene's G-buffer `channels`, the
/// sampled `textures` and `samplers` by name, into a new `rgba32float`
/// output `color` (the rate-image mode at 8x8 tiles with every rate beside
/// every other), and reads back the image and the statistics: how the render
/// tests over mesh scenes run a program.
pub fn render_color(
    gpu: &Gpu,
    shader: &mut Shader,
    channels: &[(String, wgpu::Texture)],
    textures: &[(&str, &wgpu::TextureView)],
    samplers: &[(&str, &wgpu::Sampler)],
    size: (u32, u32),
    options: DispatchOptions,
) -> Output {
    let color = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let shading_rate = mrsl_lab::shading_rate::upload_pattern(gpu, size, 8);
    let mut bindings = Bindings { size, shading_rate: Some(&shading_rate), ..Default::default() };
    for (name, texture) in channels {
        bindings.channels.insert(name.clone(), texture);
    }
    for (name, view) in textures {
        bindings.textures.insert(name.to_string(), view);
    }
    for (name, sampler) in samplers {
        bindings.samplers.insert(name.to_string(), sampler);
    }
    bindings.outputs.insert("color".into(), &color);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let stats = shader.read_stats(&gpu.device).unwrap();
    Output { pixels: gpu.read_rgba32f(&color).unwrap(), stats, width: size.0 }
}

/// Forced refinement evaluates every effect per pixel with the reference's
/// code: each of `programs` (name, source), in every adaptive mode over the
/// demo's G-buffer at an odd size, is bit-identical to its reference.
pub fn assert_forced_equals_reference(gpu: &Gpu, programs: &[(&str, &str)]) {
    let gbuffer = mrsl_lab::scene::Scene::Demo.render(75, 43);
    for (name, source) in programs {
        let program = compile(source);
        let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap();
        for mode in adaptive_modes() {
            let forced = run(gpu, &program, &gbuffer, mode, true).unwrap();
            let worst = worst_ulps(&forced.pixels, &reference.pixels);
            assert_eq!(worst, 0, "{name} {mode}: forced refinement differs from the reference by up to {worst} ulps");
        }
    }
}

/// What one of [`dispatch_in_turn`]'s dispatches left.
pub struct Dispatched {
    /// The first output, as RGBA floats.
    pub pixels: Vec<[f32; 4]>,
    /// [`Shader::read_stats`] after the dispatch.
    pub stats: Result<Stats, Error>,
    /// The `.x` words of [`Shader::refine_mask`] after the dispatch (the
    /// per-pixel refine masks), if the shader has one.
    pub refine_masks: Option<Vec<u32>>,
    /// Its `.y` words (the dynamic mode's 2x2 level; all ones at a background pixel).
    pub refine_masks_y: Option<Vec<u32>>,
}

/// `program` with only the plan entries of `modes` and the kernels they
/// use. A [`Shader`] makes a pipeline for every kernel its program's plan
/// names, and the kernels are the same text whichever modes are kept, so a
/// test that dispatches one mode need not wait for every other mode's
/// pipelines: on SwiftShader, whose pipeline compiles take seconds each,
/// that made `forced_refinement_equals_reference_for_every_example` take
/// nine minutes.
fn restricted_to(program: &CompiledProgram, modes: &[Mode]) -> CompiledProgram {
    let mut kept = program.clone();
    kept.layout.plan.modes.retain(|m| modes.contains(&m.mode));
    let used = Mode::kernels_of(modes);
    kept.kernels.retain(|k| used.contains(&KernelRef::new(k.kind, k.block_size)));
    kept
}

/// Dispatches `options` one after the other with one shader over one
/// G-buffer (prepared as [`run`] does; `rates` is the shading-rate image of
/// `options[0].rate_tile`), reading back after each.
pub fn dispatch_in_turn<const N: usize>(
    gpu: &Gpu,
    program: &CompiledProgram,
    gbuffer: &GBuffer,
    rates: &[mrsl_abi::ShadingRate],
    options: [DispatchOptions; N],
) -> Result<[Dispatched; N], Error> {
    let size = (gbuffer.width, gbuffer.height);
    let tile = options.first().map_or(mrsl_abi::shading_rate::DEFAULT_RATE_TILE, |o| o.rate_tile);
    let channels = gbuffer.upload(gpu);
    let modes = options.map(|o| o.mode);
    let mut shader = Shader::new(&gpu.device, &restricted_to(program, &modes))?;
    fill_uniforms(&mut shader, program)?;
    let (texture, sampler) = test_texture_and_sampler(gpu);
    let view = texture.create_view(&Default::default());
    let outputs: Vec<(String, wgpu::Texture)> = program
        .layout
        .outputs
        .iter()
        .map(|o| {
            assert_eq!(o.format, mrsl_abi::TextureFormat::Rgba32Float, "render tests read rgba32float outputs");
            (o.name.clone(), gpu.output_texture(&o.name, size, wgpu::TextureFormat::Rgba32Float))
        })
        .collect();
    let named_outputs = outputs.iter().map(|(name, t)| (name, t));
    let mut bindings = bind_test_program(program, size, &channels, &view, &sampler, named_outputs);
    // Only the rate-image mode reads it.
    let shading_rate = mrsl_lab::shading_rate::upload(gpu, size, tile, rates);
    bindings.shading_rate = Some(&shading_rate);
    let mut dispatched = vec![];
    for options in options {
        let first = dispatch_once(gpu, &mut shader, &bindings, &outputs[0].1, options)?;
        // A mode with a plan per kind of device (the block modes: the tile
        // kernel on GPUs, the coarse and fine kernels on CPU devices) runs
        // every plan here, whatever the device, and each must give the same
        // image, statistics and refine mask, bit for bit.
        if options.device.is_none() {
            let own = shader.device();
            let plans = program.layout.plan.modes.iter().filter(|m| m.mode == options.mode && m.device.is_some());
            for device in plans.filter_map(|m| m.device).filter(|d| *d != own) {
                let other = dispatch_once(
                    gpu,
                    &mut shader,
                    &bindings,
                    &outputs[0].1,
                    DispatchOptions { device: Some(device), ..options },
                )?;
                assert_same_dispatch(&first, &other, options, device);
            }
        }
        dispatched.push(first);
    }
    Ok(dispatched.try_into().unwrap_or_else(|_| unreachable!("one result per dispatch")))
}

/// One dispatch of [`dispatch_in_turn`], read back: the first output `color`,
/// the statistics and the refine mask.
fn dispatch_once(
    gpu: &Gpu,
    shader: &mut Shader,
    bindings: &Bindings,
    color: &wgpu::Texture,
    options: DispatchOptions,
) -> Result<Dispatched, Error> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, options)?;
    gpu.queue.submit([encoder.finish()]);
    let stats = shader.read_stats(&gpu.device);
    let pixels = gpu.read_rgba32f(color).map_err(|e| Error::Readback(e.to_string()))?;
    let (refine_masks, refine_masks_y) = match shader.refine_mask() {
        Some(t) => {
            let texels = gpu.read_texture(t).map_err(|e| Error::Readback(e.to_string()))?;
            // rg32uint: the mask is the first word of each 8-byte texel, then `.y`.
            let word = |t: &[u8]| u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
            let x = texels.chunks_exact(8).map(|t| word(&t[..4])).collect();
            let y = texels.chunks_exact(8).map(|t| word(&t[4..])).collect();
            (Some(x), Some(y))
        }
        None => (None, None),
    };
    Ok(Dispatched { pixels, stats, refine_masks, refine_masks_y })
}

/// Two plans of one mode gave the same image (bit for bit), statistics and refine masks.
#[track_caller]
fn assert_same_dispatch(first: &Dispatched, other: &Dispatched, options: DispatchOptions, device: mrsl_abi::Device) {
    let what = format!("{} (forced: {}), its {} plan", options.mode, options.force_refine, device.name());
    let bits = |p: &[[f32; 4]]| p.iter().flat_map(|t| t.map(f32::to_bits)).collect::<Vec<u32>>();
    assert!(
        bits(&first.pixels) == bits(&other.pixels),
        "{what}: another image (worst {} ulps)",
        worst_ulps(&first.pixels, &other.pixels)
    );
    let counts = |s: &Result<Stats, Error>| s.as_ref().ok().map(|s| Stats { timings: None, ..s.clone() });
    assert_eq!(counts(&first.stats), counts(&other.stats), "{what}: other statistics");
    assert!(first.refine_masks == other.refine_masks, "{what}: another refine mask");
    assert!(first.refine_masks_y == other.refine_masks_y, "{what}: another refine mask (.y)");
}

/// Bindings of a test program: its channels and outputs by name, and the
/// test texture and sampler ([`test_texture_and_sampler`]) for every texture
/// and sampler uniform it declares.
pub fn bind_test_program<'a>(
    program: &CompiledProgram,
    size: (u32, u32),
    channels: &'a [(String, wgpu::Texture)],
    view: &'a wgpu::TextureView,
    sampler: &'a wgpu::Sampler,
    outputs: impl Iterator<Item = (&'a String, &'a wgpu::Texture)>,
) -> Bindings<'a> {
    let mut bindings = Bindings { size, ..Default::default() };
    for (name, t) in channels {
        bindings.channels.insert(name.clone(), t);
    }
    for t in &program.layout.textures {
        bindings.textures.insert(t.name.clone(), view);
    }
    for s in &program.layout.samplers {
        bindings.samplers.insert(s.name.clone(), sampler);
    }
    for (name, t) in outputs {
        bindings.outputs.insert(name.clone(), t);
    }
    bindings
}

/// Sets every uniform without a default to a deterministic value, so that
/// any program can run: floats in [0.25, 0.75), integers and bools 0 (what
/// those floats were cast to before `set_uniform` checked values against
/// their type).
pub fn fill_uniforms(shader: &mut Shader, program: &CompiledProgram) -> Result<(), Error> {
    let Some(block) = &program.layout.uniforms else { return Ok(()) };
    for f in block.fields.iter().filter(|f| f.default.is_none()) {
        let float = f.ty.scalar() == mrsl_abi::Scalar::Float;
        let value = |i: u32| if float { 0.25 + 0.5 * ((i * 7919) % 13) as f64 / 13.0 } else { 0.0 };
        let values: Vec<f64> = (0..f.ty.components()).map(value).collect();
        shader.set_uniform(&f.name, &values)?;
    }
    Ok(())
}

/// The texture (4x4 `rgba8unorm`, every texel different) and the linear
/// sampler bound to every texture and sampler uniform of a test program.
pub fn test_texture_and_sampler(gpu: &Gpu) -> (wgpu::Texture, wgpu::Sampler) {
    let texture = gpu.texture_with_data(
        "test texture",
        (4, 4),
        wgpu::TextureFormat::Rgba8Unorm,
        &(0..64).map(|i| (i * 37 % 256) as u8).collect::<Vec<u8>>(),
    );
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    (texture, sampler)
}

/// Distance in units in the last place between two floats (0 when bit-equal).
pub fn ulps(a: f32, b: f32) -> u32 {
    if a == b {
        return 0;
    }
    let key = |x: f32| {
        let bits = x.to_bits() as i32;
        if bits < 0 { i32::MIN - bits } else { bits }
    };
    (key(a) as i64 - key(b) as i64).unsigned_abs().min(u32::MAX as u64) as u32
}

/// Largest distance in ulps over every channel of every pixel (0 when bit-identical).
pub fn worst_ulps(a: &[[f32; 4]], b: &[[f32; 4]]) -> u32 {
    a.iter().zip(b).flat_map(|(p, q)| (0..4).map(move |c| ulps(p[c], q[c]))).max().unwrap_or(0)
}

/// Largest absolute difference over every channel of every pixel.
pub fn max_abs_diff(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter().zip(b).flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs())).fold(0.0, f32::max)
}

/// Peak signal-to-noise ratio of `a` against `b` over RGB, each channel
/// clamped to [0, 1] (peak 1); infinite for identical images.
pub fn psnr_of(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let clamp = |v: f32| v.clamp(0.0, 1.0) as f64;
    let sum: f64 = a.iter().zip(b).flat_map(|(p, q)| (0..3).map(move |c| (clamp(p[c]) - clamp(q[c])).powi(2))).sum();
    let mse = sum / (3 * a.len()) as f64;
    if mse == 0.0 { f64::INFINITY } else { 10.0 * (1.0 / mse).log10() }
}
