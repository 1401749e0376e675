//! A G-buffer rasteriser: draws a [`Mesh`] with a wgpu render pipeline into
//! the channels every scene provides (see [`crate::scene`]), as textures
//! that a [`crate::Shader`] binds directly.
//!
//! | channel    | format        | content                                             |
//! | ---------- | ------------- | --------------------------------------------------- |
//! | `position` | `Rgba32Float` | world-space position (w = 0)                        |
//! | `normal`   | `Rgba32Float` | unit world-space normal, towards the camera (w = 0) |
//! | `uv`       | `Rg32Float`   | texture coordinates                                 |
//! | `material` | `R32Uint`     | material id; [`BACKGROUND`] where nothing was drawn |
//! | `depth`    | `R32Float`    | distance from the camera's eye                      |
//!
//! WebGPU's default `max_color_attachment_bytes_per_sample` is 32 bytes,
//! and position and normal alone take 32, so the mesh is drawn twice with a
//! shared `Depth32Float` buffer: pass 1 writes position and normal (and the
//! depth buffer), pass 2 writes uv, material and depth where the depth
//! equals pass 1's (the vertex position is `@invariant`). Where coplanar
//! triangles tie, the last one drawn wins in both passes (pass 1 tests
//! greater-or-equal), so a pixel's channels all come from one triangle.
//! Depth is reversed
//! (1 at the near plane, 0 at infinity) with an infinite far plane, which
//! keeps float depth precise over Sponza's whole depth range.
//!
//! Background pixels follow the CPU demo scene's convention: material
//! [`BACKGROUND`], the normal pointing back along the view ray, the position
//! on the ray at [`background_distance`], and that distance as depth.
//! Triangles are two-sided: a triangle seen from behind reports its normal
//! flipped, so every normal in the G-buffer faces the camera.

use crate::gbuffer::{BACKGROUND, ChannelData, GBuffer};
use crate::gpu::Gpu;
use crate::mesh::{Bounds, Mesh, MeshError, cross, dot, normalize, sub};
use wgpu::util::DeviceExt;

/// Channel names and formats, in the order [`Rasterizer::render`] returns them
/// (the same as [`GBuffer::upload`] makes for the CPU scenes).
pub const CHANNELS: [(&str, wgpu::TextureFormat); 5] = [
    ("position", wgpu::TextureFormat::Rgba32Float),
    ("normal", wgpu::TextureFormat::Rgba32Float),
    ("uv", wgpu::TextureFormat::Rg32Float),
    ("material", wgpu::TextureFormat::R32Uint),
    ("depth", wgpu::TextureFormat::R32Float),
];

/// Why rasterising failed.
#[derive(Debug, thiserror::Error)]
pub enum RasterError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("the device rejected the rasteriser's pipelines: {0}")]
    Pipeline(String),
    #[error("the device rejected the rasteriser's commands: {0}")]
    Render(String),
    #[error("G-buffer size {width}x{height} is not supported: {reason}")]
    BadSize { width: u32, height: u32, reason: String },
    #[error("the mesh's {what} need {bytes} bytes, more than the device's {limit}-byte buffer limit")]
    TooLarge { what: &'static str, bytes: u64, limit: u64 },
    #[error("bad camera: {0}")]
    BadCamera(String),
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
}

/// A camera's unit view direction, right axis and up axis.
pub type Basis = ([f32; 3], [f32; 3], [f32; 3]);

/// A pinhole camera. Right-handed world, `up` is a hint (it need not be
/// orthogonal to the view direction); image rows run top to bottom, and
/// pixel `(x, y)` sees along the ray through its centre `(x + 0.5, y + 0.5)`,
/// exactly as the CPU demo scene's camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
}

impl Camera {
    /// A camera with the world's +y as up.
    pub fn look_at(eye: [f32; 3], target: [f32; 3], fov_y_degrees: f32) -> Camera {
        Camera { eye, target, up: [0.0, 1.0, 0.0], fov_y_degrees }
    }

    /// A camera that sees all of `bounds` from the front (+z), a little to
    /// the right and above, for an image of the given aspect ratio (width /
    /// height): the bounding sphere fits in both fields of view.
    pub fn frame(bounds: &Bounds, fov_y_degrees: f32, aspect: f32) -> Camera {
        let center = bounds.center();
        let radius = (0.5 * bounds.diagonal()).max(1e-6);
        let half_y = (fov_y_degrees.to_radians() / 2.0).clamp(1e-3, 1.55);
        let half_x = (half_y.tan() * aspect.max(1e-3)).atan();
        let distance = radius / half_y.min(half_x).sin();
        let dir = normalize([0.35, 0.3, 1.0]);
        let eye = [0, 1, 2].map(|k| center[k] + distance * dir[k]);
        Camera::look_at(eye, center, fov_y_degrees)
    }

    /// The unit view direction and the camera's unit right and up axes.
    pub fn basis(&self) -> Result<Basis, RasterError> {
        let forward = normalize(sub(self.target, self.eye));
        if dot(forward, forward) == 0.0 {
            return Err(RasterError::BadCamera("the eye and the target are the same point".into()));
        }
        let right = normalize(cross(forward, self.up));
        if dot(right, right) == 0.0 || !right.iter().all(|v| v.is_finite()) {
            return Err(RasterError::BadCamera("`up` is parallel to the view direction".into()));
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            return Err(RasterError::BadCamera(format!(
                "the field of view must be between 0 and 180 degrees, not {}",
                self.fov_y_degrees
            )));
        }
        Ok((forward, right, cross(right, forward)))
    }

    /// The unit direction of the ray through the centre of pixel `(x, y)`.
    pub fn ray(&self, x: u32, y: u32, size: (u32, u32)) -> Result<[f32; 3], RasterError> {
        let (forward, right, up) = self.basis()?;
        let tan_half = (self.fov_y_degrees.to_radians() / 2.0).tan();
        let aspect = size.0 as f32 / size.1 as f32;
        let sx = (2.0 * (x as f32 + 0.5) / size.0 as f32 - 1.0) * tan_half * aspect;
        let sy = (1.0 - 2.0 * (y as f32 + 0.5) / size.1 as f32) * tan_half;
        Ok(normalize([0, 1, 2].map(|k| forward[k] + sx * right[k] + sy * up[k])))
    }
}

/// Distance of the background from the eye: 50 (the demo scene's) or twice
/// the distance to the farthest corner of `bounds`, whichever is larger.
pub fn background_distance(bounds: Option<&Bounds>, camera: &Camera) -> f32 {
    let farthest = bounds
        .map(|b| b.corners().iter().map(|c| crate::mesh::length(sub(*c, camera.eye))).fold(0.0f32, f32::max))
        .unwrap_or(0.0);
    (2.0 * farthest).max(50.0)
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    material: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    /// Column-major view-projection matrix.
    view_proj: [[f32; 4]; 4],
    /// xyz: eye; w: background distance.
    eye: [f32; 4],
    /// xyz: right axis; w: tan(fov / 2) * aspect.
    right: [f32; 4],
    /// xyz: up axis; w: tan(fov / 2).
    up: [f32; 4],
    forward: [f32; 4],
    /// xy: image size in pixels.
    size: [f32; 4],
}

const SHADER: &str = r#"
struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    size: vec4<f32>,
};
@group(0) @binding(0) var<uniform> g: Globals;

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
};

struct Pass1 {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
};

struct Pass2 {
    @location(0) uv: vec2<f32>,
    @location(1) material: u32,
    @location(2) depth: f32,
};

@vertex
fn vs_mesh(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @location(2) uv: vec2<f32>,
           @location(3) material: u32) -> VsOut {
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.normal = n;
    out.uv = uv;
    out.material = material;
    return out;
}

@fragment
fn fs_mesh1(v: VsOut, @builtin(front_facing) front: bool) -> Pass1 {
    var n = v.normal;
    if (dot(n, n) > 0.0) {
        n = normalize(n);
    }
    if (!front) {
        n = -n;
    }
    return Pass1(vec4<f32>(v.world, 0.0), vec4<f32>(n, 0.0));
}

@fragment
fn fs_mesh2(v: VsOut) -> Pass2 {
    return Pass2(v.uv, v.material, distance(v.world, g.eye.xyz));
}

// A full-screen triangle at depth 0 (infinitely far with reversed depth).
@vertex
fn vs_background(@builtin(vertex_index) i: u32) -> @builtin(position) @invariant vec4<f32> {
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

fn view_ray(frag: vec2<f32>) -> vec3<f32> {
    let sx = (2.0 * frag.x / g.size.x - 1.0) * g.right.w;
    let sy = (1.0 - 2.0 * frag.y / g.size.y) * g.up.w;
    return normalize(g.forward.xyz + sx * g.right.xyz + sy * g.up.xyz);
}

@fragment
fn fs_background1(@builtin(position) frag: vec4<f32>) -> Pass1 {
    let d = view_ray(frag.xy);
    return Pass1(vec4<f32>(g.eye.xyz + g.eye.w * d, 0.0), vec4<f32>(-d, 0.0));
}

@fragment
fn fs_background2(@builtin(position) frag: vec4<f32>) -> Pass2 {
    return Pass2(vec2<f32>(0.0, 0.0), BACKGROUND_ID, g.eye.w);
}
"#;

/// A mesh in GPU buffers.
pub struct GpuMesh {
    vertices: Option<wgpu::Buffer>,
    indices: Option<wgpu::Buffer>,
    index_count: u32,
    bounds: Option<Bounds>,
}

impl GpuMesh {
    pub fn bounds(&self) -> Option<Bounds> {
        self.bounds
    }
}

/// The rasteriser's pipelines on one device: make it once, render many frames.
pub struct Rasterizer {
    globals_layout: wgpu::BindGroupLayout,
    mesh1: wgpu::RenderPipeline,
    mesh2: wgpu::RenderPipeline,
    background1: wgpu::RenderPipeline,
    background2: wgpu::RenderPipeline,
}

fn describe(error: &wgpu::Error) -> String {
    match error {
        wgpu::Error::Validation { description, .. } => description.clone(),
        other => other.to_string(),
    }
}

impl Rasterizer {
    pub fn new(gpu: &Gpu) -> Result<Rasterizer, RasterError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let source = SHADER.replace("BACKGROUND_ID", &format!("{BACKGROUND}u"));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mrsl rasteriser"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let globals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mrsl rasteriser globals"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Globals>() as u64),
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mrsl rasteriser"),
            bind_group_layouts: &[Some(&globals_layout)],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32];
        let vertex_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attributes,
        };
        let target = |(_, format): (&str, wgpu::TextureFormat)| {
            Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
        };
        let pass1_targets = [target(CHANNELS[0]), target(CHANNELS[1])];
        let pass2_targets = [target(CHANNELS[2]), target(CHANNELS[3]), target(CHANNELS[4])];
        let pipeline = |label: &str,
                        vs: &str,
                        fs: &str,
                        buffers: &[Option<wgpu::VertexBufferLayout>],
                        targets: &[Option<wgpu::ColorTargetState>],
                        write: bool,
                        compare: wgpu::CompareFunction| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::CompareFunction::{Equal, GreaterEqual};
        let mesh1 = pipeline(
            "mrsl raster mesh 1",
            "vs_mesh",
            "fs_mesh1",
            &[Some(vertex_layout.clone())],
            &pass1_targets,
            true,
            GreaterEqual,
        );
        let mesh2 =
            pipeline("mrsl raster mesh 2", "vs_mesh", "fs_mesh2", &[Some(vertex_layout)], &pass2_targets, false, Equal);
        let background1 =
            pipeline("mrsl raster background 1", "vs_background", "fs_background1", &[], &pass1_targets, false, Equal);
        let background2 =
            pipeline("mrsl raster background 2", "vs_background", "fs_background2", &[], &pass2_targets, false, Equal);
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(RasterError::Pipeline(describe(&error)));
        }
        Ok(Rasterizer { globals_layout, mesh1, mesh2, background1, background2 })
    }

    /// Uploads a mesh (after checking it with [`Mesh::validate`]).
    pub fn upload(&self, gpu: &Gpu, mesh: &Mesh) -> Result<GpuMesh, RasterError> {
        mesh.validate()?;
        let limit = gpu.device.limits().max_buffer_size;
        let vertex_bytes = (mesh.positions.len() * std::mem::size_of::<Vertex>()) as u64;
        let index_bytes = (mesh.indices.len() * 4) as u64;
        for (what, bytes) in [("vertices", vertex_bytes), ("indices", index_bytes)] {
            if bytes > limit {
                return Err(RasterError::TooLarge { what, bytes, limit });
            }
        }
        if mesh.indices.is_empty() {
            return Ok(GpuMesh { vertices: None, indices: None, index_count: 0, bounds: None });
        }
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i],
                normal: mesh.normals[i],
                uv: mesh.uvs[i],
                material: mesh.materials[i],
            })
            .collect();
        let vertices = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let indices = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster indices"),
            contents: bytemuck::cast_slice(&mesh.indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        Ok(GpuMesh {
            vertices: Some(vertices),
            indices: Some(indices),
            index_count: mesh.indices.len() as u32,
            bounds: mesh.bounds(),
        })
    }

    /// Draws `mesh` from `camera` into new G-buffer textures, named and
    /// formatted as [`CHANNELS`], usable as `TEXTURE_BINDING` and `COPY_SRC`
    /// (and `RENDER_ATTACHMENT`). The commands are submitted.
    pub fn render(
        &self,
        gpu: &Gpu,
        mesh: &GpuMesh,
        camera: &Camera,
        size: (u32, u32),
    ) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
        let (width, height) = size;
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RasterError::BadSize { width, height, reason: format!("each side must be 1 to {max} pixels") });
        }
        let (forward, right, up) = camera.basis()?;
        let tan_half = (camera.fov_y_degrees.to_radians() / 2.0).tan();
        let aspect = width as f32 / height as f32;
        let far = background_distance(mesh.bounds.as_ref(), camera);
        // Reversed, infinite projection: clip = (x f / aspect, y f, near, -z_view).
        let near = mesh.bounds.map(|b| 1e-4 * b.diagonal()).unwrap_or(1e-3).max(1e-6);
        let f = 1.0 / tan_half;
        let row = |axis: [f32; 3], scale: f32| {
            [axis[0] * scale, axis[1] * scale, axis[2] * scale, -dot(axis, camera.eye) * scale]
        };
        let rows = [row(right, f / aspect), row(up, f), [0.0, 0.0, 0.0, near], row(forward, 1.0)];
        let view_proj: [[f32; 4]; 4] = std::array::from_fn(|col| std::array::from_fn(|r| rows[r][col]));
        let globals = Globals {
            view_proj,
            eye: [camera.eye[0], camera.eye[1], camera.eye[2], far],
            right: [right[0], right[1], right[2], tan_half * aspect],
            up: [up[0], up[1], up[2], tan_half],
            forward: [forward[0], forward[1], forward[2], 0.0],
            size: [width as f32, height as f32, 0.0, 0.0],
        };

        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let globals_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster globals"),
            contents: bytemuck::bytes_of(&globals),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl raster globals"),
            layout: &self.globals_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: globals_buffer.as_entire_binding() }],
        });
        let texture = |label: &str, format, usage| gpu.texture_2d(label, size, format, usage);
        let channels: Vec<(String, wgpu::Texture)> = CHANNELS
            .iter()
            .map(|&(name, format)| {
                let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC;
                (name.to_string(), texture(name, format, usage))
            })
            .collect();
        let depth = texture(
            "mrsl raster depth buffer",
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_view = depth.create_view(&Default::default());
        let views: Vec<wgpu::TextureView> = channels.iter().map(|(_, t)| t.create_view(&Default::default())).collect();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mrsl raster") });
        for (pass, range) in [(0, 0..2), (1, 2..5)] {
            let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views[range]
                .iter()
                .map(|view| {
                    Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })
                })
                .collect();
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(if pass == 0 { "mrsl raster pass 1" } else { "mrsl raster pass 2" }),
                color_attachments: &attachments,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: if pass == 0 { wgpu::LoadOp::Clear(0.0) } else { wgpu::LoadOp::Load },
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_bind_group(0, &bind_group, &[]);
            if let (Some(vertices), Some(indices)) = (&mesh.vertices, &mesh.indices) {
                rp.set_pipeline(if pass == 0 { &self.mesh1 } else { &self.mesh2 });
                rp.set_vertex_buffer(0, vertices.slice(..));
                rp.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                rp.draw_indexed(0..mesh.index_count, 0, 0..1);
            }
            rp.set_pipeline(if pass == 0 { &self.background1 } else { &self.background2 });
            rp.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(RasterError::Render(describe(&error)));
        }
        Ok(channels)
    }
}

/// Rasterises `mesh` from `camera` at `size` into G-buffer textures (see
/// [`Rasterizer::render`]); makes the pipelines and uploads the mesh each
/// time, so use a [`Rasterizer`] to draw many frames.
pub fn rasterize(
    gpu: &Gpu,
    mesh: &Mesh,
    camera: &Camera,
    size: (u32, u32),
) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
    let rasterizer = Rasterizer::new(gpu)?;
    let uploaded = rasterizer.upload(gpu, mesh)?;
    rasterizer.render(gpu, &uploaded, camera, size)
}

/// [`rasterize`], read back into a CPU [`GBuffer`] (for tests and tools).
pub fn rasterize_gbuffer(gpu: &Gpu, mesh: &Mesh, camera: &Camera, size: (u32, u32)) -> Result<GBuffer, RasterError> {
    read_gbuffer(gpu, &rasterize(gpu, mesh, camera, size)?)
}

/// Reads G-buffer textures back into a [`GBuffer`]: float channels keep as
/// many components as the CPU scenes' (position and normal 3, uv 2, depth
/// 1; others all of their format's), `R32Uint` channels become `Uint`.
pub fn read_gbuffer(gpu: &Gpu, channels: &[(String, wgpu::Texture)]) -> Result<GBuffer, RasterError> {
    let (mut width, mut height) = (0, 0);
    let mut out = vec![];
    for (name, texture) in channels {
        (width, height) = (texture.width(), texture.height());
        let bytes = gpu.read_texture(texture)?;
        let data = match texture.format() {
            wgpu::TextureFormat::R32Uint => ChannelData::Uint(bytemuck::pod_collect_to_vec(&bytes)),
            format => {
                let stored = format.components() as usize;
                let kept = match name.as_str() {
                    "position" | "normal" => 3,
                    "uv" => 2,
                    "depth" => 1,
                    _ => stored,
                }
                .min(stored);
                let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
                let data: Vec<f32> = floats.chunks_exact(stored).flat_map(|px| px[..kept].iter().copied()).collect();
                ChannelData::Float { components: kept as u32, data }
            }
        };
        out.push((name.clone(), data));
    }
    Ok(GBuffer { width, height, channels: out })
}
