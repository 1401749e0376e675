//! Channels as engines store them: the demo program with its position
//! rebuilt from a depth texture (`@depth`) and its normals read from two
//! octahedral components (`@encoded(octahedral)`) renders the image of the
//! float G-buffer within the rounding of the reconstruction; over Bevy's
//! deferred G-buffer (`@packed(bevy_deferred, ..)`) within its 8-bit
//! colour; forced refinement still equals the reference bit for bit in
//! every mode; and a texture of the wrong kind for a decoded channel is a
//! typed error.

use crate::harness::*;
use mrsl_lab::engine_formats;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::{ChannelData, Scene};
use mrsl_runtime::{Bindings, DispatchOptions, Error, Mode, Shader};

const DEMO: &str = include_str!("../../examples/demo.mrsl");
const SIZE: (u32, u32) = (96, 54);

/// examples/demo.mrsl over a depth texture and octahedral normals.
fn engine_program() -> String {
    engine_formats::over_depth(DEMO, "octahedral").expect("examples/demo.mrsl declares position and normal so")
}

fn floats<'a>(data: Option<&'a ChannelData>, name: &str) -> (usize, &'a [f32]) {
    match data {
        Some(ChannelData::Float { components, data }) => (*components as usize, data),
        _ => panic!("the demo scene has a float `{name}` channel"),
    }
}

/// A G-buffer's channel textures by name.
type Channels = Vec<(String, wgpu::Texture)>;

/// The demo G-buffer twice: as the lab stores it, and as an engine does
/// (depth in a Depth32Float texture, normals as octahedral Rg32Float).
fn gbuffers(gpu: &Gpu) -> (Channels, Channels, [f32; 16]) {
    let gbuffer = Scene::Demo.render(SIZE.0, SIZE.1);
    let float = gbuffer.upload(gpu);
    let (vp, inverse) = engine_formats::view_projection(&Scene::demo_camera(), SIZE).unwrap();
    let (n, positions) = floats(gbuffer.channel("position"), "position");
    let depth = engine_formats::depth_texture(gpu, SIZE, &engine_formats::depths(positions, n, vp));
    let (n, normals) = floats(gbuffer.channel("normal"), "normal");
    let encoded: Vec<f32> =
        normals.chunks_exact(n).flat_map(|v| engine_formats::octahedral([v[0], v[1], v[2]])).collect();
    let normal = gpu.texture_with_data("normal", SIZE, wgpu::TextureFormat::Rg32Float, bytemuck::cast_slice(&encoded));
    let mut engine = gbuffer.upload(gpu);
    engine.retain(|(name, _)| name != "position" && name != "normal");
    engine.push(("position".into(), depth));
    engine.push(("normal".into(), normal));
    (float, engine, inverse)
}

fn render(
    gpu: &Gpu,
    shader: &mut Shader,
    channels: &[(String, wgpu::Texture)],
    mode: Mode,
    forced: bool,
) -> Vec<[f32; 4]> {
    let options = DispatchOptions { force_refine: forced, ..DispatchOptions::new(mode) };
    render_color(gpu, shader, channels, &[], &[], SIZE, options).pixels
}

/// One program over the float G-buffer and one over the engine's, in every
/// mode: each engine image within `bound` dB PSNR of the float one, and the
/// engine program's forced refinement equal to its reference bit for bit.
fn compare_in_every_mode(
    gpu: &Gpu,
    (float, float_channels): (&mut Shader, &[(String, wgpu::Texture)]),
    (engine, engine_channels): (&mut Shader, &[(String, wgpu::Texture)]),
    bound: f64,
    what: &str,
) {
    let reference = render(gpu, engine, engine_channels, Mode::Reference, false);
    for mode in Mode::ALL {
        let expected = render(gpu, float, float_channels, mode, false);
        let found = render(gpu, engine, engine_channels, mode, false);
        let psnr = psnr_of(&found, &expected);
        println!("  {mode}: {what} against the float G-buffer: {psnr:.1} dB");
        assert!(psnr >= bound, "{mode}: {what}: {psnr:.1} dB against the float G-buffer");
        if mode != Mode::Reference {
            let forced = render(gpu, engine, engine_channels, mode, true);
            assert_eq!(worst_ulps(&forced, &reference), 0, "{mode}: forced refinement differs from the reference");
        }
    }
}

/// Every mode over the engine's G-buffer against the same mode over the
/// float one. The depth is a 32-bit float of `near / view depth`, and the
/// position rebuilt from it through the inverse view-projection differs
/// from the ray-cast one by float rounding (relative 1e-6 near, more for
/// the sky at 50 units); the octahedral normals by a few ulps. A key or a
/// refine predicate near its threshold may therefore flip at a pixel or
/// two; the bound, 60 dB PSNR in every mode, allows that and nothing like
/// a wrong decoding (which loses the image: below 20 dB).
pub fn depth_and_octahedral_normals_render_as_the_float_gbuffer(gpu: &Gpu) {
    let (float_channels, engine_channels, inverse) = gbuffers(gpu);
    let mut float = Shader::new(&gpu.device, &compile(DEMO)).unwrap();
    let mut engine = Shader::new(&gpu.device, &compile(&engine_program())).unwrap();
    engine.set_uniform_f32("inverse_view_proj", &inverse).unwrap();
    let (float, engine) = ((&mut float, &float_channels[..]), (&mut engine, &engine_channels[..]));
    compare_in_every_mode(gpu, float, engine, 60.0, "depth + octahedral normals");
}

/// examples/demo.mrsl reading its albedo and normals from Bevy's deferred G-buffer.
fn bevy_program() -> String {
    let (albedo, normal) = ("in float4 albedo;", "@key(0.4) in float3 normal;");
    assert!(DEMO.contains(albedo) && DEMO.contains(normal), "examples/demo.mrsl declares its channels so");
    DEMO.replace(albedo, "@packed(bevy_deferred, base_color) in float3 albedo;")
        .replace(normal, "@key(0.4) @packed(bevy_deferred, normal) in float3 normal;")
}

/// Every mode over Bevy's deferred G-buffer (one `Rgba32Uint` texture bound
/// as both channels) against the same mode over the float G-buffer. The
/// base colour goes through a 1/2.2 gamma and 8 bits (steps of about 0.4%
/// of the colour), the normal through 12-bit octahedral halves (about 0.05
/// degrees): 60.6 dB measured in every mode at 96x54; the bound, 40 dB,
/// allows that and a key flipping at a few pixels, and nothing like a
/// wrong decoding (below 20 dB).
pub fn bevy_deferred_gbuffer_renders_as_the_float_gbuffer(gpu: &Gpu) {
    let gbuffer = Scene::Demo.render(SIZE.0, SIZE.1);
    let float_channels = gbuffer.upload(gpu);
    let (na, albedo) = floats(gbuffer.channel("albedo"), "albedo");
    let (nn, normals) = floats(gbuffer.channel("normal"), "normal");
    let texels: Vec<u32> = albedo
        .chunks_exact(na)
        .zip(normals.chunks_exact(nn))
        .flat_map(|(a, n)| {
            let surface = engine_formats::BevySurface {
                base_color: [a[0], a[1], a[2]],
                perceptual_roughness: 0.5,
                normal: [n[0], n[1], n[2]],
            };
            engine_formats::bevy_deferred(&surface)
        })
        .collect();
    let deferred =
        gpu.texture_with_data("deferred", SIZE, wgpu::TextureFormat::Rgba32Uint, bytemuck::cast_slice(&texels));
    let mut bevy_channels = gbuffer.upload(gpu);
    bevy_channels.retain(|(name, _)| name != "albedo" && name != "normal");
    bevy_channels.push(("albedo".into(), deferred.clone()));
    bevy_channels.push(("normal".into(), deferred));
    let mut float = Shader::new(&gpu.device, &compile(DEMO)).unwrap();
    let mut bevy = Shader::new(&gpu.device, &compile(&bevy_program())).unwrap();
    let (float, engine) = ((&mut float, &float_channels[..]), (&mut bevy, &bevy_channels[..]));
    compare_in_every_mode(gpu, float, engine, 40.0, "Bevy's deferred G-buffer");
}

const ENGINE: &str = include_str!("../../examples/engine/deferred.mrsl");

/// The engine example's program (examples/engine/deferred.mrsl: depth and
/// `Rgb10a2Unorm` normals) over the demo scene stored so, against the same
/// program without its decodings over the float G-buffer. The 10-bit
/// normals move the shading by about 1e-3: 68.9 dB measured; the bound,
/// 45 dB, allows that and a refinement flipping at a few pixels.
pub fn the_engine_example_program_renders_over_engine_formats(gpu: &Gpu) {
    let decodings = ["@depth(inverse_view_proj) ", "@encoded(unorm) "];
    assert!(decodings.iter().all(|d| ENGINE.contains(d)), "the engine program decodes its position and normals");
    let float_program = decodings.iter().fold(ENGINE.to_string(), |p, d| p.replace(d, ""));
    let gbuffer = Scene::Demo.render(SIZE.0, SIZE.1);
    let float_channels = gbuffer.upload(gpu);
    let (vp, inverse) = engine_formats::view_projection(&Scene::demo_camera(), SIZE).unwrap();
    let (n, positions) = floats(gbuffer.channel("position"), "position");
    let depth = engine_formats::depth_texture(gpu, SIZE, &engine_formats::depths(positions, n, vp));
    let (n, normals) = floats(gbuffer.channel("normal"), "normal");
    let packed: Vec<u32> = normals.chunks_exact(n).map(|v| engine_formats::rgb10a2unorm([v[0], v[1], v[2]])).collect();
    let normal =
        gpu.texture_with_data("normal", SIZE, wgpu::TextureFormat::Rgb10a2Unorm, bytemuck::cast_slice(&packed));
    let mut engine_channels = gbuffer.upload(gpu);
    engine_channels.retain(|(name, _)| name != "position" && name != "normal");
    engine_channels.push(("position".into(), depth));
    engine_channels.push(("normal".into(), normal));
    let mut float = Shader::new(&gpu.device, &compile(&float_program)).unwrap();
    let mut engine = Shader::new(&gpu.device, &compile(ENGINE)).unwrap();
    engine.set_uniform_f32("inverse_view_proj", &inverse).unwrap();
    float.set_uniform_f32("inverse_view_proj", &inverse).unwrap();
    let (float, engine) = ((&mut float, &float_channels[..]), (&mut engine, &engine_channels[..]));
    compare_in_every_mode(gpu, float, engine, 45.0, "the engine program over depth + Rgb10a2Unorm normals");
}

/// A decoded channel takes only the texture its decoding reads.
pub fn decoded_channels_take_their_engine_formats(gpu: &Gpu) {
    let (float_channels, engine_channels, _) = gbuffers(gpu);
    let engine = compile(&engine_program());
    let float = compile(DEMO);
    let encode = |program: &mrsl::Program, swap: &[(&str, &wgpu::Texture)]| -> Error {
        let mut shader = Shader::new(&gpu.device, program).unwrap();
        shader.set_uniform_f32("inverse_view_proj", &[0.0; 16]).ok();
        let base = if std::ptr::eq(program, &engine) { &engine_channels } else { &float_channels };
        let color = gpu.output_texture("color", SIZE, wgpu::TextureFormat::Rgba32Float);
        let mut bindings = Bindings { size: SIZE, ..Default::default() };
        for (name, texture) in base {
            bindings.channels.insert(name.clone(), texture);
        }
        for (name, texture) in swap {
            bindings.channels.insert(name.to_string(), texture);
        }
        bindings.outputs.insert("color".into(), &color);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader
            .encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(Mode::Reference))
            .unwrap_err()
    };
    let texture = |set: &[(String, wgpu::Texture)], name: &str| set.iter().find(|(n, _)| n == name).unwrap().1.clone();
    match encode(&engine, &[("position", &texture(&float_channels, "position"))]) {
        Error::ChannelNotDepth { channel, found } => {
            assert_eq!((channel.as_str(), found), ("position", wgpu::TextureFormat::Rgba32Float))
        }
        other => panic!("a colour texture for a depth channel: {other:?}"),
    }
    match encode(&float, &[("position", &texture(&engine_channels, "position"))]) {
        e @ Error::ChannelDepthFormat { .. } => assert!(e.to_string().contains("@depth"), "{e}"),
        other => panic!("a depth texture for a float channel: {other:?}"),
    }
    let one = gpu.texture_with_data(
        "normal",
        SIZE,
        wgpu::TextureFormat::R32Float,
        &vec![0u8; (SIZE.0 * SIZE.1 * 4) as usize],
    );
    match encode(&engine, &[("normal", &one)]) {
        e @ Error::ChannelFormat { .. } => assert!(e.to_string().contains("at least 2 components"), "{e}"),
        other => panic!("one component for an octahedral channel: {other:?}"),
    }
}
