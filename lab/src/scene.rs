//! G-buffers made on the CPU: the DACS test patterns (gradient, steps,
//! sinusoid) for precise tests, and an analytically ray-cast demo scene.
//!
//! Every scene provides the same channels, so any program reading a subset
//! of them runs on any scene: `position` (float3, world space), `normal`
//! (float3, unit), `uv` (float2), `material` (uint; 255 is the background),
//! `depth` (float, distance from the camera), the material channels of
//! a deferred renderer: `albedo` (float4, linear base colour and alpha),
//! `roughness` and `metallic` (floats in [0, 1]), and `velocity` (float2,
//! the screen-space motion in pixels: 0 here, where the camera never moves).
//!
//! The mesh scenes ([`Scene::Sponza`], [`Scene::Dungeon`],
//! [`Scene::Outdoor`], [`Scene::Small`], [`Scene::Generated`]: the
//! benchmark suite) are rasterised on the GPU by [`crate::raster`]: build
//! them with [`Scene::render_on`] or [`Scene::textures_on`]. See
//! docs/scenes.md.

use crate::camera::Camera;
use crate::camera_path::CameraPath;
pub use crate::gbuffer::{BACKGROUND, ChannelData, GBuffer};
use crate::gpu::Gpu;
use crate::mesh::{Mesh, MeshError};
use crate::mesh_scene::MeshScene;
use crate::raster::RasterError;
use crate::rig::{DEFAULT_LIGHTS, Layout, LightRig};
use glam::Vec3;
use std::sync::Arc;

// Sponza's default camera (see `Scene::sponza_camera`).
const SPONZA_EYE: [f32; 3] = [-11.5, 2.2, -0.3];
const SPONZA_TARGET: [f32; 3] = [10.0, 4.5, 0.4];
const SPONZA_FOV: f32 = 60.0;

// The dungeon's default camera (see `Scene::dungeon_camera`).
const DUNGEON_EYE: [f32; 3] = [-8.0, 3.0, 10.0];
const DUNGEON_TARGET: [f32; 3] = [15.0, 0.5, -4.0];
const DUNGEON_FOV: f32 = 60.0;

// The outdoor scene's default camera (see `Scene::outdoor_camera`).
const OUTDOOR_EYE: [f32; 3] = [340.6, 7.1, -899.0];
const OUTDOOR_TARGET: [f32; 3] = [540.4, 9.1, -897.3];
const OUTDOOR_FOV: f32 = 60.0;
// Towards its sun: lower than the other scenes' (44 degrees up), on the
// grandstand's side of the straight, so that shadows fall across the road.
const OUTDOOR_SUN: [f32; 3] = [0.5, 0.45, 0.7];

// The small scene's default camera (see `Scene::small_camera`).
const SMALL_EYE: [f32; 3] = [0.294, 0.191, 0.258];
const SMALL_TARGET: [f32; 3] = [0.042, 0.015, 0.006];
const SMALL_FOV: f32 = 40.0;

// The generated scene's default camera (see `Scene::generated_camera`).
const GENERATED_EYE: [f32; 3] = [-60.0, 12.0, -1300.0];
const GENERATED_TARGET: [f32; 3] = [-60.0, 110.0, 0.0];
const GENERATED_FOV: f32 = 60.0;
// Towards its sun: low (30 degrees up) and ahead of the camera, so that the
// facades it sees are lit and the towers cast long shadows.
const GENERATED_SUN: [f32; 3] = [0.35, 0.5, -0.8];

/// Which synthetic scene to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scene {
    /// Spheres on a checkered ground plane, under the demo program's default camera.
    Demo,
    /// A tilted plane whose position and uv vary linearly across the image.
    Gradient,
    /// Vertical stripes with constant, different normals and materials (step functions).
    Steps { count: u32 },
    /// A surface whose normal oscillates: `frequency` periods across the image along `angle` (degrees).
    Sinusoid { angle: f32, frequency: f32 },
    /// The Dabrovic Sponza atrium (a real model, 76k triangles, 35
    /// materials), rasterised on the GPU from [`Scene::sponza_camera`].
    Sponza,
    /// A textured game level (the Castle Game Engine's dungeon: base colour
    /// and normal maps), rasterised on the GPU from [`Scene::dungeon_camera`];
    /// fetched by `scripts/fetch-dungeon.sh` (see docs/scenes.md).
    Dungeon,
    /// An outdoor scene with a large sky: TORCS's "forza" race track
    /// (2.5 km, 129 textured materials, alpha-tested trees), seen from
    /// above the road ([`Scene::outdoor_camera`]); fetched by
    /// `scripts/fetch-outdoor.sh`.
    Outdoor,
    /// A small object: link 6 of the Franka Panda robot arm, 18 cm long,
    /// at its native scale against the background ([`Scene::small_camera`]);
    /// fetched by `scripts/fetch-small.sh`.
    Small,
    /// A generated city of towers and spheres, kilometres across
    /// ([`crate::procedural`], nothing to fetch), seen from above its edge
    /// ([`Scene::generated_camera`]).
    Generated,
}

/// Why a scene could not be built.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Raster(#[from] RasterError),
}

impl Scene {
    /// Parses a scene name; the patterns take parameters after colons:
    /// `steps:COUNT` (default 8) and `sinusoid:ANGLE_DEGREES:PERIODS` (default 30:12).
    pub fn parse(name: &str) -> Option<Scene> {
        let mut parts = name.split(':');
        let base = parts.next()?;
        let args: Vec<f32> = parts.map(|p| p.parse::<f32>().ok().filter(|v| v.is_finite())).collect::<Option<_>>()?;
        Some(match (base, args.as_slice()) {
            ("demo", []) => Scene::Demo,
            ("gradient", []) => Scene::Gradient,
            ("steps", []) => Scene::Steps { count: 8 },
            ("steps", [n]) if *n >= 1.0 && n.fract() == 0.0 && *n <= 4096.0 => Scene::Steps { count: *n as u32 },
            ("sinusoid", []) => Scene::Sinusoid { angle: 30.0, frequency: 12.0 },
            ("sinusoid", [angle, frequency]) if *frequency > 0.0 => {
                Scene::Sinusoid { angle: *angle, frequency: *frequency }
            }
            ("sponza", []) => Scene::Sponza,
            ("dungeon", []) => Scene::Dungeon,
            ("outdoor", []) => Scene::Outdoor,
            ("small", []) => Scene::Small,
            ("generated", []) => Scene::Generated,
            _ => return None,
        })
    }

    /// The names [`Scene::parse`] accepts.
    pub const NAMES: [&str; 9] =
        ["demo", "gradient", "steps", "sinusoid", "sponza", "dungeon", "outdoor", "small", "generated"];

    /// The mesh scenes of the benchmark suite (docs/scenes.md, "The suite").
    pub const SUITE: [Scene; 5] = [Scene::Sponza, Scene::Dungeon, Scene::Outdoor, Scene::Small, Scene::Generated];

    /// Whether the scene is rasterised on the GPU (and so needs [`Scene::render_on`]).
    pub fn needs_gpu(self) -> bool {
        Scene::SUITE.contains(&self)
    }

    /// The camera the scene is seen from, for scenes that have a free one
    /// (programs with a `camera_pos` uniform want its eye).
    pub fn camera(self) -> Option<Camera> {
        match self {
            Scene::Sponza => Some(Scene::sponza_camera()),
            Scene::Dungeon => Some(Scene::dungeon_camera()),
            Scene::Outdoor => Some(Scene::outdoor_camera()),
            Scene::Small => Some(Scene::small_camera()),
            Scene::Generated => Some(Scene::generated_camera()),
            _ => None,
        }
    }

    /// The path `mrslc render --frames` follows: Sponza's default walk
    /// ([`CameraPath::Walk`] from [`Scene::sponza_camera`]); the other
    /// built-in scenes have none.
    pub fn camera_path(self) -> Option<CameraPath> {
        match self {
            Scene::Sponza => Some(CameraPath::Walk),
            _ => None,
        }
    }

    /// The demo scene's camera (the CPU ray caster's pinhole, [`Camera`]'s
    /// pixel convention): at (0, 1.5, 5), looking at (0, 0.5, 0), 50 degrees.
    pub fn demo_camera() -> Camera {
        Camera::look_at([0.0, 1.5, 5.0], [0.0, 0.5, 0.0], 50.0)
    }

    /// Sponza's default camera: in the atrium, at head height near its -x
    /// end, looking along the nave (+x) and slightly up towards the galleries.
    pub fn sponza_camera() -> Camera {
        Camera { eye: SPONZA_EYE, target: SPONZA_TARGET, up: [0.0, 1.0, 0.0], fov_y_degrees: SPONZA_FOV }
    }

    /// The dungeon's default camera (see docs/scenes.md, "Dungeon").
    pub fn dungeon_camera() -> Camera {
        Camera { eye: DUNGEON_EYE, target: DUNGEON_TARGET, up: [0.0, 1.0, 0.0], fov_y_degrees: DUNGEON_FOV }
    }

    /// The outdoor scene's default camera (see docs/scenes.md, "Outdoor").
    pub fn outdoor_camera() -> Camera {
        Camera { eye: OUTDOOR_EYE, target: OUTDOOR_TARGET, up: [0.0, 1.0, 0.0], fov_y_degrees: OUTDOOR_FOV }
    }

    /// The small scene's default camera (see docs/scenes.md, "Small").
    pub fn small_camera() -> Camera {
        Camera { eye: SMALL_EYE, target: SMALL_TARGET, up: [0.0, 1.0, 0.0], fov_y_degrees: SMALL_FOV }
    }

    /// The generated scene's default camera (see docs/scenes.md, "Generated").
    pub fn generated_camera() -> Camera {
        Camera { eye: GENERATED_EYE, target: GENERATED_TARGET, up: [0.0, 1.0, 0.0], fov_y_degrees: GENERATED_FOV }
    }

    /// The G-buffer on `gpu`: rasterised for the mesh scenes, made on the
    /// CPU (as [`Scene::render`]) for the others.
    pub fn render_on(self, gpu: &Gpu, width: u32, height: u32) -> Result<GBuffer, SceneError> {
        if self.needs_gpu() {
            Ok(crate::raster::read_gbuffer(gpu, &self.textures_on(gpu, width, height)?)?)
        } else {
            Ok(self.render(width, height))
        }
    }

    /// The mesh scene's mesh (loaded once per process and shared), or
    /// `None` for the scenes made on the CPU. A fetched model that is not
    /// there is [`MeshError::DungeonNotFound`], [`MeshError::OutdoorNotFound`]
    /// or [`MeshError::SmallNotFound`], which name the script that fetches it.
    pub fn mesh(self) -> Result<Option<Arc<Mesh>>, MeshError> {
        Ok(Some(match self {
            Scene::Sponza => crate::fixtures::sponza_shared()?,
            Scene::Dungeon => crate::fixtures::dungeon_shared()?,
            Scene::Outdoor => crate::fixtures::outdoor_shared()?,
            Scene::Small => crate::fixtures::small_shared()?,
            Scene::Generated => crate::fixtures::generated_shared()?,
            _ => return Ok(None),
        }))
    }

    /// The light rig of a mesh scene `mesh` with `bounds`: Sponza's and the
    /// dungeon's as [`LightRig::for_bounds`] makes it; the other scenes'
    /// scaled to their size ([`LightRig::scaled`]): in rows over the city, under a low sun;
    /// in rows over the track, each light raised to its clearance above the
    /// ground within 50 m, under a lower sun; around the small object.
    pub fn rig(self, mesh: &Mesh, bounds: &crate::mesh::Bounds) -> LightRig {
        match self {
            Scene::Small => LightRig::scaled(bounds, DEFAULT_LIGHTS, Layout::Around),
            Scene::Outdoor => {
                let mut rig = LightRig::scaled(bounds, DEFAULT_LIGHTS, Layout::Rows);
                rig.lift_over(&mesh.positions, 50.0, Layout::Rows.clearance(bounds));
                rig.sun = crate::rig::sun_towards(bounds, OUTDOOR_SUN);
                rig
            }
            Scene::Generated => LightRig {
                sun: crate::rig::sun_towards(bounds, GENERATED_SUN),
                ..LightRig::scaled(bounds, DEFAULT_LIGHTS, Layout::Rows)
            },
            _ => LightRig::for_bounds(bounds, DEFAULT_LIGHTS),
        }
    }

    /// The light rig of a scene made on the CPU, whose point lights a
    /// program written for the mesh scenes' rig (`light_pos`, `light_color`,
    /// `light_count`) gets there too ([`LightRig::apply_point_lights`]): the
    /// demo's, scaled to its ground and spheres ([`DEMO_BOUNDS`]) and lit
    /// around them; `None` for the flat test scenes and the mesh scenes
    /// (whose rig is their mesh scene's). The demo is ray-cast, not a mesh:
    /// no shadow map, and its sun stays the program's.
    pub fn cpu_rig(self) -> Option<LightRig> {
        (self == Scene::Demo).then(|| LightRig::scaled(&DEMO_BOUNDS, DEFAULT_LIGHTS, Layout::Around))
    }

    /// The mesh scenes' mesh on `gpu`, with camera and light rig; `None` for
    /// the scenes made on the CPU.
    pub fn mesh_scene(self, gpu: &Gpu) -> Result<Option<MeshScene>, SceneError> {
        let (Some(mesh), Some(camera)) = (self.mesh()?, self.camera()) else { return Ok(None) };
        Ok(Some(MeshScene::with_rig(gpu, &mesh, camera, |bounds| self.rig(&mesh, bounds))?))
    }

    /// The G-buffer as textures on `gpu` (the formats of [`GBuffer::upload`]):
    /// Sponza's straight from the rasteriser, without a round trip through
    /// the CPU; the CPU scenes' uploaded.
    pub fn textures_on(self, gpu: &Gpu, width: u32, height: u32) -> Result<Vec<(String, wgpu::Texture)>, SceneError> {
        match self.mesh_scene(gpu)? {
            Some(scene) => Ok(scene.gbuffer(gpu, &scene.camera, (width, height))?),
            None => Ok(self.render(width, height).upload(gpu)),
        }
    }

    /// The G-buffer, made on the CPU.
    ///
    /// # Panics
    ///
    /// The mesh scenes are rasterised on a GPU: here they make their own
    /// device and panic if there is none or the model cannot be loaded. Use
    /// [`Scene::render_on`] to get those failures as errors.
    pub fn render(self, width: u32, height: u32) -> GBuffer {
        match self {
            Scene::Sponza | Scene::Dungeon | Scene::Outdoor | Scene::Small | Scene::Generated => {
                let gpu = Gpu::new().unwrap_or_else(|e| panic!("the mesh scenes need a GPU adapter: {e}"));
                self.render_on(&gpu, width, height).unwrap_or_else(|e| panic!("cannot render the {self:?} scene: {e}"))
            }
            Scene::Demo => demo(width, height),
            Scene::Gradient => {
                surface(width, height, |u, v| (0, [u * 2.0 - 1.0, 1.0 - v * 2.0, 0.2 * u], [0.0, 0.0, 1.0]))
            }
            Scene::Steps { count } => surface(width, height, move |u, v| {
                let k = ((u * count as f32) as u32).min(count - 1);
                let a = k as f32 / count as f32 * 2.4 - 1.2;
                (k, [u * 2.0 - 1.0, 1.0 - v * 2.0, 0.0], [a.sin(), 0.3, a.cos()])
            }),
            Scene::Sinusoid { angle, frequency } => {
                let (s, c) = angle.to_radians().sin_cos();
                surface(width, height, move |u, v| {
                    let phase = (u * c + v * s) * frequency * std::f32::consts::TAU;
                    let slope = 0.6 * phase.cos();
                    (0, [u * 2.0 - 1.0, 1.0 - v * 2.0, 0.0], [slope * c, slope * s, 1.0])
                })
            }
        }
    }
}

impl GBuffer {
    pub fn channel(&self, name: &str) -> Option<&ChannelData> {
        self.channels.iter().find(|(n, _)| n == name).map(|(_, d)| d)
    }

    /// Uploads every channel as a texture in the format mrsl's layout expects.
    pub fn upload(&self, gpu: &Gpu) -> Vec<(String, wgpu::Texture)> {
        let size = (self.width, self.height);
        self.channels
            .iter()
            .map(|(name, data)| {
                let texture = match data {
                    ChannelData::Uint(values) => {
                        gpu.texture_with_data(name, size, wgpu::TextureFormat::R32Uint, bytemuck::cast_slice(values))
                    }
                    ChannelData::Float { components, data } => {
                        let (format, stride) = match components {
                            1 => (wgpu::TextureFormat::R32Float, 1),
                            2 => (wgpu::TextureFormat::Rg32Float, 2),
                            _ => (wgpu::TextureFormat::Rgba32Float, 4),
                        };
                        let n = *components as usize;
                        let mut padded = Vec::with_capacity(data.len() / n * stride);
                        for px in data.chunks_exact(n) {
                            padded.extend_from_slice(px);
                            padded.extend(std::iter::repeat_n(0.0f32, stride - n));
                        }
                        gpu.texture_with_data(name, size, format, bytemuck::cast_slice(&padded))
                    }
                };
                (name.clone(), texture)
            })
            .collect()
    }
}

/// `v` over its length, at least 1e-20 (the CPU scenes' convention: a zero
/// vector stays zero, and no division by zero).
fn normalize(v: Vec3) -> Vec3 {
    v / v.length().max(1e-20)
}

/// A surface facing the camera, described per pixel by `f(u, v) -> (material, position, normal)`.
fn surface(width: u32, height: u32, f: impl Fn(f32, f32) -> (u32, [f32; 3], [f32; 3])) -> GBuffer {
    let mut b = Builder::new(width, height);
    for y in 0..height {
        for x in 0..width {
            let (u, v) = ((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            let (material, position, normal) = f(u, v);
            let depth = 5.0 - position[2];
            b.push(position, normalize(Vec3::from(normal)).to_array(), [u, v], material, depth, GREY);
        }
    }
    b.finish()
}

struct Builder {
    width: u32,
    height: u32,
    position: Vec<f32>,
    normal: Vec<f32>,
    uv: Vec<f32>,
    material: Vec<u32>,
    depth: Vec<f32>,
    albedo: Vec<f32>,
    roughness: Vec<f32>,
    metallic: Vec<f32>,
}

/// The surface of a CPU scene's pixel: (albedo, roughness, metallic).
type Surface = ([f32; 4], f32, f32);

/// The pattern scenes' surface: a light grey dielectric of medium roughness
/// (the mesh loaders' default material).
const GREY: Surface = ([0.8, 0.8, 0.8, 1.0], 0.5, 0.0);

/// The background's: no albedo, fully rough, not metallic (the rasteriser's too).
const BACKGROUND_SURFACE: Surface = ([0.0; 4], 1.0, 0.0);

impl Builder {
    fn new(width: u32, height: u32) -> Builder {
        let n = (width * height) as usize;
        Builder {
            width,
            height,
            position: Vec::with_capacity(3 * n),
            normal: Vec::with_capacity(3 * n),
            uv: Vec::with_capacity(2 * n),
            material: Vec::with_capacity(n),
            depth: Vec::with_capacity(n),
            albedo: Vec::with_capacity(4 * n),
            roughness: Vec::with_capacity(n),
            metallic: Vec::with_capacity(n),
        }
    }
    fn push(
        &mut self,
        position: [f32; 3],
        normal: [f32; 3],
        uv: [f32; 2],
        material: u32,
        depth: f32,
        surface: Surface,
    ) {
        self.position.extend(position);
        self.normal.extend(normal);
        self.uv.extend(uv);
        self.material.push(material);
        self.depth.push(depth);
        self.albedo.extend(surface.0);
        self.roughness.push(surface.1);
        self.metallic.push(surface.2);
    }
    fn finish(self) -> GBuffer {
        let n = (self.width * self.height) as usize;
        GBuffer {
            width: self.width,
            height: self.height,
            channels: vec![
                ("position".into(), ChannelData::Float { components: 3, data: self.position }),
                ("normal".into(), ChannelData::Float { components: 3, data: self.normal }),
                ("uv".into(), ChannelData::Float { components: 2, data: self.uv }),
                ("material".into(), ChannelData::Uint(self.material)),
                ("depth".into(), ChannelData::Float { components: 1, data: self.depth }),
                ("albedo".into(), ChannelData::Float { components: 4, data: self.albedo }),
                ("roughness".into(), ChannelData::Float { components: 1, data: self.roughness }),
                ("metallic".into(), ChannelData::Float { components: 1, data: self.metallic }),
                // The CPU scenes' camera never moves.
                ("velocity".into(), ChannelData::Float { components: 2, data: vec![0.0; 2 * n] }),
            ],
        }
    }
}

/// Ray-casts spheres on a ground plane from the demo program's default camera
/// (at (0, 1.5, 5), looking at (0, 0.5, 0), 50 degree vertical field of view).
/// The demo's world: its ground (y = 0, |x| and |z| below 6) and its
/// spheres, the tallest reaching y = 1.8.
pub const DEMO_BOUNDS: crate::mesh::Bounds = crate::mesh::Bounds { min: [-6.0, 0.0, -6.0], max: [6.0, 1.8, 6.0] };

fn demo(width: u32, height: u32) -> GBuffer {
    let camera = Scene::demo_camera();
    let (eye, target) = (Vec3::from(camera.eye), Vec3::from(camera.target));
    let forward = normalize(target - eye);
    let right = normalize(Vec3::new(-forward.z, 0.0, forward.x));
    let up = right.cross(forward);
    let tan_half = (camera.fov_y_degrees.to_radians() / 2.0).tan();
    let aspect = width as f32 / height as f32;
    // (center, radius, material)
    let spheres = [
        (Vec3::new(-1.3, 0.7, 0.0), 0.7f32, 1u32),
        (Vec3::new(0.5, 0.5, 0.9), 0.5, 2),
        (Vec3::new(1.6, 0.9, -1.2), 0.9, 3),
        (Vec3::new(-0.2, 0.35, -1.6), 0.35, 4),
    ];
    let mut b = Builder::new(width, height);
    for y in 0..height {
        for x in 0..width {
            let sx = (2.0 * (x as f32 + 0.5) / width as f32 - 1.0) * tan_half * aspect;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / height as f32) * tan_half;
            let dir = normalize(forward + sx * right + sy * up);
            let mut best: Option<(f32, Vec3, [f32; 2], u32)> = None;
            // Ground plane y = 0, within |x|, |z| < 6.
            if dir.y < -1e-6 {
                let t = -eye.y / dir.y;
                let p = [eye.x + t * dir.x, 0.0, eye.z + t * dir.z];
                if p[0].abs() < 6.0 && p[2].abs() < 6.0 {
                    best = Some((t, Vec3::Y, [p[0] * 0.25 + 0.5, p[2] * 0.25 + 0.5], 0));
                }
            }
            for (center, radius, material) in spheres {
                let oc = eye - center;
                let bq = oc.dot(dir);
                let cq = oc.dot(oc) - radius * radius;
                let disc = bq * bq - cq;
                if disc < 0.0 {
                    continue;
                }
                let t = -bq - disc.sqrt();
                if t > 1e-4 && best.is_none_or(|(bt, ..)| t < bt) {
                    let n = normalize(eye + t * dir - center);
                    let uv = [0.5 + n.z.atan2(n.x) / std::f32::consts::TAU, 0.5 - n.y.asin() / std::f32::consts::PI];
                    best = Some((t, n, uv, material));
                }
            }
            match best {
                Some((t, n, uv, material)) => {
                    b.push((eye + t * dir).to_array(), n.to_array(), uv, material, t, demo_surface(material, uv))
                }
                None => {
                    let t = 50.0;
                    let position = (eye + t * dir).to_array();
                    b.push(position, (-dir).to_array(), [0.0, 0.0], BACKGROUND, t, BACKGROUND_SURFACE)
                }
            }
        }
    }
    b.finish()
}

/// The demo scene's materials: a ground of light and dark tiles (8 per uv
/// unit), a red plastic, a gold, a glossy blue and a rough white sphere.
fn demo_surface(material: u32, uv: [f32; 2]) -> Surface {
    match material {
        0 => {
            let light = ((uv[0] * 8.0).floor() + (uv[1] * 8.0).floor()).rem_euclid(2.0) == 0.0;
            (if light { [0.75, 0.72, 0.66, 1.0] } else { [0.2, 0.19, 0.18, 1.0] }, 0.7, 0.0)
        }
        1 => ([0.8, 0.12, 0.08, 1.0], 0.45, 0.0),
        2 => ([1.0, 0.77, 0.34, 1.0], 0.3, 1.0),
        3 => ([0.1, 0.3, 0.8, 1.0], 0.15, 0.0),
        _ => ([0.9, 0.9, 0.88, 1.0], 0.85, 0.0),
    }
}
