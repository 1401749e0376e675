//! G-buffers as engines store them, made from a lab G-buffer and the camera
//! it was drawn with: a depth texture (for `@depth` position channels),
//! octahedral normals (for `@encoded(octahedral)`) and Bevy's deferred
//! G-buffer texel (for `@packed(bevy_deferred, ..)`), so that a program over
//! them can be compared with the same program over the float channels.

use crate::camera::{Camera, CameraError};
use crate::gpu::Gpu;
use glam::{Mat4, Vec4};

/// `program` (examples/demo.mrsl, or a program that declares its channels
/// as it does) over a depth texture and normals stored as `encoding`
/// (`@encoded(ENCODING)`): its position rebuilt with
/// `@depth(inverse_view_proj)`, a uniform it gains. `None` when the program
/// does not declare `position` and `normal` as the demo does.
pub fn over_depth(program: &str, encoding: &str) -> Option<String> {
    let position = "@surface_key(normal, 0.05) in float3 position;";
    let normal = "@key(0.4) in float3 normal;";
    if !(program.contains(position) && program.contains(normal)) {
        return None;
    }
    let rebuilt = program
        .replace(position, "@surface_key(normal, 0.05) @depth(inverse_view_proj) in float3 position;")
        .replace(normal, &format!("@key(0.4) @encoded({encoding}) in float3 normal;"));
    Some(rebuilt + "\nuniform float4x4 inverse_view_proj;\n")
}

/// The near plane the depth is projected with.
pub const NEAR: f32 = 0.05;

/// The view-projection `camera` draws a `size` image with (reversed depth,
/// infinite far plane: [`Camera::view_projection`]), and its inverse, as
/// the column-major values a `uniform float4x4` takes.
pub fn view_projection(camera: &Camera, size: (u32, u32)) -> Result<(Mat4, [f32; 16]), CameraError> {
    let vp = camera.view_projection(size.0 as f32 / size.1 as f32, NEAR)?;
    Ok((vp, vp.inverse().to_cols_array()))
}

/// Each pixel's depth as `vp` projects its position (`positions`:
/// `components` floats a pixel, x, y, z first, as a lab channel holds them).
pub fn depths(positions: &[f32], components: usize, vp: Mat4) -> Vec<f32> {
    positions
        .chunks_exact(components)
        .map(|p| {
            let clip = vp * Vec4::new(p[0], p[1], p[2], 1.0);
            clip.z / clip.w
        })
        .collect()
}

/// The octahedral encoding of a unit vector, both components in -1 to 1
/// (the inverse of the kernels' `@encoded(octahedral)` decoding).
pub fn octahedral(n: [f32; 3]) -> [f32; 2] {
    let sum = n[0].abs() + n[1].abs() + n[2].abs();
    let (x, y) = (n[0] / sum, n[1] / sum);
    if n[2] >= 0.0 {
        [x, y]
    } else {
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        [(1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y)]
    }
}

/// A unit normal as an `Rgb10a2Unorm` texel (Bevy's prepass normals): each
/// component `n * 0.5 + 0.5` in 10 bits, red lowest, alpha 0; what
/// `@encoded(unorm)` reads back.
pub fn rgb10a2unorm(n: [f32; 3]) -> u32 {
    let bits = |c: f32| ((c * 0.5 + 0.5).clamp(0.0, 1.0) * 1023.0).round() as u32;
    bits(n[0]) | (bits(n[1]) << 10) | (bits(n[2]) << 20)
}

/// A `Depth32Float` texture (TEXTURE_BINDING) holding `depths`. WebGPU
/// copies no data into a depth32float texture, so a render pass writes it:
/// a full-screen triangle whose fragments read their depth from an
/// `R32Float` texture and write it as `frag_depth`.
pub fn depth_texture(gpu: &Gpu, size: (u32, u32), depths: &[f32]) -> wgpu::Texture {
    let device = &gpu.device;
    let source =
        gpu.texture_with_data("depth values", size, wgpu::TextureFormat::R32Float, bytemuck::cast_slice(depths));
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
    let depth = gpu.texture_2d("depth", size, wgpu::TextureFormat::Depth32Float, usage);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth upload"),
        source: wgpu::ShaderSource::Wgsl(include_str!("depth_upload.wgsl").into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("depth upload"),
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
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("depth upload"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&source.create_view(&Default::default())),
        }],
    });
    let view = depth.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth upload"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, Some(&group), &[]);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    depth
}

/// What a pixel of Bevy's deferred G-buffer holds (the lab's G-buffer has
/// no emissive, reflectance or flags of its own: they get Bevy's defaults).
pub struct BevySurface {
    pub base_color: [f32; 3],
    pub perceptual_roughness: f32,
    pub normal: [f32; 3],
}

/// Bevy 0.19's deferred G-buffer texel (`Rgba32Uint`) of a surface, packed
/// as its `deferred_gbuffer_from_pbr_input` packs it: x the base colour with
/// a 1/2.2 gamma and the roughness as unorm4x8, y no emissive (rgb9e5 of
/// zero is 0), z reflectance 0.5, metallic 0 and occlusion 1 as unorm4x8,
/// w the octahedral normal in two 12-bit halves and no flags.
pub fn bevy_deferred(s: &BevySurface) -> [u32; 4] {
    let unorm4x8 = |v: [f32; 4]| {
        v.iter().enumerate().fold(0u32, |word, (k, c)| word | (((c.clamp(0.0, 1.0) * 255.0).round() as u32) << (8 * k)))
    };
    let gamma = |c: f32| c.max(0.0).powf(1.0 / 2.2);
    let color = [gamma(s.base_color[0]), gamma(s.base_color[1]), gamma(s.base_color[2]), s.perceptual_roughness];
    let [x, y] = octahedral(s.normal).map(|e| ((e * 0.5 + 0.5).clamp(0.0, 1.0) * 4095.0) as u32);
    [unorm4x8(color), 0, unorm4x8([0.5, 0.0, 1.0, 0.0]), (x & 0xfff) | ((y & 0xfff) << 12)]
}
