//! What a G-buffer as engines store it costs against the lab's float one:
//! examples/demo.mrsl over float `position` and `normal` textures
//! (`Rgba32Float`) against the same program with its position rebuilt from
//! a `Depth32Float` depth texture (`@depth`, through the inverse
//! view-projection) and its normals read from `Rgb10a2Unorm`
//! (`@encoded(unorm)`), as Bevy's prepass stores them; the other channels
//! are the same textures. At 1920x1080, in the reference and coarse 4x4.
//!
//! `cargo run --release -p mrsl-lab --example engine_gbuffer_cost [PAIRS] [SCENE]`
//! (SCENE: `demo`, the default, or a mesh scene such as `sponza`)
//!
//! Each pair times one dispatch of each program, encoding to idle, the
//! order alternating; it prints the median over pairs of the engine
//! G-buffer's time over the float one's, so that a slow moment of a shared
//! machine weighs on both.

use mrsl_lab::engine_formats;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::microbench::median;
use mrsl_lab::scene::{ChannelData, Scene};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::time::Instant;

const SIZE: (u32, u32) = (1920, 1080);
const DEMO: &str = include_str!("../../examples/demo.mrsl");

fn main() {
    let mut args = std::env::args().skip(1);
    let pairs: usize = args.next().map_or(9, |a| a.parse().expect("PAIRS is a number"));
    let scene_name = args.next().unwrap_or_else(|| "demo".into());
    let scene = Scene::parse(&scene_name).unwrap_or_else(|| panic!("unknown scene `{scene_name}`"));
    mrsl_lab::fixtures::locate_sponza();
    // SAFETY: before any thread starts Vulkan.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    println!(
        "adapter: {} ({:?}); scene {scene_name} at {}x{}",
        gpu.adapter_info.name, gpu.adapter_info.backend, SIZE.0, SIZE.1
    );
    let gbuffer = scene.render_on(&gpu, SIZE.0, SIZE.1).unwrap_or_else(|e| panic!("{e}"));
    let camera = scene.camera().or((scene == Scene::Demo).then(Scene::demo_camera)).expect("a scene with a camera");
    let (vp, inverse) = engine_formats::view_projection(&camera, SIZE).expect("a camera that projects");
    let float = gbuffer.upload(&gpu);
    let floats = |name: &str| match gbuffer.channel(name) {
        Some(ChannelData::Float { components, data }) => (*components as usize, data.as_slice()),
        _ => panic!("the scene has a float `{name}` channel"),
    };
    let (n, positions) = floats("position");
    let depth = engine_formats::depth_texture(&gpu, SIZE, &engine_formats::depths(positions, n, vp));
    let (n, normals) = floats("normal");
    let packed: Vec<u32> = normals.chunks_exact(n).map(|v| engine_formats::rgb10a2unorm([v[0], v[1], v[2]])).collect();
    let normal =
        gpu.texture_with_data("normal", SIZE, wgpu::TextureFormat::Rgb10a2Unorm, bytemuck::cast_slice(&packed));
    let mut engine: Vec<(String, wgpu::Texture)> =
        float.iter().filter(|(name, _)| name != "position" && name != "normal").cloned().collect();
    engine.push(("position".into(), depth));
    engine.push(("normal".into(), normal));

    let modes = [Mode::Reference, Mode::Coarse4x4];
    let mut float_shader = shader(&gpu, DEMO, &modes);
    let mut engine_shader =
        shader(&gpu, &engine_formats::over_depth(DEMO, "unorm").expect("the demo's channels"), &modes);
    engine_shader.set_uniform_f32("inverse_view_proj", &inverse).expect("the engine program's matrix");
    let output = gpu.output_texture("color", SIZE, wgpu::TextureFormat::Rgba32Float);
    for mode in modes {
        let options = DispatchOptions::new(mode).uninstrumented();
        let time = |shader: &mut Shader, channels: &[(String, wgpu::Texture)]| {
            let mut bindings = Bindings { size: SIZE, ..Default::default() };
            bindings.channels = channels.iter().map(|(n, t)| (n.clone(), t)).collect();
            bindings.outputs.insert("color".into(), &output);
            let start = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options).expect("dispatch");
            gpu.queue.submit([encoder.finish()]);
            gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("idle");
            start.elapsed().as_secs_f64() * 1e3
        };
        for _ in 0..3 {
            time(&mut float_shader, &float);
            time(&mut engine_shader, &engine);
        }
        let (mut ratios, mut float_ms, mut engine_ms) = (vec![], vec![], vec![]);
        for pair in 0..pairs {
            let (f, e) = if pair % 2 == 0 {
                let f = time(&mut float_shader, &float);
                (f, time(&mut engine_shader, &engine))
            } else {
                let e = time(&mut engine_shader, &engine);
                (time(&mut float_shader, &float), e)
            };
            ratios.push(e / f);
            float_ms.push(f);
            engine_ms.push(e);
        }
        ratios.sort_by(f64::total_cmp);
        println!(
            "{:>11}: float G-buffer {:.1} ms, depth + Rgb10a2Unorm normals {:.1} ms (medians of {pairs}); engine / float {:.3} (median of the pairs' ratios, range {:.3} to {:.3})",
            mode.name(),
            median(&float_ms),
            median(&engine_ms),
            median(&ratios),
            ratios.first().unwrap(),
            ratios.last().unwrap()
        );
    }
}

fn shader(gpu: &Gpu, source: &str, modes: &[Mode]) -> Shader {
    let program = mrsl::compile(source, &mrsl::Options::for_modes(modes)).unwrap_or_else(|d| panic!("{d:?}"));
    Shader::new(&gpu.device, &program.compiled).expect("pipelines")
}
