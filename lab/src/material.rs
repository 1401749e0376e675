//! Surface materials of a mesh, as a deferred renderer's geometry pass needs
//! them: a base colour, roughness and metalness (each a factor, optionally
//! times a texture), and an optional tangent-space normal map — glTF 2.0's
//! metallic-roughness model, which OBJ/MTL materials are mapped onto
//! (`crate::mesh`'s MTL reader; see docs/scenes.md, "Materials and
//! textures"). The textures are
//! [`TextureImage`]s, decoded and given mipmaps by [`crate::image_texture`].

use crate::image_texture::TextureImage;
use std::sync::Arc;

/// How a texture repeats outside [0, 1] (glTF's sampler wrap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A surface material (glTF 2.0's metallic-roughness model). Each texture,
/// where present, multiplies its factor; the rasteriser samples it with the
/// vertex's first texture coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    pub roughness: f32,
    pub metallic: f32,
    /// sRGB-encoded colour, alpha linear.
    pub base_color_texture: Option<Arc<TextureImage>>,
    /// Linear: roughness in G, metalness in B (glTF's packing).
    pub metallic_roughness_texture: Option<Arc<TextureImage>>,
    /// Linear tangent-space normals, `rgb = n * 0.5 + 0.5`.
    pub normal_texture: Option<Arc<TextureImage>>,
    /// Scales the normal map's x and y.
    pub normal_scale: f32,
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// glTF's `MASK` alpha mode: fragments whose alpha is below this are not drawn.
    pub alpha_cutoff: Option<f32>,
    /// The texture coordinates' v runs up the image (OBJ's convention), so
    /// textures are sampled at (u, 1 − v); glTF's v runs down (false).
    pub flip_v: bool,
}

impl Default for Material {
    /// What surfaces without material information get: a light grey
    /// dielectric of medium roughness.
    fn default() -> Material {
        Material {
            base_color: [0.8, 0.8, 0.8, 1.0],
            roughness: 0.5,
            metallic: 0.0,
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            wrap: [Wrap::Repeat; 2],
            alpha_cutoff: None,
            flip_v: false,
        }
    }
}

impl Material {
    /// Whether the material has a normal map (and so its vertices need tangents).
    pub fn has_normal_map(&self) -> bool {
        self.normal_texture.is_some()
    }
}
