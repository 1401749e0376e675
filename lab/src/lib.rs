//! mrsl-lab: the evaluation kit around the mrsl runtime — everything a tool
//! or a test needs that an engine does not.
//!
//! - [`gpu`]: a headless device (the first adapter wgpu finds on Vulkan;
//!   lavapipe on a machine without a GPU) and texture upload/readback.
//! - [`gbuffer`]: G-buffers in CPU memory (a leaf module).
//! - [`scene`]: the built-in scenes: CPU test patterns and a ray-cast demo,
//!   and the Dabrovic Sponza rasterised on the GPU.
//! - [`material`]: surface materials (factors, textures, mipmaps).
//! - [`mesh`], [`raster`]: OBJ/glTF loading and the G-buffer rasteriser.
//! - [`rig`], [`mesh_scene`]: the light rig (point lights, a sun with a
//!   shadow map) and a mesh on the GPU with its camera and rig.
//! - [`scene_file`]: TOML scene files.
//! - [`metrics`]: RMSE, PSNR, MSSIM and FLIP against a reference image.
//!
//! Module dependencies run one way: `gbuffer` ← `material` ← `mesh` ← `raster` ← `rig`
//! ← `mesh_scene` ← `scene` ← `scene_file`, with `gpu` beneath them all.

pub mod gbuffer;
pub mod gpu;
pub mod material;
pub mod mesh;
pub mod mesh_scene;
pub mod metrics;
pub mod raster;
pub mod rig;
pub mod scene;
pub mod scene_file;
