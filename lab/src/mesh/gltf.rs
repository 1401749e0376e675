//! glTF 2.0 files (`.gltf` with external or embedded buffers, or binary
//! `.glb`), read through the `gltf` crate: buffers, the node hierarchy's
//! transforms, triangle primitives and their materials and textures.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::{DEFAULT_CREASE_ANGLE, Mesh, MeshError, MeshWarning, drop_degenerate_triangles};
use crate::image_texture::TextureImage;
use crate::material::{Material, Wrap};
use crate::vector::normalize;
use base64::Engine as _;
use glam::{Mat3, Mat4, Vec3};

/// A mesh of the file and the transform of the node that places it.
type Instance<'a> = (::gltf::Mesh<'a>, Mat4);

impl Mesh {
    /// Loads a glTF 2.0 file (`.gltf` with external or embedded buffers, or
    /// binary `.glb`): every triangle primitive of the default scene (or of
    /// every mesh, when the file has no scene) with its node transforms
    /// applied. Each glTF material is one material id (named after it, or
    /// `material<N>`); primitives without a material share one named
    /// `default`. Primitives without normals get smooth normals.
    pub fn load_gltf(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| MeshError::Io { path: path.to_path_buf(), source })?;
        let error = |message: String| MeshError::Gltf { path: path.to_path_buf(), message };
        let gltf = ::gltf::Gltf::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
        let buffers = read_buffers(&gltf, path)?;
        let mut mesh = materials(&gltf, path, &buffers);
        let mut default_material: Option<u32> = None;
        let mut degenerate = 0usize;
        for (gmesh, world) in instances(&gltf).map_err(error)? {
            for primitive in gmesh.primitives() {
                let Some(mut piece) = primitive_piece(&primitive, &gmesh, world, &buffers).map_err(error)? else {
                    continue;
                };
                degenerate += drop_degenerate_triangles(&piece.positions, &mut piece.indices);
                let material = match primitive.material().index() {
                    Some(i) => i as u32,
                    None => *default_material.get_or_insert_with(|| {
                        mesh.material_names.push("default".into());
                        mesh.material_names.len() as u32 - 1
                    }),
                };
                piece.materials = vec![material; piece.positions.len()];
                if piece.normals.is_empty() {
                    piece.normals = vec![[0.0; 3]; piece.positions.len()];
                    piece.compute_normals(DEFAULT_CREASE_ANGLE);
                }
                mesh.append(&piece);
            }
        }
        if degenerate > 0 {
            mesh.warnings.push(MeshWarning::DegenerateFaces { count: degenerate });
        }
        if mesh.indices.is_empty() {
            return Err(MeshError::Empty { path: path.to_path_buf() });
        }
        mesh.ensure_tangents();
        Ok(mesh)
    }
}

/// The file's buffers: the GLB binary chunk, data URIs, or files next to the model.
fn read_buffers(gltf: &::gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>, MeshError> {
    let error = |message: String| MeshError::Gltf { path: path.to_path_buf(), message };
    let mut buffers: Vec<Vec<u8>> = vec![];
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            ::gltf::buffer::Source::Bin => {
                gltf.blob.clone().ok_or_else(|| error("buffer refers to a missing GLB binary chunk".into()))?
            }
            ::gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(data) => data.map_err(|message| error(format!("buffer {}: {message}", buffer.index())))?,
                None => {
                    let file = beside(path, uri);
                    std::fs::read(&file).map_err(|source| MeshError::Io { path: file, source })?
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(error(format!(
                "buffer {} has {} bytes, the file declares {}",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// A mesh without triangles yet: the file's material names and parameters
/// (their textures decoded once per image), and the warnings they raise.
fn materials(gltf: &::gltf::Gltf, path: &Path, buffers: &[Vec<u8>]) -> Mesh {
    let mut mesh = Mesh { material_names: gltf.materials().map(|m| material_name(&m)).collect(), ..Default::default() };
    let mut images: HashMap<usize, Option<Arc<TextureImage>>> = HashMap::new();
    for material in gltf.materials() {
        let params = gltf_material(&material, path, buffers, &mut images, &mut mesh.warnings);
        mesh.material_params.push(params);
    }
    if gltf.extensions_used().any(|e| e == "KHR_texture_transform") {
        mesh.warnings.push(MeshWarning::Unsupported {
            material: "(any)".into(),
            feature: "KHR_texture_transform (texture coordinates are used untransformed)".into(),
        });
    }
    mesh
}

fn material_name(material: &::gltf::Material) -> String {
    material.name().map(str::to_string).unwrap_or_else(|| format!("material{}", material.index().unwrap_or(0)))
}

/// The meshes of the default scene (else the first) with their nodes' world
/// transforms, or every mesh untransformed when the file has no scene.
fn instances(gltf: &::gltf::Gltf) -> Result<Vec<Instance<'_>>, String> {
    let Some(scene) = gltf.default_scene().or_else(|| gltf.scenes().next()) else {
        return Ok(gltf.meshes().map(|m| (m, Mat4::IDENTITY)).collect());
    };
    let mut instances = vec![];
    let mut stack: Vec<(::gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1_000_000 {
            return Err("the node hierarchy has a cycle".into());
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(m) = node.mesh() {
            instances.push((m, world));
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(instances)
}

/// A triangle primitive (strips and fans unrolled) in world space, without
/// its material ids; its normals are empty where the file has none. `None`
/// for points, lines and primitives without positions.
fn primitive_piece(
    primitive: &::gltf::Primitive,
    gmesh: &::gltf::Mesh,
    world: Mat4,
    buffers: &[Vec<u8>],
) -> Result<Option<Mesh>, String> {
    use ::gltf::mesh::Mode;
    let mode = primitive.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        return Ok(None);
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| d.as_slice()));
    let Some(positions) = reader.read_positions() else { return Ok(None) };
    let positions: Vec<[f32; 3]> = positions.map(|p| world.transform_point3(Vec3::from(p)).to_array()).collect();
    let n = positions.len();
    let normal_matrix = normal_matrix(world);
    let normals: Option<Vec<[f32; 3]>> = reader
        .read_normals()
        .map(|ns| ns.map(|v| normalize(normal_matrix * Vec3::from(v)).to_array()).collect::<Vec<_>>())
        .filter(|v| v.len() == n);
    let uvs: Vec<[f32; 2]> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().collect::<Vec<_>>())
        .filter(|v| v.len() == n)
        .unwrap_or_else(|| vec![[0.0, 0.0]; n]);
    let colors: Vec<[f32; 4]> = reader
        .read_colors(0)
        .map(|c| c.into_rgba_f32().collect::<Vec<_>>())
        .filter(|v| v.len() == n)
        .unwrap_or_default();
    // Tangents follow the node transform like directions; a mirroring
    // transform turns the bitangent's handedness.
    let mirrored = det3(world) < 0.0;
    let tangents: Vec<[f32; 4]> = reader
        .read_tangents()
        .map(|ts| {
            ts.map(|t| {
                let d = normalize(world.transform_vector3(Vec3::new(t[0], t[1], t[2])));
                let w = if t[3] < 0.0 { -1.0 } else { 1.0 };
                d.extend(if mirrored { -w } else { w }).to_array()
            })
            .collect::<Vec<_>>()
        })
        .filter(|v| v.len() == n && normals.is_some())
        .unwrap_or_default();
    let raw: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if let Some(bad) = raw.iter().find(|&&i| i as usize >= n) {
        let name = gmesh.name().map(str::to_string).unwrap_or_else(|| gmesh.index().to_string());
        return Err(format!("mesh {name} has index {bad} but only {n} vertices"));
    }
    let mut indices = triangle_list(mode, &raw);
    if mirrored {
        for t in indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }
    let normals = normals.unwrap_or_default();
    Ok(Some(Mesh { positions, normals, uvs, indices, tangents, colors, ..Default::default() }))
}

/// A glTF material's parameters, its textures decoded (once per image, in
/// `images`) from GLB chunks, data URIs or files next to the model.
fn gltf_material(
    material: &::gltf::Material,
    path: &Path,
    buffers: &[Vec<u8>],
    images: &mut HashMap<usize, Option<Arc<TextureImage>>>,
    warnings: &mut Vec<MeshWarning>,
) -> Material {
    let name = material_name(material);
    let pbr = material.pbr_metallic_roughness();
    let mut out = Material {
        base_color: pbr.base_color_factor(),
        roughness: pbr.roughness_factor(),
        metallic: pbr.metallic_factor(),
        alpha_cutoff: match material.alpha_mode() {
            ::gltf::material::AlphaMode::Mask => Some(material.alpha_cutoff().unwrap_or(0.5)),
            _ => None,
        },
        ..Material::default()
    };
    if material.alpha_mode() == ::gltf::material::AlphaMode::Blend {
        warnings.push(MeshWarning::Unsupported {
            material: name.clone(),
            feature: "alpha blending (drawn opaque; alpha is in the albedo channel)".into(),
        });
    }
    let mut texture = |slot: &str, texture: ::gltf::Texture, tex_coord: u32, out: &mut Material| {
        if tex_coord != 0 {
            warnings.push(MeshWarning::Unsupported {
                material: name.clone(),
                feature: format!("{slot} on texture coordinates {tex_coord} (only TEXCOORD_0 is read)"),
            });
            return None;
        }
        let sampler = texture.sampler();
        let wrap = |mode: ::gltf::texture::WrappingMode| match mode {
            ::gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            ::gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            ::gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        };
        out.wrap = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
        let image = texture.source();
        images
            .entry(image.index())
            .or_insert_with(|| match gltf_image(&image, path, buffers) {
                Ok(decoded) => Some(Arc::new(decoded)),
                Err(message) => {
                    warnings.push(MeshWarning::Texture {
                        material: name.clone(),
                        texture: format!("{slot} (image {})", image.index()),
                        message,
                    });
                    None
                }
            })
            .clone()
    };
    if let Some(info) = pbr.base_color_texture() {
        out.base_color_texture = texture("baseColorTexture", info.texture(), info.tex_coord(), &mut out);
    }
    if let Some(info) = pbr.metallic_roughness_texture() {
        out.metallic_roughness_texture =
            texture("metallicRoughnessTexture", info.texture(), info.tex_coord(), &mut out);
    }
    if let Some(info) = material.normal_texture() {
        out.normal_scale = info.scale();
        out.normal_texture = texture("normalTexture", info.texture(), info.tex_coord(), &mut out);
    }
    out
}

/// Decodes a glTF image from a buffer view, a data URI or a file next to the model.
fn gltf_image(image: &::gltf::Image, path: &Path, buffers: &[Vec<u8>]) -> Result<TextureImage, String> {
    match image.source() {
        ::gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
            let bytes =
                data.get(view.offset()..view.offset() + view.length()).ok_or("its buffer view is out of range")?;
            TextureImage::decode(bytes, &format!("image {}", image.index()))
        }
        ::gltf::image::Source::Uri { uri, .. } => match data_uri(uri) {
            Some(bytes) => TextureImage::decode(&bytes?, &format!("image {}", image.index())),
            None => {
                let file = beside(path, uri);
                TextureImage::load(&file).map_err(|e| format!("{}: {e}", file.display()))
            }
        },
    }
}

/// The determinant of the upper 3x3 of `m` (the columns' triple product).
fn det3(m: Mat4) -> f32 {
    let [c0, c1, c2] = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate());
    c0.dot(c1.cross(c2))
}

/// The matrix that transforms normals: the inverse transpose of the upper
/// 3x3, up to a positive factor (the cofactor matrix, whose rows are the
/// cross products of the columns, with the determinant's sign).
fn normal_matrix(m: Mat4) -> Mat3 {
    let [c0, c1, c2] = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate());
    let s = if det3(m) < 0.0 { -1.0 } else { 1.0 };
    Mat3::from_cols(s * c1.cross(c2), s * c2.cross(c0), s * c0.cross(c1))
}

/// A glTF primitive's indices as a triangle list.
fn triangle_list(mode: ::gltf::mesh::Mode, raw: &[u32]) -> Vec<u32> {
    match mode {
        ::gltf::mesh::Mode::TriangleStrip => (2..raw.len())
            .flat_map(|k| if k % 2 == 0 { [raw[k - 2], raw[k - 1], raw[k]] } else { [raw[k - 1], raw[k - 2], raw[k]] })
            .collect(),
        ::gltf::mesh::Mode::TriangleFan => (2..raw.len()).flat_map(|k| [raw[0], raw[k - 1], raw[k]]).collect(),
        _ => raw[..raw.len() / 3 * 3].to_vec(),
    }
}

/// The bytes of a `data:` URI (`None` for any other URI): only base64 data
/// is supported. Decoded by the `base64` crate, with padding optional and
/// either alphabet (standard, or URL-safe), as the hand-written decoder
/// before it; unlike that one, it refuses an `=` before the end and a mix of
/// the two alphabets, which no encoder writes.
fn data_uri(uri: &str) -> Option<Result<Vec<u8>, &'static str>> {
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    const CONFIG: GeneralPurposeConfig = GeneralPurposeConfig::new()
        .with_decode_padding_mode(DecodePaddingMode::Indifferent)
        .with_decode_allow_trailing_bits(true);
    const STANDARD: GeneralPurpose = GeneralPurpose::new(&base64::alphabet::STANDARD, CONFIG);
    const URL_SAFE: GeneralPurpose = GeneralPurpose::new(&base64::alphabet::URL_SAFE, CONFIG);
    let rest = uri.strip_prefix("data:")?;
    let Some((_, data)) = rest.split_once(";base64,") else { return Some(Err("only base64 data URIs are supported")) };
    // Line breaks and spaces are not data (RFC 2045 lets encoders wrap lines).
    let data: Vec<u8> = data.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    Some(STANDARD.decode(&data).or_else(|_| URL_SAFE.decode(&data)).map_err(|_| "invalid base64 data"))
}

/// The file a relative URI names, next to the model (percent-decoded).
fn beside(model: &Path, uri: &str) -> std::path::PathBuf {
    let name = percent_encoding::percent_decode_str(uri).decode_utf8_lossy();
    model.parent().unwrap_or(Path::new(".")).join(name.as_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_decode_with_or_without_padding_in_either_alphabet() {
        let decode = |uri: &str| data_uri(uri).map(|r| r.map_err(str::to_string));
        assert_eq!(decode("data:application/octet-stream;base64,AAEC/w=="), Some(Ok(vec![0, 1, 2, 255])));
        assert_eq!(decode("data:application/octet-stream;base64,AAEC_w"), Some(Ok(vec![0, 1, 2, 255])));
        assert_eq!(decode("data:image/png;base64,AA\r\nEC /w=="), Some(Ok(vec![0, 1, 2, 255])));
        assert_eq!(decode("data:text/plain,hello"), Some(Err("only base64 data URIs are supported".into())));
        assert_eq!(decode("data:;base64,A"), Some(Err("invalid base64 data".into())));
        assert_eq!(decode("data:;base64,AA!C"), Some(Err("invalid base64 data".into())));
        assert_eq!(decode("buffer.bin"), None);
    }

    #[test]
    fn relative_uris_are_percent_decoded_next_to_the_model() {
        let model = Path::new("/scenes/level.gltf");
        assert_eq!(beside(model, "tex/a%20b.png"), Path::new("/scenes/tex/a b.png"));
        // Not an escape: kept as written.
        assert_eq!(beside(model, "100%.png"), Path::new("/scenes/100%.png"));
        assert_eq!(beside(model, "%zz.png"), Path::new("/scenes/%zz.png"));
        assert_eq!(beside(Path::new("level.gltf"), "b.bin"), Path::new("b.bin"));
    }
}
