//! An engine using mrsl the way a real renderer would: it owns the wgpu
//! device, fills its own G-buffer textures, and lets the mrsl runtime record
//! its passes into the engine's command encoder, between the engine's own
//! work. Run it with:
//!
//! ```sh
//! cargo run -p mrsl-runtime --example engine            # writes engine.png and engine-reference.png
//! ```
//!
//! The G-buffer here is filled from the CPU (a sphere over a ground plane,
//! analytically); an engine would rasterise it in its own geometry pass.

use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};

const PROGRAM: &str = r#"
in float3 position;
in float3 normal;
@key in uint material;

uniform float3 light_dir = float3(0.4, 0.8, 0.45);
uniform float3 eye = float3(0.0, 1.2, 4.0);
uniform float threshold = 0.04;

coarse effect float diffuse {
    diffuse = saturate(dot(normal, normalize(light_dir)));
    if (fwidth(diffuse) > threshold) refine;
}
coarse effect float specular {
    float3 h = normalize(normalize(light_dir) + normalize(eye - position));
    specular = pow(saturate(dot(normal, h)), 48.0);
    if (specular > 0.05) refine;
}
fine effect float3 base = material == 1u ? float3(0.8, 0.3, 0.2) : float3(0.7, 0.7, 0.65);
fine out float4 color = float4(base * (0.08 + diffuse) + float3(specular), 1.0);
"#;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 270;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 1. The engine's own device.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: None,
        apply_limit_buckets: false,
    }))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))?;
    println!("adapter: {}", adapter.get_info().name);

    // 2. The engine's own G-buffer: position, normal (rgba32float), material (r32uint).
    let (position, normal, material) = gbuffer();
    let texture = |label: &str, format: wgpu::TextureFormat, bytes: &[u8], bytes_per_pixel: u32| {
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        queue.write_texture(
            t.as_image_copy(),
            bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(WIDTH * bytes_per_pixel),
                rows_per_image: None,
            },
            t.size(),
        );
        t
    };
    let position = texture("position", wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&position), 16);
    let normal = texture("normal", wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&normal), 16);
    let material = texture("material", wgpu::TextureFormat::R32Uint, bytemuck::cast_slice(&material), 4);
    let color = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("color"),
        size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });

    // 3. Compile the program and instantiate it on the engine's device.
    let program =
        mrsl::compile(PROGRAM, &mrsl::Options::default()).map_err(|d| mrsl::render_all(&d, "engine.mrsl", PROGRAM))?;
    let mut shader = Shader::new(&device, &program)?;
    shader.set_uniform("threshold", &[0.03])?;
    let mut bindings = Bindings { size: (WIDTH, HEIGHT), ..Default::default() };
    bindings.channels.insert("position".into(), &position);
    bindings.channels.insert("normal".into(), &normal);
    bindings.channels.insert("material".into(), &material);
    bindings.outputs.insert("color".into(), &color);

    for (mode, file) in [(Mode::Dynamic, "engine.png"), (Mode::Reference, "engine-reference.png")] {
        // 4. The engine's frame: its own passes, then mrsl's, in one encoder.
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        shader.encode(&device, &queue, &mut encoder, &bindings, DispatchOptions::new(mode))?;
        let readback = copy_out(&device, &mut encoder, &color);
        queue.submit([encoder.finish()]);
        println!("{}", shader.read_stats(&device)?.table());
        save_png(&device, &readback, file)?;
        println!("wrote {file}");
    }
    Ok(())
}

/// A sphere on a ground plane seen from `eye`, as world-space position,
/// normal and material per pixel (material 0 = ground, 1 = sphere, 2 = sky).
fn gbuffer() -> (Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<u32>) {
    let eye = [0.0f32, 1.2, 4.0];
    let (mut position, mut normal, mut material) = (vec![], vec![], vec![]);
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
                (100.0, [-d[0], -d[1], -d[2]], 2)
            };
            position.push([eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2], 1.0]);
            normal.push([n[0], n[1], n[2], 0.0]);
            material.push(m);
        }
    }
    (position, normal, material)
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

fn save_png(device: &wgpu::Device, buffer: &wgpu::Buffer, path: &str) -> Result<(), Box<dyn std::error::Error>> {
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
