//! A G-buffer rasteriser: draws a [`Mesh`] with a wgpu render pipeline into
//! the channels a deferred renderer's geometry pass writes (see
//! [`crate::scene`] and docs/scenes.md), as textures that a
//! [`crate::Shader`] binds directly.
//!
//! | channel     | format        | content                                                  |
//! | ----------- | ------------- | -------------------------------------------------------- |
//! | `position`  | `Rgba32Float` | world-space position (w = 0)                             |
//! | `normal`    | `Rgba32Float` | unit shading normal, normal-mapped, towards the camera   |
//! | `uv`        | `Rg32Float`   | texture coordinates                                      |
//! | `material`  | `R32Uint`     | material id; [`BACKGROUND`] where nothing was drawn      |
//! | `depth`     | `R32Float`    | distance from the camera's eye                           |
//! | `albedo`    | `Rgba32Float` | linear base colour × factor × vertex colour; a: alpha    |
//! | `roughness` | `R32Float`    | perceptual roughness, factor × texture (G)               |
//! | `metallic`  | `R32Float`    | metalness, factor × texture (B)                          |
//! | `velocity`  | `Rg32Float`   | current minus previous projected position, in pixels     |
//!
//! Each material is drawn with its own bind group: its factors and its
//! textures, sampled with trilinear filtering from mipmaps made on the CPU
//! ([`crate::image_texture::mip_chain`]); the level of detail comes from the
//! derivatives of uv across each 2x2 pixel quad, as in any geometry pass.
//! Base colour textures are `Rgba8UnormSrgb`, so the sampler decodes sRGB to
//! linear before filtering; metallic-roughness and normal maps are linear.
//! Normal maps perturb the interpolated normal in the tangent frame (the
//! tangent made orthogonal to the normal, bitangent = w · normal × tangent).
//! Materials without a texture sample a 1x1 white (or flat-normal) texture,
//! so their constant factors come through unchanged.
//!
//! WebGPU's default `max_color_attachment_bytes_per_sample` is 32 bytes,
//! and position and normal alone take 32, so the mesh is drawn three times
//! with a shared `Depth32Float` buffer: pass 1 writes position and normal
//! (and the depth buffer), pass 2 uv, material, depth and velocity (24
//! bytes), pass 3 albedo,
//! roughness and metallic, the last two where the depth equals pass 1's
//! (the vertex position is `@invariant`). Where coplanar triangles tie,
//! the last one drawn wins in every pass (pass 1 tests greater-or-equal),
//! so a pixel's channels all come from one triangle. Alpha-masked materials
//! (glTF `MASK`) discard the same fragments in all three passes. Depth is
//! reversed (1 at the near plane, 0 at infinity) with an infinite far plane,
//! which keeps float depth precise over Sponza's whole depth range.
//!
//! Background pixels follow the CPU demo scene's convention: material
//! [`BACKGROUND`], the normal pointing back along the view ray, the position
//! on the ray at [`background_distance`], and that distance as depth; albedo
//! (0, 0, 0, 0), roughness 1 and metallic 0.
//! Triangles are two-sided: a triangle seen from behind reports its normal
//! flipped, so every normal in the G-buffer faces the camera.
//!
//! **Motion vectors.** [`Rasterizer::render_moving`] takes the previous
//! frame's camera besides the current one: the scenes are static, so the
//! camera alone moves things, and `velocity` is the surface point's pixel
//! position projected by the current camera minus its position projected by
//! the previous one (pixel units, x right, y down; `(x + 0.5, y + 0.5)` is a
//! pixel's centre in both). Both projections are computed in the fragment
//! shader from the interpolated world position with the same arithmetic, so
//! an unmoved camera gives exactly zero. The background has velocity 0, as
//! has a point behind the previous camera (it was not on screen; there is no
//! position to come from). Without a previous camera ([`Rasterizer::render`])
//! the channel is 0 everywhere, and programs that do not declare `in float2
//! velocity` never see it (the runtime ignores channels a program does not
//! read).

use crate::camera::{Camera, CameraError};
use crate::gbuffer::{BACKGROUND, ChannelData, GBuffer};
use crate::gpu::Gpu;
use crate::image_texture::{ImageTexture, TexelEncoding, TextureImage};
use crate::material::{Material, Wrap};
use crate::mesh::{Bounds, Mesh, MeshError};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// Channel names and formats, in the order [`Rasterizer::render`] returns them
/// (the same as [`GBuffer::upload`] makes for the CPU scenes).
pub const CHANNELS: [(&str, wgpu::TextureFormat); 9] = [
    ("position", wgpu::TextureFormat::Rgba32Float),
    ("normal", wgpu::TextureFormat::Rgba32Float),
    ("uv", wgpu::TextureFormat::Rg32Float),
    ("material", wgpu::TextureFormat::R32Uint),
    ("depth", wgpu::TextureFormat::R32Float),
    ("albedo", wgpu::TextureFormat::Rgba32Float),
    ("roughness", wgpu::TextureFormat::R32Float),
    ("metallic", wgpu::TextureFormat::R32Float),
    ("velocity", wgpu::TextureFormat::Rg32Float),
];

/// Which channels each pass writes (indices into [`CHANNELS`], in the order
/// of the fragment shaders' `@location`s). Velocity is last in [`CHANNELS`],
/// so that the first eight keep the CPU scenes' order, but is written by
/// pass 2, the one with room left under the 32-byte limit.
const PASSES: [&[usize]; 3] = [&[0, 1], &[2, 3, 4, 8], &[5, 6, 7]];

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
    #[error("texture {image} is {width}x{height}, larger than the device's {limit}-texel limit")]
    TextureTooLarge { image: String, width: u32, height: u32, limit: u32 },
    #[error(transparent)]
    BadCamera(#[from] CameraError),
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
}

/// Distance of the background from the eye: 50 (the demo scene's) or twice
/// the distance to the farthest corner of `bounds`, whichever is larger.
pub fn background_distance(bounds: Option<&Bounds>, camera: &Camera) -> f32 {
    let farthest = bounds
        .map(|b| b.corners().iter().map(|&c| Vec3::from(c).distance(Vec3::from(camera.eye))).fold(0.0f32, f32::max))
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
    tangent: [f32; 4],
    color: [f32; 4],
}

/// A material's factors as the shader reads them.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MaterialUniform {
    base_color: [f32; 4],
    /// x: roughness, y: metallic, z: normal scale, w: alpha cutoff (negative: none).
    params: [f32; 4],
    /// x: 1 where a normal map applies; y: 1 to sample at (u, 1 − v).
    flags: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    /// Column-major view-projection matrix.
    view_proj: [[f32; 4]; 4],
    /// The previous frame's (the same as `view_proj` without one).
    previous_view_proj: [[f32; 4]; 4],
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

impl Globals {
    /// The globals of a `size` image of a mesh with `bounds` seen from
    /// `camera`, `previous` (else `camera`) giving the motion vectors.
    fn new(
        bounds: Option<&Bounds>,
        camera: &Camera,
        previous: Option<&Camera>,
        size: (u32, u32),
    ) -> Result<Globals, RasterError> {
        let (width, height) = size;
        let (forward, right, up) = camera.basis()?;
        let tan_half = (camera.fov_y_degrees.to_radians() / 2.0).tan();
        let aspect = width as f32 / height as f32;
        let far = background_distance(bounds, camera);
        let near = bounds.map(|b| 1e-4 * b.diagonal()).unwrap_or(1e-3).max(1e-6);
        let view_proj = camera.view_projection(aspect, near)?.to_cols_array_2d();
        let previous_view_proj = match previous {
            Some(previous) => previous.view_projection(aspect, near)?.to_cols_array_2d(),
            None => view_proj,
        };
        Ok(Globals {
            view_proj,
            previous_view_proj,
            eye: [camera.eye[0], camera.eye[1], camera.eye[2], far],
            right: [right[0], right[1], right[2], tan_half * aspect],
            up: [up[0], up[1], up[2], tan_half],
            forward: [forward[0], forward[1], forward[2], 0.0],
            size: [width as f32, height as f32, 0.0, 0.0],
        })
    }
}

/// The passes' shaders; `BACKGROUND_ID` is replaced by [`BACKGROUND`].
const SHADER: &str = include_str!("raster.wgsl");

/// The bind group layouts: group 0, the globals; group 1, a material
/// (factors, three textures, a sampler).
fn bind_group_layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
    let uniform = |binding, size: usize| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    };
    let globals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mrsl rasteriser globals"),
        entries: &[uniform(0, std::mem::size_of::<Globals>())],
    });
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let material_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mrsl rasteriser material"),
        entries: &[
            uniform(0, std::mem::size_of::<MaterialUniform>()),
            texture(1),
            texture(2),
            texture(3),
            wgpu::BindGroupLayoutEntry {
                binding: 4,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    });
    (globals_layout, material_layout)
}

/// The mesh and background pipelines of passes 1 to 3: pass 1 writes the
/// depth buffer (greater-or-equal, reversed depth), passes 2 and 3 draw
/// where the depth equals it.
fn pipelines(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    globals_layout: &wgpu::BindGroupLayout,
    material_layout: &wgpu::BindGroupLayout,
) -> ([wgpu::RenderPipeline; 3], [wgpu::RenderPipeline; 3]) {
    let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("mrsl rasteriser mesh"),
        bind_group_layouts: &[Some(globals_layout), Some(material_layout)],
        immediate_size: 0,
    });
    let background_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("mrsl rasteriser background"),
        bind_group_layouts: &[Some(globals_layout)],
        immediate_size: 0,
    });
    let attributes = wgpu::vertex_attr_array![
        0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32, 4 => Float32x4, 5 => Float32x4
    ];
    let vertex_layout = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    };
    let targets = |pass: usize| -> Vec<Option<wgpu::ColorTargetState>> {
        PASSES[pass]
            .iter()
            .map(|&i| {
                let format = CHANNELS[i].1;
                Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
            })
            .collect()
    };
    let pipeline = |label: &str,
                    layout: &wgpu::PipelineLayout,
                    vs: &str,
                    fs: &str,
                    buffers: &[Option<wgpu::VertexBufferLayout>],
                    pass: usize,
                    write: bool,
                    compare: wgpu::CompareFunction| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
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
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &targets(pass),
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    use wgpu::CompareFunction::{Equal, GreaterEqual};
    let vertex = [Some(vertex_layout)];
    let mesh = [0, 1, 2].map(|pass| {
        let (write, compare) = if pass == 0 { (true, GreaterEqual) } else { (false, Equal) };
        let label = format!("mrsl raster mesh {}", pass + 1);
        pipeline(&label, &mesh_layout, "vs_mesh", &format!("fs_mesh{}", pass + 1), &vertex, pass, write, compare)
    });
    let background = [0, 1, 2].map(|pass| {
        let label = format!("mrsl raster background {}", pass + 1);
        let fs = format!("fs_background{}", pass + 1);
        pipeline(&label, &background_layout, "vs_background", &fs, &[], pass, false, Equal)
    });
    (mesh, background)
}

/// A mesh in GPU buffers, its triangles grouped by material, with each
/// material's bind group (factors and textures).
pub struct GpuMesh {
    vertices: Option<wgpu::Buffer>,
    indices: Option<wgpu::Buffer>,
    /// (first index, index count, bind group) per run of one material.
    draws: Vec<(u32, u32, usize)>,
    bind_groups: Vec<wgpu::BindGroup>,
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
    material_layout: wgpu::BindGroupLayout,
    /// Mesh pipelines of passes 1 to 3, then the background's.
    mesh: [wgpu::RenderPipeline; 3],
    background: [wgpu::RenderPipeline; 3],
    /// 1x1 stand-ins for missing textures: white sRGB, white linear, flat normal.
    white_srgb: wgpu::TextureView,
    white_linear: wgpu::TextureView,
    flat_normal: wgpu::TextureView,
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
        let (globals_layout, material_layout) = bind_group_layouts(device);
        let (mesh, background) = pipelines(device, &module, &globals_layout, &material_layout);
        let pixel = |label: &str, format, texel: [u8; 4]| {
            gpu.texture_with_data(label, (1, 1), format, &texel).create_view(&Default::default())
        };
        let white_srgb = pixel("mrsl white", wgpu::TextureFormat::Rgba8UnormSrgb, [255; 4]);
        let white_linear = pixel("mrsl white", wgpu::TextureFormat::Rgba8Unorm, [255; 4]);
        let flat_normal = pixel("mrsl flat normal", wgpu::TextureFormat::Rgba8Unorm, [128, 128, 255, 255]);
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(RasterError::Pipeline(mrsl_runtime::gpu::describe(&error)));
        }
        Ok(Rasterizer { globals_layout, material_layout, mesh, background, white_srgb, white_linear, flat_normal })
    }

    /// Uploads a mesh (after checking it with [`Mesh::validate`]): its
    /// vertices, its triangles grouped by material (in the order of first
    /// use, each material's triangles in their original order), and each
    /// material's factors and textures with their mipmaps.
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
            return Ok(GpuMesh { vertices: None, indices: None, draws: vec![], bind_groups: vec![], bounds: None });
        }
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i],
                normal: mesh.normals[i],
                uv: mesh.uvs[i],
                material: mesh.materials[i],
                tangent: mesh.tangents.get(i).copied().unwrap_or([0.0; 4]),
                color: mesh.colors.get(i).copied().unwrap_or([1.0; 4]),
            })
            .collect();
        // Triangles grouped by material, so that each material is one draw.
        let mut order: Vec<u32> = vec![];
        let mut runs: Vec<(u32, Vec<u32>)> = vec![];
        for t in mesh.indices.chunks_exact(3) {
            let id = mesh.materials[t[0] as usize];
            match runs.iter_mut().find(|(m, _)| *m == id) {
                Some((_, list)) => list.extend_from_slice(t),
                None => runs.push((id, t.to_vec())),
            }
        }
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut textures = TextureCache::default();
        let mut draws = vec![];
        let mut bind_groups = vec![];
        for (id, list) in runs {
            let first = order.len() as u32;
            order.extend_from_slice(&list);
            bind_groups.push(self.material_bind_group(gpu, &mesh.material(id), &mut textures)?);
            draws.push((first, list.len() as u32, bind_groups.len() - 1));
        }
        let vertices = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let indices = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster indices"),
            contents: bytemuck::cast_slice(&order),
            usage: wgpu::BufferUsages::INDEX,
        });
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(RasterError::Render(mrsl_runtime::gpu::describe(&error)));
        }
        Ok(GpuMesh { vertices: Some(vertices), indices: Some(indices), draws, bind_groups, bounds: mesh.bounds() })
    }

    /// A material's bind group: its factors, its textures (uploaded once
    /// each, through `cache`) or the 1x1 stand-ins, and a trilinear sampler
    /// with its wrap modes.
    fn material_bind_group(
        &self,
        gpu: &Gpu,
        material: &Material,
        cache: &mut TextureCache,
    ) -> Result<wgpu::BindGroup, RasterError> {
        let uniform = MaterialUniform {
            base_color: material.base_color,
            params: [
                material.roughness,
                material.metallic,
                material.normal_scale,
                material.alpha_cutoff.unwrap_or(-1.0),
            ],
            flags: [u32::from(material.has_normal_map()), u32::from(material.flip_v), 0, 0],
        };
        let buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl raster material"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut view =
            |image: &Option<std::sync::Arc<TextureImage>>, encoding, fallback: &wgpu::TextureView| match image {
                Some(image) => cache.view(gpu, image, encoding).cloned(),
                None => Ok(fallback.clone()),
            };
        let base = view(&material.base_color_texture, TexelEncoding::Srgb, &self.white_srgb)?;
        let mr = view(&material.metallic_roughness_texture, TexelEncoding::Linear, &self.white_linear)?;
        let normal = view(&material.normal_texture, TexelEncoding::Normal, &self.flat_normal)?;
        let sampler = cache.sampler(gpu, material.wrap);
        Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl raster material"),
            layout: &self.material_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&base) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&mr) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&normal) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&sampler) },
            ],
        }))
    }

    /// Draws `mesh` from `camera` into new G-buffer textures, named and
    /// formatted as [`CHANNELS`], usable as `TEXTURE_BINDING` and `COPY_SRC`
    /// (and `RENDER_ATTACHMENT`). The commands are submitted. `velocity` is
    /// 0: see [`Rasterizer::render_moving`].
    pub fn render(
        &self,
        gpu: &Gpu,
        mesh: &GpuMesh,
        camera: &Camera,
        size: (u32, u32),
    ) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
        self.render_moving(gpu, mesh, camera, None, size)
    }

    /// [`Rasterizer::render`] with the previous frame's camera, if any, for
    /// the `velocity` channel (see the module's documentation).
    pub fn render_moving(
        &self,
        gpu: &Gpu,
        mesh: &GpuMesh,
        camera: &Camera,
        previous: Option<&Camera>,
        size: (u32, u32),
    ) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
        let (width, height) = size;
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RasterError::BadSize { width, height, reason: format!("each side must be 1 to {max} pixels") });
        }
        let globals = Globals::new(mesh.bounds.as_ref(), camera, previous, size)?;

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
                    | wgpu::TextureUsages::COPY_SRC
                    | crate::gpu::storage_readable(format);
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
        for pass in 0..PASSES.len() {
            self.encode_pass(&mut encoder, pass, &views, &depth_view, &bind_group, mesh);
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(RasterError::Render(mrsl_runtime::gpu::describe(&error)));
        }
        Ok(channels)
    }

    /// Pass `pass` (0 to 2): the mesh, then the background behind it,
    /// into the pass's channels of `views`.
    fn encode_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pass: usize,
        views: &[wgpu::TextureView],
        depth_view: &wgpu::TextureView,
        bind_group: &wgpu::BindGroup,
        mesh: &GpuMesh,
    ) {
        let written = PASSES[pass];
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = written
            .iter()
            .map(|&i| {
                Some(wgpu::RenderPassColorAttachment {
                    view: &views[i],
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let label = format!("mrsl raster pass {}", pass + 1);
        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(&label),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth_view,
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
        rp.set_bind_group(0, bind_group, &[]);
        if let (Some(vertices), Some(indices)) = (&mesh.vertices, &mesh.indices) {
            rp.set_pipeline(&self.mesh[pass]);
            rp.set_vertex_buffer(0, vertices.slice(..));
            rp.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            for &(first, count, group) in &mesh.draws {
                rp.set_bind_group(1, &mesh.bind_groups[group], &[]);
                rp.draw_indexed(first..first + count, 0, 0..1);
            }
        }
        rp.set_pipeline(&self.background[pass]);
        rp.draw(0..3, 0..1);
    }
}

/// Textures uploaded for one mesh (each image once per encoding, keyed by
/// its allocation: materials share images through `Arc`), and samplers per
/// pair of wrap modes.
#[derive(Default)]
struct TextureCache {
    views: std::collections::HashMap<(usize, TexelEncoding), wgpu::TextureView>,
    samplers: std::collections::HashMap<[Wrap; 2], wgpu::Sampler>,
}

impl TextureCache {
    fn view(
        &mut self,
        gpu: &Gpu,
        image: &std::sync::Arc<TextureImage>,
        encoding: TexelEncoding,
    ) -> Result<&wgpu::TextureView, RasterError> {
        let key = (std::sync::Arc::as_ptr(image) as usize, encoding);
        let entry = match self.views.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => return Ok(e.into_mut()),
            std::collections::hash_map::Entry::Vacant(e) => e,
        };
        let limit = gpu.device.limits().max_texture_dimension_2d;
        if image.width > limit || image.height > limit {
            return Err(RasterError::TextureTooLarge {
                image: image.source.clone(),
                width: image.width,
                height: image.height,
                limit,
            });
        }
        let texture = ImageTexture::new(image, encoding).upload(gpu, &image.source);
        Ok(entry.insert(texture.create_view(&Default::default())))
    }

    fn sampler(&mut self, gpu: &Gpu, wrap: [Wrap; 2]) -> wgpu::Sampler {
        let mode = |w: Wrap| match w {
            Wrap::Repeat => wgpu::AddressMode::Repeat,
            Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
            Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        };
        self.samplers
            .entry(wrap)
            .or_insert_with(|| {
                gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("mrsl raster material"),
                    address_mode_u: mode(wrap[0]),
                    address_mode_v: mode(wrap[1]),
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    mipmap_filter: wgpu::MipmapFilterMode::Linear,
                    ..Default::default()
                })
            })
            .clone()
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
                    "uv" | "velocity" => 2,
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
