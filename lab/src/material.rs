//! Surface materials of a mesh, as a deferred renderer's geometry pass needs
//! them: a base colour, roughness and metalness (each a factor, optionally
//! times a texture), and an optional tangent-space normal map — glTF 2.0's
//! metallic-roughness model, which OBJ/MTL materials are mapped onto (see
//! docs/scenes.md, "Materials and textures").
//!
//! Textures are decoded here (PNG, JPEG and TGA, through `image`) into 8-bit
//! RGBA as their files store them; [`mip_chain`] makes their mipmaps on the
//! CPU, averaging in linear light for sRGB-encoded base colours (averaging the
//! encoded bytes would darken every minified texture) and renormalising the
//! vectors of normal maps.

use crate::color::{linear_to_srgb8, srgb_to_linear};
use std::sync::Arc;

/// How a texture repeats outside [0, 1] (glTF's sampler wrap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A decoded texture: 8-bit RGBA texels, rows top to bottom, exactly as the
/// file stores them (sRGB-encoded or linear is decided by the slot it fills).
#[derive(Clone, PartialEq)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    /// `4 * width * height` bytes.
    pub rgba: Vec<u8>,
    /// Where it came from (a file name or `image N`), for messages.
    pub source: String,
}

impl std::fmt::Debug for TextureImage {
    // The texels would drown any message that prints a mesh.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TextureImage({}, {}x{})", self.source, self.width, self.height)
    }
}

impl TextureImage {
    /// Decodes a PNG, JPEG or TGA file's bytes (the format is sniffed from
    /// the content; `hint`, a file name, settles TGA, which has no signature).
    pub fn decode(bytes: &[u8], source: &str) -> Result<TextureImage, String> {
        let format = image::guess_format(bytes).ok().or_else(|| image::ImageFormat::from_path(source).ok());
        let decoded = match format {
            Some(format) => image::load_from_memory_with_format(bytes, format),
            None => image::load_from_memory(bytes),
        }
        .map_err(|e| e.to_string())?;
        let rgba = decoded.to_rgba8();
        let (width, height) = rgba.dimensions();
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        Ok(TextureImage { width, height, rgba: rgba.into_raw(), source: source.to_string() })
    }

    /// Reads and decodes an image file.
    pub fn load(path: &std::path::Path) -> Result<TextureImage, String> {
        let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
        TextureImage::decode(&bytes, &path.display().to_string())
    }
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

/// How a texture's texels are encoded, which decides how its mipmaps are averaged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TexelEncoding {
    /// sRGB-encoded RGB, linear alpha (base colour).
    Srgb,
    /// Linear values (metallic-roughness).
    Linear,
    /// Unit vectors encoded as `n * 0.5 + 0.5` (normal maps): averaged, then renormalised.
    Normal,
}

/// Every mip level of `image`, level 0 first, down to 1x1: each level's
/// texel is the average of the 2x2 texels below it (a 2x1 or 1x2 pair, or
/// one texel, where a side is already 1; the last row or column of an odd
/// side is folded into its neighbour's average). RGBA bytes per level.
pub fn mip_chain(image: &TextureImage, encoding: TexelEncoding) -> Vec<(u32, u32, Vec<u8>)> {
    let decode = |t: &[u8]| -> [f32; 4] {
        match encoding {
            TexelEncoding::Srgb => {
                [srgb_to_linear(t[0]), srgb_to_linear(t[1]), srgb_to_linear(t[2]), t[3] as f32 / 255.0]
            }
            TexelEncoding::Linear => std::array::from_fn(|c| t[c] as f32 / 255.0),
            TexelEncoding::Normal => {
                std::array::from_fn(|c| if c < 3 { t[c] as f32 / 255.0 * 2.0 - 1.0 } else { t[c] as f32 / 255.0 })
            }
        }
    };
    let encode = |v: [f32; 4]| -> [u8; 4] {
        let unorm = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        match encoding {
            TexelEncoding::Srgb => [linear_to_srgb8(v[0]), linear_to_srgb8(v[1]), linear_to_srgb8(v[2]), unorm(v[3])],
            TexelEncoding::Linear => v.map(unorm),
            TexelEncoding::Normal => {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let n = if l > 1e-6 { [v[0] / l, v[1] / l, v[2] / l] } else { [0.0, 0.0, 1.0] };
                [unorm(n[0] * 0.5 + 0.5), unorm(n[1] * 0.5 + 0.5), unorm(n[2] * 0.5 + 0.5), unorm(v[3])]
            }
        }
    };
    let (mut w, mut h) = (image.width, image.height);
    let mut level: Vec<[f32; 4]> = image.rgba.chunks_exact(4).map(decode).collect();
    let mut out = vec![(w, h, image.rgba.clone())];
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = Vec::with_capacity((nw * nh) as usize);
        for y in 0..nh {
            // Source rows and columns of this texel: two each, three for the
            // last of an odd side (so no source texel is dropped).
            let rows = span(y, nh, h);
            for x in 0..nw {
                let cols = span(x, nw, w);
                let mut sum = [0.0f32; 4];
                let mut count = 0.0;
                for sy in rows.clone() {
                    for sx in cols.clone() {
                        let t = level[(sy * w + sx) as usize];
                        for c in 0..4 {
                            sum[c] += t[c];
                        }
                        count += 1.0;
                    }
                }
                next.push(sum.map(|s| s / count));
            }
        }
        // Each level is encoded from the one above's full-precision values,
        // so rounding does not accumulate down the chain.
        let bytes: Vec<u8> = next.iter().flat_map(|&v| encode(v)).collect();
        out.push((nw, nh, bytes));
        level = next;
        (w, h) = (nw, nh);
    }
    out
}

/// The source texels along one axis that texel `i` of a level `n` wide
/// averages, from a level `source` wide.
fn span(i: u32, n: u32, source: u32) -> std::ops::Range<u32> {
    if source == 1 {
        return 0..1;
    }
    let start = 2 * i;
    let end = if i + 1 == n { source } else { start + 2 };
    start..end
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_black_and_white_checker_minifies_to_half_linear_light() {
        let n = 8u32;
        let rgba: Vec<u8> = (0..n * n)
            .flat_map(|i| {
                let v = if (i % n + i / n).is_multiple_of(2) { 255 } else { 0 };
                [v, v, v, 255]
            })
            .collect();
        let image = TextureImage { width: n, height: n, rgba, source: "checker".into() };
        let chain = mip_chain(&image, TexelEncoding::Srgb);
        assert_eq!(chain.iter().map(|l| (l.0, l.1)).collect::<Vec<_>>(), [(8, 8), (4, 4), (2, 2), (1, 1)]);
        // Half the light: sRGB 188, not the 128 that averaging bytes gives.
        assert!(chain[1].2.chunks_exact(4).all(|t| t == [188, 188, 188, 255]), "{:?}", &chain[1].2[..8]);
        assert_eq!(&chain[3].2, &[188, 188, 188, 255]);
    }

    #[test]
    fn odd_sides_keep_every_texel_and_normals_stay_unit() {
        // 3x1: one level of 1x1 averaging all three texels.
        let image = TextureImage {
            width: 3,
            height: 1,
            rgba: vec![0, 0, 0, 0, 30, 0, 0, 0, 60, 0, 0, 0],
            source: "row".into(),
        };
        let chain = mip_chain(&image, TexelEncoding::Linear);
        assert_eq!(chain.len(), 2);
        assert_eq!(chain[1].2, vec![30, 0, 0, 0]);
        // Two normals tilted apart average to +z, renormalised.
        let a = [(0.6f32 * 0.5 + 0.5) * 255.0, 127.5, (0.8f32 * 0.5 + 0.5) * 255.0].map(|v| v.round() as u8);
        let b = [(-0.6f32 * 0.5 + 0.5) * 255.0, 127.5, (0.8f32 * 0.5 + 0.5) * 255.0].map(|v| v.round() as u8);
        let image = TextureImage {
            width: 2,
            height: 1,
            rgba: vec![a[0], a[1], a[2], 255, b[0], b[1], b[2], 255],
            source: "normals".into(),
        };
        let top = &mip_chain(&image, TexelEncoding::Normal)[1].2;
        assert!((top[0] as i32 - 128).abs() <= 1 && top[2] == 255, "{top:?}");
    }

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
