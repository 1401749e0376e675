//! mrsl-lab: the evaluation kit around the mrsl runtime — everything a tool
//! or a test needs that an engine does not.
//!
//! - [`gpu`]: a headless device (the first adapter wgpu finds on Vulkan;
//!   lavapipe on a machine without a GPU) and texture upload/readback.
//! - [`gbuffer`]: G-buffers in CPU memory (a leaf module).
//! - [`scene`]: the built-in scenes: CPU test patterns and a ray-cast demo,
//!   and the mesh scenes rasterised on the GPU (the Dabrovic Sponza, the
//!   dungeon, an outdoor race track, a small robot part and a generated
//!   city: the benchmark suite, see docs/scenes.md).
//! - [`color`]: the sRGB transfer function.
//! - [`image_texture`]: images decoded, mipmapped and uploaded (for the
//!   materials and for the images scene files bind to `texture2d` uniforms).
//! - [`material`]: surface materials (factors and textures).
//! - [`mesh`], [`raster`]: OBJ/glTF/AC3D loading (normals, tangents, MTL)
//!   and the G-buffer rasteriser (with motion vectors from the previous
//!   frame's camera); [`fixtures`]: the test models (Sponza, the dungeon,
//!   the outdoor and small scenes' models), found and loaded once;
//!   [`procedural`]: the generated scene's city.
//! - [`camera`], [`camera_path`]: the pinhole camera, and cameras along a
//!   path, for sequences of frames.
//! - [`rig`], [`mesh_scene`]: the light rig (point lights, a sun with a
//!   shadow map) and a mesh on the GPU with its camera and rig.
//! - [`scene_file`]: TOML scene files.
//! - [`uniforms`]: binding what a scene provides to a program's uniforms by
//!   name and type.
//! - [`shading_rate`]: shading-rate images made on the CPU.
//! - [`runtime_dir`]: a private `XDG_RUNTIME_DIR` where there is none, so
//!   that Mesa's Vulkan drivers print no error line.
//! - [`metrics`]: RMSE, PSNR, MSSIM and FLIP against a reference image.
//! - [`figures`]: what a mode's plan does that any device can report
//!   (dispatches, global bytes per pixel, workgroup memory, evaluations
//!   per coarse sample).
//!
//! The vector maths is glam's, but for `vector::normalize` (see there why).
//!
//! Module dependencies run one way: `color` ← `image_texture` ← `material`
//! ← `mesh` ← `procedural` ← `fixtures`, `mesh` ← `camera` ← `raster` ←
//! `rig` ← `mesh_scene` ← `scene` ← `scene_file`, `fixtures` ← `scene`, and
//! `camera` ← `camera_path` ← `scene`, with `gpu`, `gbuffer`, `hash` and `vector`
//! beneath them all; `uniforms` (used from `rig` on) depends on no other
//! module, `metrics` on `color` alone, and `runtime_dir` and `figures` on none.

pub mod camera;
pub mod camera_path;
pub mod color;
pub mod engine_formats;
pub mod figures;
pub mod fixtures;
pub mod gbuffer;
pub mod gpu;
mod hash;
pub mod image_texture;
pub mod material;
pub mod mesh;
pub mod mesh_scene;
pub mod metrics;
pub mod microbench;
pub mod procedural;
pub mod raster;
pub mod rig;
pub mod runtime_dir;
pub mod scene;
pub mod scene_file;
pub mod shading_rate;
pub mod uniforms;
mod vector;
