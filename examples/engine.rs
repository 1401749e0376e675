//! An engine using mrsl the way a real renderer would: it owns the wgpu
//! device, fills its own G-buffer textures, loads kernels that `mrslc
//! compile` wrote ahead of time, and lets the mrsl runtime record its passes
//! into the engine's command encoder. The compiler is not linked:
//!
//! ```sh
//! cargo run --release -p mrslc -- compile examples/demo.mrsl -o kernels
//! cargo run --release -p mrsl-runtime --example engine -- kernels
//! ```
//!
//! writes `engine.dynamic.png` and `engine.reference.png` into the current
//! directory. Built with the runtime's `compile` feature (`--features
//! compile`) and no argument, it compiles the built-in demo program at load
//! time instead.
//!
//! The G-buffer here is filled from the CPU (a sphere over a ground plane,
//! analytically); an engine would rasterise it in its own geometry pass. It
//! has `position`, `normal` (rgba32float), `uv` (rg32float) and `material`
//! (r32uint); a program reading another channel gets a typed error naming it.

use mrsl_runtime::{Bindings, CompiledProgram, DispatchOptions, Mode, Shader};
use std::collections::HashMap;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 270;
const EYE: [f32; 3] = [0.0, 1.2, 4.0];

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let program = load_program()?;

    // 1. The engine's own device (here: whatever adapter wgpu finds first).
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))?;
    println!("adapter: {}", adapter.get_info().name);

    // 2. The engine's own G-buffer.
    let texture = |label: &str, format: wgpu::TextureFormat, bytes: &[u8], usage: wgpu::TextureUsages| {
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: usage | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        if !bytes.is_empty() {
            let bytes_per_row = Some(WIDTH * format.block_copy_size(None).unwrap_or(4));
            let layout = wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row, rows_per_image: None };
            queue.write_texture(t.as_image_copy(), bytes, layout, t.size());
        }
        t
    };
    let g = gbuffer();
    let sampled = wgpu::TextureUsages::TEXTURE_BINDING;
    let channels = HashMap::from([
        ("position", texture("position", wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&g.position), sampled)),
        ("normal", texture("normal", wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&g.normal), sampled)),
        ("uv", texture("uv", wgpu::TextureFormat::Rg32Float, bytemuck::cast_slice(&g.uv), sampled)),
        ("material", texture("material", wgpu::TextureFormat::R32Uint, bytemuck::cast_slice(&g.material), sampled)),
    ]);
    // Output targets in the formats the layout names.
    let storage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
    let outputs: Vec<(String, wgpu::Texture)> = program
        .layout
        .outputs
        .iter()
        .map(|o| (o.name.clone(), texture(&o.name, mrsl_runtime::wgpu_format(o.format), &[], storage)))
        .collect();

    // 3. The program on the engine's device.
    let mut shader = Shader::new(&device, &program)?;
    if program.layout.uniforms.as_ref().is_some_and(|u| u.fields.iter().any(|f| f.name == "camera_pos")) {
        shader.set_uniform("camera_pos", &EYE.map(f64::from))?;
    }
    let mut bindings = Bindings { size: (WIDTH, HEIGHT), ..Default::default() };
    for (name, t) in &channels {
        bindings.channels.insert(name.to_string(), t);
    }
    for (name, t) in &outputs {
        bindings.outputs.insert(name.clone(), t);
    }

    for mode in [Mode::Dynamic, Mode::Reference] {
        // 4. The engine's frame: its own passes, then mrsl's, in one encoder.
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        shader.encode(&device, &queue, &mut encoder, &bindings, DispatchOptions::new(mode))?;
        let (name, color) = &outputs[0];
        let readback = copy_out(&device, &mut encoder, color);
        queue.submit([encoder.finish()]);
        println!("{}", shader.read_stats(&device)?.table());
        let file = format!("engine.{mode}.png");
        save_png(&device, &readback, color.format(), &file).map_err(|e| format!("output `{name}`: {e}"))?;
        println!("wrote {file}");
    }
    Ok(())
}

/// The kernels in the directory given as the first argument, or (with the
/// `compile` feature and no argument) the demo program compiled now.
fn load_program() -> Result<CompiledProgram, Box<dyn std::error::Error>> {
    if let Some(dir) = std::env::args_os().nth(1) {
        return Ok(CompiledProgram::read_dir(dir.as_ref(), None)?);
    }
    #[cfg(feature = "compile")]
    {
        println!("no kernel directory given: compiling the built-in demo program");
        // The kernels of the two modes this engine runs.
        Ok(mrsl_runtime::compile_modes(
            include_str!("demo.mrsl"),
            "examples/demo.mrsl",
            &[Mode::Dynamic, Mode::Reference],
        )?)
    }
    #[cfg(not(feature = "compile"))]
    Err("usage: engine KERNEL_DIR\n\
         KERNEL_DIR holds the files `mrslc compile` writes, e.g.:\n  \
         cargo run --release -p mrslc -- compile examples/demo.mrsl -o kernels\n  \
         cargo run --release -p mrsl-runtime --example engine -- kernels\n\
         (or build the example with `--features compile` to compile the demo at load time)"
        .into())
}

/// The engine's G-buffer, per pixel.
struct GBuffer {
    position: Vec<[f32; 4]>,
    normal: Vec<[f32; 4]>,
    uv: Vec<[f32; 2]>,
    material: Vec<u32>,
}

/// A sphere on a ground plane seen from `EYE`: world-space position, normal,
/// uv (planar on the ground, spherical on the sphere) and material per pixel
/// (0 = ground, 1 = sphere, 255 = sky).
fn gbuffer() -> GBuffer {
    let eye = EYE;
    let mut g = GBuffer { position: vec![], normal: vec![], uv: vec![], material: vec![] };
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let u = (x as f32 + 0.5) / WIDTH as f32 * 2.0 - 1.0;
            let v = 1.0 - (y as f32 + 0.5) / HEIGHT as f32 * 2.0;
            let d = normalize([u * 0.8 * WIDTH as f32 / HEIGHT as f32, v * 0.8 - 0.25, -1.6]);
            // Sphere at (0, 0.7, 0), radius 0.7.
            let oc = [eye[0], eye[1] - 0.7, eye[2]];
            let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
            let c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - 0.49;
            let (t, n, m) = if b * b - c >= 0.0 && -b - (b * b - c).sqrt() > 0.0 {
                let t = -b - (b * b - c).sqrt();
                let p = [eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2]];
                (t, normalize([p[0], p[1] - 0.7, p[2]]), 1)
            } else if d[1] < 0.0 {
                (-eye[1] / d[1], [0.0, 1.0, 0.0], 0)
            } else {
                (100.0, [-d[0], -d[1], -d[2]], 255)
            };
            let p = [eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2]];
            let uv = match m {
                1 => [0.5 + n[2].atan2(n[0]) / std::f32::consts::TAU, 0.5 - n[1].asin() / std::f32::consts::PI],
                0 => [p[0] * 0.25, p[2] * 0.25],
                _ => [0.0, 0.0],
            };
            g.position.push([p[0], p[1], p[2], 1.0]);
            g.normal.push([n[0], n[1], n[2], 0.0]);
            g.uv.push(uv);
            g.material.push(m);
        }
    }
    g
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn copy_out(device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) -> wgpu::Buffer {
    let padded = (WIDTH * 16).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * HEIGHT) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(padded), rows_per_image: None },
        },
        texture.size(),
    );
    buffer
}

fn save_png(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    format: wgpu::TextureFormat,
    path: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    if format != wgpu::TextureFormat::Rgba32Float {
        return Err(format!("this example writes rgba32float outputs only, not {format:?}").into());
    }
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| r.expect("readback buffer maps"));
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let data = slice.get_mapped_range()?;
    let padded = (WIDTH * 16).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let mut img = image::RgbImage::new(WIDTH, HEIGHT);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let at = (y * padded + x * 16) as usize;
            let px: [f32; 4] = bytemuck::pod_read_unaligned(&data[at..at + 16]);
            let srgb = |v: f32| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8;
            img.put_pixel(x, y, image::Rgb([srgb(px[0]), srgb(px[1]), srgb(px[2])]));
        }
    }
    img.save(path)?;
    Ok(())
}
