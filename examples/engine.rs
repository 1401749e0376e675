//! An engine using mrsl the way a real renderer would: it owns the wgpu
//! device, fills its own G-buffer textures as engines store them, loads
//! kernels that `mrslc compile` wrote ahead of time, and lets the mrsl
//! runtime record its passes into the engine's command encoder. The
//! compiler is not linked:
//!
//! ```sh
//! cargo run --release -p mrslc -- compile examples/engine/deferred.mrsl -o kernels
//! cargo run --release -p mrsl-runtime --example engine -- kernels [--out DIR]
//! ```
//!
//! writes `engine.dynamic.png` and `engine.reference.png` into `out/` (or
//! `--out DIR`). Built with the runtime's `compile` feature (`--features
//! compile`) and no kernel directory, it compiles examples/engine/deferred.mrsl
//! at load time instead.
//!
//! The G-buffer is a sphere over a ground plane, ray-cast on the CPU (an
//! engine rasterises it in its geometry pass), stored as engines store it:
//! a `Depth32Float` depth texture (no position: the kernels rebuild it
//! through the inverse view-projection, `@depth`), normals in
//! `Rgb10a2Unorm` (`@encoded(unorm)`), albedo in `Rgba8Unorm` and an
//! `R8Uint` material id. A program reading a channel the engine does not
//! have gets a typed error naming it.

use glam::{Mat4, Vec3, Vec4};
use mrsl_runtime::{Bindings, CompiledProgram, DispatchOptions, Mode, Shader};
use std::collections::HashMap;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 270;
const EYE: [f32; 3] = [0.0, 1.2, 4.0];
const TARGET: [f32; 3] = [0.0, 0.5, 0.0];
const FOV_Y_DEGREES: f32 = 45.0;
/// The near plane of the reversed, infinite-far depth.
const NEAR: f32 = 0.05;

fn main() -> std::process::ExitCode {
    let runtime_dir = quiet_headless_vulkan();
    let code = match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            std::process::ExitCode::FAILURE
        }
    };
    if let Some(dir) = runtime_dir {
        // Nothing was written there; leave no directory behind.
        let _ = std::fs::remove_dir(dir);
    }
    code
}

/// Headless runs without a login session (containers, CI, ssh without
/// one) have no `XDG_RUNTIME_DIR`; libwayland, which Mesa's Vulkan drivers
/// load, then prints "error: XDG_RUNTIME_DIR is invalid or not set in the
/// environment." although nothing fails. An engine with a window runs in a
/// session; this example, like `mrslc`, points the variable at a private
/// directory (mode 0700, as the XDG specification asks) when it is unset or
/// not absolute, and returns it. It must run before any thread starts or
/// wgpu loads Vulkan.
fn quiet_headless_vulkan() -> Option<std::path::PathBuf> {
    let valid = std::env::var_os("XDG_RUNTIME_DIR")
        .is_some_and(|v| std::path::Path::new(&v).is_absolute() && std::path::Path::new(&v).is_dir());
    #[cfg(unix)]
    if !valid {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        let dir = std::env::temp_dir().join(format!("mrsl-engine-runtime-{}", std::process::id()));
        if std::fs::DirBuilder::new().mode(0o700).create(&dir).is_ok()
            && std::fs::symlink_metadata(&dir).is_ok_and(|m| m.is_dir() && m.mode() & 0o077 == 0)
        {
            // SAFETY: called first thing in `main`, before any other thread exists.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
            return Some(dir);
        }
    }
    #[cfg(not(unix))]
    let _ = valid;
    None
}

/// The command line: `[KERNEL_DIR] [--out DIR]`.
struct Args {
    kernels: Option<std::path::PathBuf>,
    out: std::path::PathBuf,
}

fn args() -> Result<Args, Box<dyn std::error::Error>> {
    let mut args = Args { kernels: None, out: "out".into() };
    let mut rest = std::env::args_os().skip(1);
    while let Some(arg) = rest.next() {
        if arg == "--out" {
            args.out = rest.next().ok_or("--out needs a directory")?.into();
        } else if args.kernels.is_none() {
            args.kernels = Some(arg.into());
        } else {
            return Err(format!("unexpected argument {}", arg.to_string_lossy()).into());
        }
    }
    Ok(args)
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = args()?;
    let program = load_program(args.kernels.as_deref())?;
    std::fs::create_dir_all(&args.out).map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;

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
    let normals: Vec<u32> = g.normal.iter().map(|n| rgb10a2unorm(*n)).collect();
    let albedo: Vec<u8> = g.albedo.iter().flat_map(|a| a.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)).collect();
    let channels = HashMap::from([
        ("position", depth_texture(&device, &queue, &g.depth)),
        ("normal", texture("normal", wgpu::TextureFormat::Rgb10a2Unorm, bytemuck::cast_slice(&normals), sampled)),
        ("albedo", texture("albedo", wgpu::TextureFormat::Rgba8Unorm, &albedo, sampled)),
        ("material", texture("material", wgpu::TextureFormat::R8Uint, &g.material, sampled)),
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
    let declares =
        |name: &str| program.layout.uniforms.as_ref().is_some_and(|u| u.fields.iter().any(|f| f.name == name));
    if declares("camera_pos") {
        shader.set_uniform_f32("camera_pos", &EYE)?;
    }
    // The position channel is rebuilt from depth with the inverse of the
    // view-projection the depth was written with (`@depth(inverse_view_proj)`).
    if declares("inverse_view_proj") {
        shader.set_uniform_f32("inverse_view_proj", &view_projection().inverse().to_cols_array())?;
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
        let file = args.out.join(format!("engine.{mode}.png"));
        save_png(&device, &readback, color.format(), &file).map_err(|e| format!("output `{name}`: {e}"))?;
        println!("wrote {}", file.display());
    }
    Ok(())
}

/// The kernels in the directory given, or (with the `compile` feature and
/// no directory) the demo program compiled now.
fn load_program(dir: Option<&std::path::Path>) -> Result<CompiledProgram, Box<dyn std::error::Error>> {
    if let Some(dir) = dir {
        return Ok(CompiledProgram::read_dir(dir, None)?);
    }
    #[cfg(feature = "compile")]
    {
        println!("no kernel directory given: compiling examples/engine/deferred.mrsl");
        // The kernels of the two modes this engine runs.
        Ok(mrsl_runtime::compile_modes(
            include_str!("engine/deferred.mrsl"),
            "examples/engine/deferred.mrsl",
            &[Mode::Dynamic, Mode::Reference],
        )?)
    }
    #[cfg(not(feature = "compile"))]
    Err("usage: engine KERNEL_DIR [--out DIR]\n\
         KERNEL_DIR holds the files `mrslc compile` writes, e.g.:\n  \
         cargo run --release -p mrslc -- compile examples/engine/deferred.mrsl -o kernels\n  \
         cargo run --release -p mrsl-runtime --example engine -- kernels\n\
         (or build the example with `--features compile` to compile it at load time)"
        .into())
}

/// The engine's G-buffer, per pixel: what its geometry pass writes.
struct GBuffer {
    depth: Vec<f32>,
    normal: Vec<[f32; 3]>,
    albedo: Vec<[f32; 4]>,
    material: Vec<u8>,
}

/// The camera's view-projection: reversed depth with an infinite far plane
/// (clip = (x f / aspect, y f, NEAR, -z_view), so depth = NEAR / view depth),
/// as engines use for precision.
fn view_projection() -> Mat4 {
    let (eye, target) = (Vec3::from(EYE), Vec3::from(TARGET));
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let f = 1.0 / (FOV_Y_DEGREES.to_radians() / 2.0).tan();
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let row = |axis: Vec3, scale: f32| (axis * scale).extend(-axis.dot(eye) * scale);
    Mat4::from_cols(row(right, f / aspect), row(up, f), Vec4::new(0.0, 0.0, 0.0, NEAR), row(forward, 1.0)).transpose()
}

/// A sphere (centre (0, 0.7, 0), radius 0.7) on a ground plane seen from
/// `EYE`, ray-cast through each pixel's centre: depth, normal, albedo and
/// material (0 = ground, 1 = sphere, 255 = sky, at a depth of 100 units).
fn gbuffer() -> GBuffer {
    let (eye, target) = (Vec3::from(EYE), Vec3::from(TARGET));
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan_half = (FOV_Y_DEGREES.to_radians() / 2.0).tan();
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let vp = view_projection();
    let mut g = GBuffer { depth: vec![], normal: vec![], albedo: vec![], material: vec![] };
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let sx = (2.0 * (x as f32 + 0.5) / WIDTH as f32 - 1.0) * tan_half * aspect;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / HEIGHT as f32) * tan_half;
            let d = (forward + sx * right + sy * up).normalize();
            let oc = eye - Vec3::new(0.0, 0.7, 0.0);
            let (b, c) = (oc.dot(d), oc.dot(oc) - 0.49);
            let (t, n, m) = if b * b - c >= 0.0 && -b - (b * b - c).sqrt() > 0.0 {
                let t = -b - (b * b - c).sqrt();
                (t, (oc + t * d).normalize(), 1)
            } else if d.y < 0.0 {
                (-eye.y / d.y, Vec3::Y, 0)
            } else {
                (100.0, -d, 255)
            };
            let p = eye + t * d;
            let checker = ((p.x * 2.0).floor() + (p.z * 2.0).floor()).rem_euclid(2.0) == 0.0;
            let albedo = match m {
                1 => [0.8, 0.25, 0.12, 1.0],
                0 if checker => [0.75, 0.72, 0.66, 1.0],
                0 => [0.25, 0.24, 0.22, 1.0],
                _ => [0.0, 0.0, 0.0, 1.0],
            };
            let clip = vp * p.extend(1.0);
            g.depth.push(clip.z / clip.w);
            g.normal.push(n.to_array());
            g.albedo.push(albedo);
            g.material.push(m);
        }
    }
    g
}

/// A unit normal as an `Rgb10a2Unorm` texel: each component `n * 0.5 + 0.5`
/// in 10 bits (red lowest), alpha 0.
fn rgb10a2unorm(n: [f32; 3]) -> u32 {
    let bits = |c: f32| ((c * 0.5 + 0.5).clamp(0.0, 1.0) * 1023.0).round() as u32;
    bits(n[0]) | (bits(n[1]) << 10) | (bits(n[2]) << 20)
}

/// The depth texture of the geometry pass. WebGPU copies no data into a
/// `Depth32Float` texture, so a pass writes it, as a geometry pass would:
/// a full-screen triangle whose fragments take their depth from an
/// `R32Float` texture of the CPU depths.
fn depth_texture(device: &wgpu::Device, queue: &wgpu::Queue, depths: &[f32]) -> wgpu::Texture {
    let size = wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 };
    let make = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let values = make(
        "depth values",
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    let layout = wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(WIDTH * 4), rows_per_image: None };
    queue.write_texture(values.as_image_copy(), bytemuck::cast_slice(depths), layout, size);
    let depth = make(
        "depth",
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("geometry pass"),
        source: wgpu::ShaderSource::Wgsl(DEPTH_PASS.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("geometry pass"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    let view = values.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("geometry pass"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
    });
    let target = depth.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("geometry pass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, Some(&group), &[]);
        pass.draw(0..3, 0..1);
    }
    queue.submit([encoder.finish()]);
    depth
}

/// The depth pass: one full-screen triangle, each fragment's depth from the values texture.
const DEPTH_PASS: &str = "
@group(0) @binding(0) var values: texture_2d<f32>;
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(values, vec2<i32>(p.xy), 0).x;
}
";

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
    path: &std::path::Path,
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
