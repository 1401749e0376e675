//! The light rig of the mesh scenes: dozens of point lights and a sun with a
//! shadow map, handed to programs as uniforms and a texture they declare by
//! name (see docs/scenes.md, "Lights and shadows").
//!
//! | name            | mrsl type      | content                                                    |
//! | --------------- | -------------- | ---------------------------------------------------------- |
//! | `light_pos`     | `float4[N]`    | xyz world position, w range (attenuation reaches 0 there)  |
//! | `light_color`   | `float4[N]`    | rgb colour, a intensity                                    |
//! | `light_count`   | `int`          | lights in use: min(rig's lights, N)                        |
//! | `sun_pos`       | `float3`       | the sun camera's eye                                       |
//! | `sun_view_proj` | `float4x4`     | world → sun clip space; `clip.xy / clip.w` is in [-1, 1]   |
//! | `sun_focal`     | `float`        | shadow-map uv per world unit at distance 1 (1 / 2tan(fov/2)) |
//! | `sun_color`     | `float3`       | the sun's radiance                                         |
//! | `sun_size`      | `float`        | the sun's width in world units (PCSS light size)           |
//! | `shadow_map`    | `texture2d`    | distance from `sun_pos` as `r + g` (see below)             |
//!
//! A uniform is set only when the program declares it with the type above
//! (any length N for the arrays); see [`crate::uniforms`] for what happens
//! to a name declared with another type.
//!
//! The shadow map is the `depth` channel of a G-buffer rasterised from the
//! sun (a pinhole camera: the same rasteriser and pixel convention as the
//! view), so texel `(x, y)` holds the distance from `sun_pos` to the nearest
//! surface along the ray through its centre. mrsl textures are filterable
//! floats and `R32Float` is not filterable in WebGPU without an optional
//! feature, so the distance is stored in `Rg16Float` as a sum of two halves:
//! `r = f16(d)`, `g = f16(d - r)` — about 22 bits of precision instead of
//! half's 11, which keeps the shadow bias at millimetres on Sponza.

use crate::camera::{Camera, CameraError};
use crate::gpu::Gpu;
use crate::hash::hash01;
use crate::mesh::Bounds;
use crate::raster::{GpuMesh, RasterError, Rasterizer};
use crate::uniforms::{Applied, Offered, UniformTypeError};
use crate::vector::normalize;
use glam::Vec3;
use mrsl_abi::{Scalar, ValueType};
use mrsl_runtime::Shader;

/// A point light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    pub position: [f32; 3],
    /// Distance at which the light's attenuation reaches zero.
    pub range: f32,
    pub color: [f32; 3],
    pub intensity: f32,
}

/// A sun: a distant, bright area light seen through a pinhole shadow camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    /// The shadow camera: its eye is the light's position, its view covers the scene.
    pub camera: Camera,
    pub color: [f32; 3],
    /// Width of the light in world units (PCSS's light size).
    pub size: f32,
}

/// Point lights and a sun for a mesh scene.
#[derive(Debug, Clone, PartialEq)]
pub struct LightRig {
    pub lights: Vec<PointLight>,
    pub sun: Sun,
}

/// Default number of point lights of [`LightRig::for_bounds`].
pub const DEFAULT_LIGHTS: usize = 32;

/// Default shadow-map resolution (square).
pub const DEFAULT_SHADOW_MAP_SIZE: u32 = 1024;

impl LightRig {
    /// `count` point lights spread over `bounds` and a sun above it.
    ///
    /// The lights stand in two rows along the longest horizontal axis, a
    /// fifth of the height above the floor (lanterns along an atrium's
    /// colonnades), with a deterministic jitter and warm-to-cool colours;
    /// each reaches a quarter of the scene's length. The sun is up and to
    /// the side, far enough (three diagonals) that its rays are almost
    /// parallel, with a field of view just covering the bounding sphere.
    pub fn for_bounds(bounds: &Bounds, count: usize) -> LightRig {
        LightRig { lights: row_lights(bounds, count), sun: sun_for(bounds) }
    }

    /// A rig for a scene at any world scale: the lights laid out by
    /// `layout`, their intensities scaled by one factor so that the
    /// layout's reference point ([`Layout::reference_point`]) gets the
    /// summed light ([`light_sum`]) that the centre of Sponza's floor gets
    /// from [`LightRig::for_bounds`]'s rig; the sun as that rig's (its light
    /// does not fall off, and its size and distance follow the bounds).
    pub fn scaled(bounds: &Bounds, count: usize, layout: Layout) -> LightRig {
        let mut lights = match layout {
            Layout::Rows => row_lights(bounds, count),
            Layout::Around => ring_lights(bounds, count),
        };
        let reference =
            light_sum(&row_lights(&REFERENCE_BOUNDS, count), Layout::Rows.reference_point(&REFERENCE_BOUNDS));
        let here = light_sum(&lights, layout.reference_point(bounds));
        if here > 0.0 && reference > 0.0 {
            for light in &mut lights {
                light.intensity *= reference / here;
            }
        }
        LightRig { lights, sun: sun_for(bounds) }
    }

    /// Raises every light that is less than `clearance` above the highest
    /// of `positions` within `radius` of it horizontally to that height
    /// (lights laid out over uneven ground, such as a race track's hills,
    /// would otherwise stand in them).
    pub fn lift_over(&mut self, positions: &[[f32; 3]], radius: f32, clearance: f32) {
        for light in &mut self.lights {
            let [x, _, z] = light.position;
            let ground = positions
                .iter()
                .filter(|p| (p[0] - x).powi(2) + (p[2] - z).powi(2) <= radius * radius)
                .map(|p| p[1])
                .fold(f32::NEG_INFINITY, f32::max);
            if ground.is_finite() {
                light.position[1] = light.position[1].max(ground + clearance);
            }
        }
    }

    /// The sun's world → clip matrix, column-major (16 values): `clip.xy /
    /// clip.w` is the pixel convention of [`Camera::ray`] on a square image,
    /// `clip.w` the depth along the view direction.
    pub fn sun_view_proj(&self) -> Result<[f32; 16], CameraError> {
        // A square image, and no near plane: clip.z is 0, unused.
        Ok(self.sun.camera.view_projection(1.0, 0.0)?.to_cols_array())
    }

    /// Sets the rig's uniforms that the shader's program declares (names
    /// above) with the rig's type ([`crate::uniforms`]): a name the program
    /// declares with another type is left at its default and reported in
    /// [`Applied::warnings`], or is [`RigError::Type`] when it has no
    /// default. Arrays take as many lights as they hold. `shadow_map` is
    /// checked (a `texture2d`) and listed in [`Applied::set`] when the
    /// program samples it; the caller binds the texture
    /// ([`LightRig::shadow_map`]).
    pub fn apply(&self, shader: &mut Shader) -> Result<Applied, RigError> {
        let mut applied = Applied::default();
        let layout = shader.layout().clone();
        let lights = self.lights.len();
        let float = Offered::scalar(Scalar::Float);
        // The arrays first: light_count counts the lights they hold.
        let capacity = self.apply_arrays(shader, &layout, &mut applied, |_| true)?;
        let focal = 0.5 / (self.sun.camera.fov_y_degrees.to_radians() / 2.0).tan();
        let view_proj = self.sun_view_proj()?;
        let singles: [(&str, Offered, Vec<f32>); 6] = [
            ("light_count", Offered::scalar(Scalar::Int), vec![lights.min(capacity.unwrap_or(lights)) as f32]),
            ("sun_pos", Offered::float3(), self.sun.camera.eye.to_vec()),
            ("sun_view_proj", Offered::Value(ValueType::Matrix(4)), view_proj.to_vec()),
            ("sun_focal", float.clone(), vec![focal]),
            ("sun_color", Offered::float3(), self.sun.color.to_vec()),
            ("sun_size", float, vec![self.sun.size]),
        ];
        for (name, offered, values) in singles {
            if applied.admit(&layout, SOURCE, name, &offered)? {
                shader.set_uniform(name, &values.into_iter().map(f64::from).collect::<Vec<_>>())?;
                applied.record(name);
            }
        }
        if applied.admit(&layout, SOURCE, "shadow_map", &Offered::Texture)? {
            applied.record("shadow_map");
        }
        Ok(applied)
    }

    /// The point lights alone, for a scene whose rig has no shadow map (the
    /// ray-cast demo): `light_pos` and `light_color` where the program
    /// declares them as `float4` arrays, which take no defaults, and
    /// `light_count` where it declares an `int` without one. A program's own
    /// sun and lights, and names of other types, keep their defaults without
    /// a warning: the scene only supplies what the program could not run without.
    pub fn apply_point_lights(&self, shader: &mut Shader) -> Result<Applied, RigError> {
        let mut applied = Applied::default();
        let layout = shader.layout().clone();
        let field =
            |name: &str| layout.uniforms.as_ref().and_then(|u| u.fields.iter().find(|f| f.name == name)).cloned();
        let float4_array = |name: &str| {
            field(name).is_some_and(
                |f| matches!(f.ty, ValueType::Array(ref t, _) if **t == ValueType::Vector(Scalar::Float, 4)),
            )
        };
        let capacity = self.apply_arrays(shader, &layout, &mut applied, float4_array)?;
        let count = field("light_count");
        if count.is_some_and(|f| f.default.is_none() && f.ty == ValueType::Scalar(Scalar::Int)) {
            let lights = self.lights.len().min(capacity.unwrap_or(self.lights.len()));
            shader.set_uniform("light_count", &[lights as f64])?;
            applied.record("light_count");
        }
        Ok(applied)
    }

    /// `light_pos` and `light_color`, each where `wanted` and the program
    /// declares it (admitted by type); returns the fewest lights an array
    /// set holds, which `light_count` must not exceed.
    fn apply_arrays(
        &self,
        shader: &mut Shader,
        layout: &mrsl_abi::Layout,
        applied: &mut Applied,
        wanted: impl Fn(&str) -> bool,
    ) -> Result<Option<usize>, RigError> {
        let mut capacity: Option<usize> = None;
        for name in ["light_pos", "light_color"] {
            if !wanted(name) || !applied.admit(layout, SOURCE, name, &Offered::Float4Array(self.lights.len()))? {
                continue;
            }
            let components = declared_components(layout, name);
            let held = components / 4;
            capacity = Some(capacity.map_or(held, |c| c.min(held)));
            let mut values: Vec<f64> = self
                .lights
                .iter()
                .take(held)
                .flat_map(|l| match name {
                    "light_pos" => [l.position[0], l.position[1], l.position[2], l.range],
                    _ => [l.color[0], l.color[1], l.color[2], l.intensity],
                })
                .map(f64::from)
                .collect();
            // Arrays larger than the rig: the rest stays zero (lights past light_count).
            values.resize(components, 0.0);
            shader.set_uniform(name, &values)?;
            applied.record(name);
        }
        Ok(capacity)
    }

    /// Renders the sun's shadow map (`size` x `size`, `Rg16Float`, distance
    /// as `r + g`; see the module documentation).
    pub fn shadow_map(
        &self,
        gpu: &Gpu,
        rasterizer: &Rasterizer,
        mesh: &GpuMesh,
        size: u32,
    ) -> Result<wgpu::Texture, RasterError> {
        let channels = rasterizer.render(gpu, mesh, &self.sun.camera, (size, size))?;
        let depth = channels
            .iter()
            .find(|(name, _)| name == "depth")
            .map(|(_, t)| t)
            .ok_or_else(|| RasterError::Render("the rasteriser made no depth channel".into()))?;
        let distances: Vec<f32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(depth)?);
        let texels: Vec<half::f16> = distances
            .iter()
            .flat_map(|&d| {
                let hi = half::f16::from_f32(d);
                [hi, half::f16::from_f32(d - hi.to_f32())]
            })
            .collect();
        Ok(gpu.texture_with_data(
            "mrsl shadow map",
            (size, size),
            wgpu::TextureFormat::Rg16Float,
            bytemuck::cast_slice(&texels),
        ))
    }

    /// Distance from `p` to the sun (what the shadow map stores for the nearest surface).
    pub fn sun_distance(&self, p: [f32; 3]) -> f32 {
        Vec3::from(p).distance(Vec3::from(self.sun.camera.eye))
    }
}

/// How [`LightRig::scaled`] places the point lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Two rows over the floor, as [`LightRig::for_bounds`]: for scenes seen
    /// from inside (a building, a city, a race track).
    Rows,
    /// Two rings around the bounding sphere, each light reaching across it:
    /// for a lone object seen from outside.
    Around,
}

impl Layout {
    /// The distance from a light to the nearest surface the layout puts it
    /// over: a fifth of the height for [`Layout::Rows`] (their height above
    /// the floor), 0.6 of the bounding sphere's radius for [`Layout::Around`].
    pub fn clearance(self, bounds: &Bounds) -> f32 {
        match self {
            Layout::Rows => 0.2 * bounds.extent()[1],
            Layout::Around => 0.6 * 0.5 * bounds.diagonal(),
        }
    }

    /// Where [`LightRig::scaled`] matches the light to Sponza's: the centre
    /// of the floor for [`Layout::Rows`], the centre of the bounds for
    /// [`Layout::Around`].
    pub fn reference_point(self, bounds: &Bounds) -> [f32; 3] {
        let [x, y, z] = bounds.center();
        match self {
            Layout::Rows => [x, bounds.min[1], z],
            Layout::Around => [x, y, z],
        }
    }
}

/// About the Dabrovic Sponza's bounds (docs/scenes.md): the scene whose rig
/// [`LightRig::scaled`] matches.
pub const REFERENCE_BOUNDS: Bounds = Bounds { min: [-17.4, -1.0, -7.8], max: [17.4, 15.6, 7.8] };

/// The lights' summed strength at `p` under the falloff of
/// `examples/sponza_lights.mrsl` (intensity · window(d / range) / (d² + 1),
/// no cosine). Its `+ 1` is a world unit: the same rig at a hundred times
/// Sponza's size would light its floor some 10⁴ times less, and at a
/// hundredth of it, where the falloff is flat, some ten times more, which is
/// what [`LightRig::scaled`] corrects.
pub fn light_sum(lights: &[PointLight], p: [f32; 3]) -> f32 {
    lights
        .iter()
        .map(|l| {
            let d = Vec3::from(l.position).distance(Vec3::from(p));
            let window = (1.0 - (d / l.range).powi(4)).max(0.0).powi(2);
            l.intensity * window / (d * d + 1.0)
        })
        .sum()
}

/// [`LightRig::for_bounds`]'s lights: two rows along the longer horizontal axis.
fn row_lights(bounds: &Bounds, count: usize) -> Vec<PointLight> {
    let (min, extent) = (bounds.min, bounds.extent());
    // Long axis: x or z, whichever is longer; rows are offset along the other.
    let (long, short) = if extent[0] >= extent[2] { (0, 2) } else { (2, 0) };
    (0..count)
        .map(|i| {
            let row = (i % 2) as f32;
            let along = ((i / 2) as f32 + 0.5) / count.div_ceil(2) as f32;
            let jitter = |k: u32| hash01(i as u32 * 4 + k) - 0.5;
            let mut p = [0.0; 3];
            p[long] = min[long] + extent[long] * (0.05 + 0.9 * along + 0.02 * jitter(0));
            p[short] = min[short] + extent[short] * (0.3 + 0.4 * row + 0.05 * jitter(1));
            p[1] = min[1] + extent[1] * (0.2 + 0.1 * jitter(2));
            PointLight {
                position: p,
                range: 0.25 * extent[long].max(extent[short]),
                color: light_color(i),
                intensity: 2.0,
            }
        })
        .collect()
}

/// Warm to cool, by a fixed hash of the light's number.
fn light_color(i: usize) -> [f32; 3] {
    let warm = hash01(i as u32 * 4 + 3);
    [1.0, 0.55 + 0.35 * warm, 0.25 + 0.6 * (1.0 - warm)]
}

/// [`Layout::Around`]: two rings of lights around the bounding sphere (of
/// radius r), 1.6 r from its centre, one half above the centre (0.7 r) and
/// one a little below (0.2 r), the lower ring turned by half a step; each
/// light reaches 3 r, across the whole object.
fn ring_lights(bounds: &Bounds, count: usize) -> Vec<PointLight> {
    let centre = Vec3::from(bounds.center());
    let radius = (0.5 * bounds.diagonal()).max(1e-6);
    let per_ring = count.div_ceil(2).max(1) as f32;
    (0..count)
        .map(|i| {
            let ring = (i % 2) as f32;
            let jitter = |k: u32| hash01(i as u32 * 4 + k) - 0.5;
            let angle = std::f32::consts::TAU * (((i / 2) as f32 + 0.5 * ring + 0.1 * jitter(0)) / per_ring);
            let height = if ring == 0.0 { 0.7 } else { -0.2 } + 0.05 * jitter(1);
            let p = centre + radius * Vec3::new(1.6 * angle.cos(), height, 1.6 * angle.sin());
            PointLight { position: p.to_array(), range: 3.0 * radius, color: light_color(i), intensity: 2.0 }
        })
        .collect()
}

/// [`LightRig::for_bounds`]'s sun direction (towards the sun).
pub const SUN_DIRECTION: [f32; 3] = [0.3, 1.0, 0.2];

/// [`LightRig::for_bounds`]'s sun: towards [`SUN_DIRECTION`] (see [`sun_towards`]).
fn sun_for(bounds: &Bounds) -> Sun {
    sun_towards(bounds, SUN_DIRECTION)
}

/// A sun three diagonals from the centre of `bounds` towards `direction`,
/// its view just covering the bounding sphere, 3% of its distance wide.
pub fn sun_towards(bounds: &Bounds, direction: [f32; 3]) -> Sun {
    let center = Vec3::from(bounds.center());
    let radius = (0.5 * bounds.diagonal()).max(1e-3);
    let distance = 3.0 * bounds.diagonal().max(1e-3);
    let eye = center + distance * normalize(Vec3::from(direction));
    let fov = 2.0 * (radius / distance).asin().to_degrees() * 1.02;
    let camera = Camera::look_at(eye.to_array(), center.to_array(), fov);
    Sun { camera, color: [3.0, 2.85, 2.6], size: 0.03 * distance }
}

/// Why the rig's uniforms could not be set.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    /// The sun's camera is degenerate.
    #[error("the light rig cannot be used: {0}")]
    Camera(#[from] CameraError),
    /// The shader refused a value.
    #[error(transparent)]
    Uniform(#[from] mrsl_runtime::Error),
    /// The program declares one of the rig's names with another type and no
    /// default, so its value would be missing.
    #[error(transparent)]
    Type(#[from] UniformTypeError),
}

/// How the rig names itself in warnings and errors.
pub const SOURCE: &str = "light rig";

/// The number of components of the program's uniform `name` (0 if it has none).
fn declared_components(layout: &mrsl_abi::Layout, name: &str) -> usize {
    let field = layout.uniforms.as_ref().and_then(|u| u.fields.iter().find(|f| f.name == name));
    field.map_or(0, |f| f.ty.components() as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Bounds {
        Bounds { min: [-17.0, -1.0, -8.0], max: [16.0, 15.0, 7.0] }
    }

    #[test]
    fn lights_lie_inside_the_bounds_and_are_deterministic() {
        let rig = LightRig::for_bounds(&bounds(), 32);
        assert_eq!(rig.lights.len(), 32);
        let b = bounds();
        for l in &rig.lights {
            for k in 0..3 {
                assert!(l.position[k] > b.min[k] && l.position[k] < b.max[k], "{l:?}");
            }
            assert!(l.range > 0.0 && l.intensity > 0.0);
        }
        assert_eq!(rig, LightRig::for_bounds(&bounds(), 32));
    }

    #[test]
    fn the_sun_projects_the_scene_inside_its_view() {
        let rig = LightRig::for_bounds(&bounds(), 4);
        let m = rig.sun_view_proj().unwrap();
        let apply = |p: [f32; 3]| {
            let c: [f32; 4] = std::array::from_fn(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
            [c[0] / c[3], c[1] / c[3], c[3]]
        };
        for corner in bounds().corners() {
            let [x, y, w] = apply(corner);
            assert!(x.abs() < 1.0 && y.abs() < 1.0 && w > 0.0, "corner {corner:?} -> {x} {y} {w}");
        }
        // The centre of the scene is the centre of the image, at the eye distance.
        let [x, y, w] = apply(bounds().center());
        assert!(x.abs() < 1e-5 && y.abs() < 1e-5, "{x} {y}");
        assert!((w - rig.sun_distance(bounds().center())).abs() < 1e-3);
        // Image right is clip +x, image up is clip +y (as Camera::ray).
        let (_, right, up) = rig.sun.camera.basis().unwrap();
        let c = bounds().center();
        let [x, _, _] = apply([0, 1, 2].map(|k| c[k] + right[k]));
        let [_, y, _] = apply([0, 1, 2].map(|k| c[k] + up[k]));
        assert!(x > 0.0 && y > 0.0);
    }

    #[test]
    fn two_halves_keep_22_bits_of_distance() {
        for d in [0.5f32, 12.345, 99.87654, 170.001] {
            let hi = half::f16::from_f32(d);
            let lo = half::f16::from_f32(d - hi.to_f32());
            let back = hi.to_f32() + lo.to_f32();
            assert!(((back - d) / d).abs() < 2.0f32.powi(-21), "{d} -> {back}");
        }
    }
}
