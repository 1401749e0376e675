//! MTL material libraries: the parameters and textures of an OBJ's
//! `usemtl` names, mapped onto glTF's metallic-roughness model
//! ([`crate::material::Material`]), with what cannot be used reported.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{Mesh, MeshWarning};
use crate::image_texture::TextureImage;
use crate::material::Material;

/// Reads the OBJ's material libraries (relative to `dir`) and gives each of
/// `mesh.material_names` its parameters, reporting what cannot be used.
pub(super) fn read_materials(mesh: &mut Mesh, dir: &Path, libraries: &[String]) {
    let mut found: HashMap<String, tobj::Material> = HashMap::new();
    for library in libraries {
        let path = dir.join(library);
        match tobj::load_mtl(&path) {
            Ok((materials, _)) => {
                for m in materials {
                    found.entry(m.name.clone()).or_insert(m);
                }
            }
            Err(e) => mesh.warnings.push(MeshWarning::MaterialLibrary { path, message: e.to_string() }),
        }
    }
    let mut cache: HashMap<PathBuf, Option<Arc<TextureImage>>> = HashMap::new();
    for name in &mesh.material_names {
        let Some(m) = found.get(name) else {
            mesh.material_params.push(Material::default());
            continue;
        };
        let mut warnings = vec![];
        let (material, unsupported) = material_from_mtl(m, |key, file| {
            let path = dir.join(file);
            cache
                .entry(path.clone())
                .or_insert_with(|| match TextureImage::load(&path) {
                    Ok(image) => Some(Arc::new(image)),
                    Err(message) => {
                        warnings.push(MeshWarning::Texture {
                            material: name.clone(),
                            texture: format!("`{key} {file}`"),
                            message,
                        });
                        None
                    }
                })
                .clone()
        });
        mesh.warnings.extend(warnings);
        mesh.warnings.extend(
            unsupported.into_iter().map(|feature| MeshWarning::Unsupported { material: name.clone(), feature }),
        );
        mesh.material_params.push(material);
    }
}

/// The material of an MTL entry. `texture` loads a texture named in the
/// file (relative to the .mtl file) and reports failures itself.
///
/// `Kd` is the base colour and `map_Kd` multiplies it (the MTL
/// specification's rule); `d` (or `1 - Tr`) is its alpha. Roughness is
/// the PBR extension's `Pr`, else derived from the Blinn-Phong exponent
/// `Ns` by the usual correspondence alpha² = 2 / (Ns + 2), roughness =
/// √alpha; metalness is `Pm`, else 0. `norm` is a tangent-space normal map.
pub(super) fn material_from_mtl(
    m: &tobj::Material,
    mut texture: impl FnMut(&str, &str) -> Option<Arc<TextureImage>>,
) -> (Material, Vec<String>) {
    let mut unsupported = vec![];
    let mut out = Material { flip_v: true, ..Material::default() };
    if let Some(kd) = m.diffuse {
        out.base_color = [kd[0], kd[1], kd[2], 1.0];
    }
    let number = |key: &str| m.unknown_param.get(key).and_then(|v| v.split_whitespace().next()?.parse::<f32>().ok());
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
        let (material, unsupported) = material_from_mtl(&m, |key, file| {
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
