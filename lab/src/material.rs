//! Surface materials of a mesh, as a deferred renderer's geometry pass needs
//! them: a base colour, roughness and metalness (each a factor, optionally
//! times a texture), and an optional tangent-space normal map — glTF 2.0's
//! metallic-roughness model, which OBJ/MTL materials are mapped onto (see
//! docs/scenes.md, "Materials and textures"). The textures are
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
    /// The material of an MTL entry. `texture` loads a texture named in the
    /// file (relative to the .mtl file) and reports failures itself.
    ///
    /// `Kd` is the base colour and `map_Kd` multiplies it (the MTL
    /// specification's rule); `d` (or `1 - Tr`) is its alpha. Roughness is
    /// the PBR extension's `Pr`, else derived from the Blinn-Phong exponent
    /// `Ns` by the usual correspondence alpha² = 2 / (Ns + 2), roughness =
    /// √alpha; metalness is `Pm`, else 0. `norm` is a tangent-space normal map.
    pub fn from_mtl(
        m: &tobj::Material,
        mut texture: impl FnMut(&str, &str) -> Option<Arc<TextureImage>>,
    ) -> (Material, Vec<String>) {
        let mut unsupported = vec![];
        let mut out = Material { flip_v: true, ..Material::default() };
        if let Some(kd) = m.diffuse {
            out.base_color = [kd[0], kd[1], kd[2], 1.0];
        }
        let number =
            |key: &str| m.unknown_param.get(key).and_then(|v| v.split_whitespace().next()?.parse::<f32>().ok());
        if let Some(d) = m.dissolve {
            out.base_color[3] = d.clamp(0.0, 1.0);
        } else if let Some(tr) = number("Tr") {
            out.base_color[3] = (1.0 - tr).clamp(0.0, 1.0);
        }
        out.roughness = match (number("Pr"), m.shininess) {
            (Some(pr), _) => pr.clamp(0.0, 1.0),
            (None, Some(ns)) => (2.0 / (ns.max(0.0) + 2.0)).sqrt().sqrt(),
            (None, None) => out.roughness,
        };
        out.metallic = number("Pm").map(|v| v.clamp(0.0, 1.0)).unwrap_or(0.0);
        if let Some(name) = &m.diffuse_texture {
            out.base_color_texture = texture("map_Kd", texture_file_name(name));
        }
        if let Some(name) = m.unknown_param.get("norm") {
            out.normal_texture = texture("norm", texture_file_name(name));
        }
        if let Some(name) = &m.normal_texture {
            unsupported.push(format!(
                "bump map `{}` (a height map in the MTL specification; write `norm` for a tangent-space normal map)",
                texture_file_name(name)
            ));
        }
        for key in ["map_Pr", "map_Pm", "map_Ks", "map_Ns", "map_d"] {
            let named = match key {
                "map_Ks" => m.specular_texture.as_deref(),
                "map_Ns" => m.shininess_texture.as_deref(),
                "map_d" => m.dissolve_texture.as_deref(),
                other => m.unknown_param.get(other).map(String::as_str),
            };
            if let Some(name) = named {
                unsupported.push(format!("`{key} {}`", texture_file_name(name)));
            }
        }
        (out, unsupported)
    }

    /// Whether the material has a normal map (and so its vertices need tangents).
    pub fn has_normal_map(&self) -> bool {
        self.normal_texture.is_some()
    }
}

/// The file name of an MTL texture statement, without its options
/// (`-bm 1.0 file.png`: options come first, the file name last).
fn texture_file_name(statement: &str) -> &str {
    let statement = statement.trim();
    if statement.starts_with('-') { statement.split_whitespace().last().unwrap_or(statement) } else { statement }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtl_statements_map_onto_the_pbr_model() {
        let mut m = tobj::Material {
            name: "m".into(),
            diffuse: Some([0.5, 0.25, 1.0]),
            shininess: Some(98.0),
            ..Default::default()
        };
        m.diffuse_texture = Some("-s 1 1 1 tex/albedo.png".into());
        m.unknown_param.insert("Pm".into(), "1".into());
        m.unknown_param.insert("norm".into(), "n.png".into());
        m.normal_texture = Some("height.png".into());
        let mut asked = vec![];
        let (material, unsupported) = Material::from_mtl(&m, |key, file| {
            asked.push((key.to_string(), file.to_string()));
            None
        });
        assert_eq!(asked, [("map_Kd".to_string(), "tex/albedo.png".to_string()), ("norm".into(), "n.png".into())]);
        assert_eq!(material.base_color, [0.5, 0.25, 1.0, 1.0]);
        // Ns 98: alpha = sqrt(2 / 100), roughness = sqrt(alpha).
        assert!((material.roughness - (0.02f32).sqrt().sqrt()).abs() < 1e-6);
        assert_eq!(material.metallic, 1.0);
        assert_eq!(unsupported.len(), 1, "{unsupported:?}");
        assert!(unsupported[0].contains("height.png"));
    }
}
