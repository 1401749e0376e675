//! A mesh on the GPU with its camera and light rig: G-buffers from any
//! camera (one per frame of a camera path), the rig's shadow map (rendered
//! once, on first use) and the uniforms a program takes from the scene.

use crate::camera::Camera;
use crate::gpu::Gpu;
use crate::mesh::{Bounds, Mesh, MeshWarning};
use crate::raster::{GpuMesh, RasterError, Rasterizer};
use crate::rig::{DEFAULT_LIGHTS, DEFAULT_SHADOW_MAP_SIZE, LightRig, RigError};
use crate::uniforms::{Applied, Offered};
use mrsl_runtime::Shader;

/// A mesh scene ready to render.
pub struct MeshScene {
    rasterizer: Rasterizer,
    mesh: GpuMesh,
    /// The scene's own camera.
    pub camera: Camera,
    pub rig: LightRig,
    shadow_map: Option<wgpu::Texture>,
    /// What loading the mesh skipped or could not use (for the tools to print once).
    pub warnings: Vec<MeshWarning>,
}

impl MeshScene {
    /// Uploads `mesh`; the rig has [`DEFAULT_LIGHTS`] lights over its bounds.
    pub fn new(gpu: &Gpu, mesh: &Mesh, camera: Camera) -> Result<MeshScene, RasterError> {
        MeshScene::with_rig(gpu, mesh, camera, |bounds| LightRig::for_bounds(bounds, DEFAULT_LIGHTS))
    }

    /// Uploads `mesh`, with the rig `rig` makes from its bounds (a unit cube
    /// around the origin for a mesh without triangles).
    pub fn with_rig(
        gpu: &Gpu,
        mesh: &Mesh,
        camera: Camera,
        rig: impl FnOnce(&Bounds) -> LightRig,
    ) -> Result<MeshScene, RasterError> {
        let rasterizer = Rasterizer::new(gpu)?;
        let uploaded = rasterizer.upload(gpu, mesh)?;
        let bounds = uploaded.bounds().unwrap_or(Bounds { min: [-1.0, -1.0, -1.0], max: [1.0, 1.0, 1.0] });
        let rig = rig(&bounds);
        Ok(MeshScene { rasterizer, mesh: uploaded, camera, rig, shadow_map: None, warnings: mesh.warnings.clone() })
    }

    /// The G-buffer seen from `camera` (see [`Rasterizer::render`]).
    pub fn gbuffer(
        &self,
        gpu: &Gpu,
        camera: &Camera,
        size: (u32, u32),
    ) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
        self.rasterizer.render(gpu, &self.mesh, camera, size)
    }

    /// [`MeshScene::gbuffer`] with the `velocity` channel of a move from
    /// `previous` (see [`Rasterizer::render_moving`]).
    pub fn gbuffer_moving(
        &self,
        gpu: &Gpu,
        camera: &Camera,
        previous: Option<&Camera>,
        size: (u32, u32),
    ) -> Result<Vec<(String, wgpu::Texture)>, RasterError> {
        self.rasterizer.render_moving(gpu, &self.mesh, camera, previous, size)
    }

    /// The rig's shadow map ([`DEFAULT_SHADOW_MAP_SIZE`] square), rendered on first use.
    pub fn shadow_map(&mut self, gpu: &Gpu) -> Result<&wgpu::Texture, RasterError> {
        if self.shadow_map.is_none() {
            self.shadow_map = Some(self.rig.shadow_map(gpu, &self.rasterizer, &self.mesh, DEFAULT_SHADOW_MAP_SIZE)?);
        }
        Ok(self.shadow_map.as_ref().expect("set just above"))
    }

    /// Sets what the scene provides among the uniforms the program declares,
    /// by name and type ([`crate::uniforms`]): the rig's (see [`crate::rig`])
    /// and `camera_pos` (a `float3`: the eye of `camera`). Returns the names
    /// set and the names left at the program's default for their type.
    pub fn set_uniforms(&self, shader: &mut Shader, camera: &Camera) -> Result<Applied, RigError> {
        let mut applied = self.rig.apply(shader)?;
        let layout = shader.layout().clone();
        if applied.admit(&layout, "scene", "camera_pos", &Offered::float3())? {
            shader.set_uniform("camera_pos", &camera.eye.map(f64::from))?;
            applied.record("camera_pos");
        }
        Ok(applied)
    }
}
