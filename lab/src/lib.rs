//! mrsl-lab: the evaluation kit around the mrsl runtime — everything a tool
//! or a test needs that an engine does not.
//!
//! - [`gpu`]: a headless device (the first adapter wgpu finds on Vulkan;
//!   lavapipe on a machine without a GPU) and texture upload/readback.
//! - [`gbuffer`]: G-buffers in CPU memory (a leaf module).
//! - [`scene`]: the built-in scenes: CPU test patterns and a ray-cast demo,
//!   and the Dabrovic Sponza rasterised on the GPU.
//! - [`material`]: surface materials (factors, textures, mipmaps).
//! - [`mesh`], [`raster`]: OBJ/glTF loading and the G-buffer rasteriser
//!   (with motion vectors from the previous frame's camera).
//! - [`camera_path`]: cameras along a path, for sequences of frames.
//! - [`rig`], [`mesh_scene`]: the light rig (point lights, a sun with a
//!   shadow map) and a mesh on the GPU with its camera and rig.
//! - [`scene_file`]: TOML scene files, and [`image_texture`]: the images
//!   they bind to `texture2d` uniforms.
//! - [`uniforms`]: binding what a scene provides to a program's uniforms by
//!   name and type.
//! - [`runtime_dir`]: a private `XDG_RUNTIME_DIR` where there is none, so
//!   that Mesa's Vulkan drivers print no error line.
//! - [`metrics`]: RMSE, PSNR, MSSIM and FLIP against a reference image.
//!
//! Module dependencies run one way: `gbuffer` ← `material` ← `mesh` ←
//! `raster` ← `rig` ← `mesh_scene` ← `scene` ← `scene_file`, and `raster`
//! ← `camera_path` ← `scene`, with `gpu`
//! beneath them all; `uniforms` (used from `rig` on) and `image_texture`
//! (used by `scene_file`) depend on no other module but `gpu`, and
//! `runtime_dir` on none.

pub mod camera_path;
pub mod color;
pub mod gbuffer;
pub mod gpu;
pub mod image_texture;
pub mod material;
pub mod mesh;
pub mod mesh_scene;
pub mod metrics;
pub mod raster;
pub mod rig;
pub mod runtime_dir;
pub mod scene;
pub mod scene_file;
pub mod shading_rate;
pub mod uniforms;
