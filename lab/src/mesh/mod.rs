//! Triangle meshes for the G-buffer rasteriser: loaders for Wavefront OBJ
//! (through `tobj`) and glTF 2.0 / GLB (through `gltf`), smooth normals with
//! a crease angle for models that have none, and the Dabrovic Sponza, which
//! the crates.io package `obj-rs` 0.7.4 ships as a test fixture.
//!
//! A [`Mesh`] is indexed and single-indexed: vertex `i` has `positions[i]`,
//! `normals[i]`, `uvs[i]` and `materials[i]` (and `tangents[i]` and
//! `colors[i]` where those are not empty). Materials are stored **per
//! vertex**, and the loaders never share a vertex between two materials, so
//! the three vertices of a triangle always carry the same id (the rasteriser
//! takes a triangle's material from its first vertex). Material ids index
//! `material_names` and `material_params` (the factors and textures, see
//! [`crate::material`]).
//!
//! What a loader skips or cannot use is not dropped silently: degenerate
//! faces (fewer than three corners, or no area), textures that cannot be
//! read and material features that are not supported become
//! [`MeshWarning`]s in `Mesh::warnings`, which the tools print once.

use std::collections::HashMap;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::image_texture::TextureImage;
use crate::material::{Material, Wrap};

/// Default crease angle (degrees) for computed normals: faces meeting at a
/// sharper angle keep their own normal, so boxes stay boxes while Sponza's
/// columns and arches shade smoothly.
pub const DEFAULT_CREASE_ANGLE: f32 = 45.0;

/// Where the Dabrovic Sponza lies inside the `obj-rs` 0.7.4 package.
const SPONZA_IN_PACKAGE: &str = "tests/fixtures/sponza.obj";
const SPONZA_PACKAGE: &str = "obj-rs";
const SPONZA_VERSION: &str = "0.7.4";

/// Why a mesh could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: not a valid OBJ file: {message}", path.display())]
    Obj { path: PathBuf, message: String },
    #[error("{}: not a valid glTF file: {message}", path.display())]
    Gltf { path: PathBuf, message: String },
    #[error("{}: unsupported mesh format (expected .obj, .gltf or .glb)", path.display())]
    UnsupportedFormat { path: PathBuf },
    #[error("{}: the file has no triangles", path.display())]
    Empty { path: PathBuf },
    #[error(
        "the Dabrovic Sponza (tests/fixtures/sponza.obj of the crates.io package obj-rs 0.7.4) was not found; \
         run `cargo fetch` in the workspace (mrslc finds it in cargo's registry), or set MRSL_SPONZA to the file. \
         Looked at: {}",
        searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    SponzaNotFound { searched: Vec<PathBuf> },
    #[error(
        "the textured dungeon scene (level-dungeon.gltf of Debian's castle-game-engine-doc package) was not found; \
         run scripts/fetch-dungeon.sh in the workspace, or set MRSL_DUNGEON to the file. Looked at: {}",
        searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    DungeonNotFound { searched: Vec<PathBuf> },
    #[error("invalid mesh: {0}")]
    Invalid(String),
}

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Bounds {
    pub fn center(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| 0.5 * (self.min[i] + self.max[i]))
    }
    pub fn extent(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| self.max[i] - self.min[i])
    }
    /// Length of the diagonal.
    pub fn diagonal(&self) -> f32 {
        length(self.extent())
    }
    /// The eight corners.
    pub fn corners(&self) -> [[f32; 3]; 8] {
        std::array::from_fn(|k| {
            [
                if k & 1 == 0 { self.min[0] } else { self.max[0] },
                if k & 2 == 0 { self.min[1] } else { self.max[1] },
                if k & 4 == 0 { self.min[2] } else { self.max[2] },
            ]
        })
    }
}

/// An indexed triangle mesh (see the module documentation for the conventions).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per vertex.
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    /// Material id per vertex (see the module documentation).
    pub materials: Vec<u32>,
    /// Three per triangle, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
    pub material_names: Vec<String>,
    /// Per vertex, or empty: xyz the unit tangent (the direction of
    /// increasing u), w the bitangent's sign (bitangent = w · normal ×
    /// tangent); w = 0 where the vertex has none. Filled for the triangles of
    /// normal-mapped materials (from the file, else by MikkTSpace).
    pub tangents: Vec<[f32; 4]>,
    /// Per vertex, or empty (white): linear RGBA that multiplies the base
    /// colour (glTF's `COLOR_0`).
    pub colors: Vec<[f32; 4]>,
    /// Per material id (missing entries are [`Material::default`]).
    pub material_params: Vec<Material>,
    /// What the loader skipped or could not use (see [`MeshWarning`]).
    pub warnings: Vec<MeshWarning>,
}

/// Something a loader skipped or could not use; the mesh is still usable.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshWarning {
    /// Faces with fewer than three corners, or triangles without area (two
    /// corners at the same position, or all three on a line), were left out.
    DegenerateFaces { count: usize },
    /// A texture could not be loaded; the material uses its constant factor.
    Texture { material: String, texture: String, message: String },
    /// A material library (`mtllib`) could not be read.
    MaterialLibrary { path: PathBuf, message: String },
    /// A material feature the kit does not use.
    Unsupported { material: String, feature: String },
    /// Tangents could not be generated for a normal-mapped material (its
    /// normal map is then not applied where they are missing).
    Tangents { message: String },
}

impl std::fmt::Display for MeshWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshWarning::DegenerateFaces { count } => write!(
                f,
                "{count} degenerate face{} (fewer than three corners, or no area) left out",
                if *count == 1 { "" } else { "s" }
            ),
            MeshWarning::Texture { material, texture, message } => {
                write!(
                    f,
                    "material `{material}`: texture {texture} not loaded ({message}); its constant factor is used"
                )
            }
            MeshWarning::MaterialLibrary { path, message } => {
                write!(f, "material library {} not read ({message}); its materials get the default", path.display())
            }
            MeshWarning::Unsupported { material, feature } => {
                write!(f, "material `{material}`: {feature} is not supported and is ignored")
            }
            MeshWarning::Tangents { message } => write!(f, "tangents: {message}"),
        }
    }
}

impl Mesh {
    /// Loads an `.obj`, `.gltf` or `.glb` file (by extension, case-insensitive).
    pub fn load(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("obj") => Mesh::load_obj(path),
            Some("gltf" | "glb") => Mesh::load_gltf(path),
            _ => Err(MeshError::UnsupportedFormat { path: path.to_path_buf() }),
        }
    }

    /// The Dabrovic Sponza, with computed normals (crease angle
    /// [`DEFAULT_CREASE_ANGLE`]) and its 35 materials numbered 0..34 in the
    /// order the file first uses them.
    pub fn sponza() -> Result<Mesh, MeshError> {
        Mesh::load_obj(sponza_path()?)
    }

    /// Loads a Wavefront OBJ file: polygons are triangulated by ear clipping
    /// (Sponza has concave polygons of up to 78 vertices, which a fan would
    /// fill wrongly), `usemtl` names become material ids in the order of
    /// first use (an `.mtl` file is not needed: only the names are used), and
    /// objects without normals get smooth normals with
    /// [`DEFAULT_CREASE_ANGLE`]. Faces before any `usemtl` get a material
    /// named `default`. Objects without texture coordinates (and objects
    /// whose corners all share one) get uv (0, 0).
    pub fn load_obj(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let io = |source| MeshError::Io { path: path.to_path_buf(), source };
        let text = std::fs::read(path).map_err(io)?;
        let obj_error = |message: String| MeshError::Obj { path: path.to_path_buf(), message };

        // Material names in the order of first use. tobj only numbers
        // materials it found in an .mtl file, so a synthetic material library
        // with exactly these names is put in front of the file.
        let mut names: Vec<String> = vec![];
        let mut libraries: Vec<String> = vec![];
        let mut degenerate = 0usize;
        for line in text.lines() {
            let line = line.map_err(|e| obj_error(e.to_string()))?;
            if let Some(rest) = line.trim_start().strip_prefix("usemtl") {
                let name = rest.trim();
                if !name.is_empty() && rest.starts_with(char::is_whitespace) && !names.iter().any(|n| n == name) {
                    names.push(name.to_string());
                }
            } else if let Some(rest) = line.trim_start().strip_prefix("mtllib")
                && rest.starts_with(char::is_whitespace)
            {
                libraries.push(rest.trim().to_string());
            } else if let Some(rest) = line.trim_start().strip_prefix("f ")
                && rest.split_whitespace().count() < 3
            {
                // tobj reads a face of one or two corners as a point or a
                // line and drops it unseen; counted here.
                degenerate += 1;
            }
        }
        const SYNTHETIC: &str = "<mrsl usemtl names>";
        let header = format!("mtllib {SYNTHETIC}\n");
        let mut reader = std::io::BufReader::new(header.as_bytes().chain(&text[..]));
        let options = tobj::LoadOptions {
            // tobj's single-index mode misaligns texture coordinates when some
            // faces have `vt` and others do not (Sponza has both), and its
            // triangulation is a fan: both are done here instead.
            single_index: false,
            triangulate: false,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _) = tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| {
            if mtl == Path::new(SYNTHETIC) {
                let materials: Vec<tobj::Material> =
                    names.iter().map(|n| tobj::Material { name: n.clone(), ..Default::default() }).collect();
                Ok((materials, names.iter().enumerate().map(|(i, n)| (n.clone(), i)).collect()))
            } else {
                Err(tobj::LoadError::OpenFileFailed)
            }
        })
        .map_err(|e| obj_error(e.to_string()))?;

        let mut material_names = names.clone();
        let mut default_material: Option<u32> = None;
        let mut pieces: Vec<(Mesh, bool)> = vec![];
        for model in &models {
            let m = &model.mesh;
            let corners = m.indices.len();
            if corners == 0 {
                continue;
            }
            let material = match m.material_id {
                Some(id) => id as u32,
                None => *default_material.get_or_insert_with(|| {
                    material_names.push("default".into());
                    material_names.len() as u32 - 1
                }),
            };
            // For corners without `vt`, tobj repeats the previous corner's
            // (or the file's first) texture coordinate, so an object whose
            // faces have none comes out with a single coordinate everywhere:
            // such objects get uv (0, 0), which interpolates exactly (a
            // constant like 1.0 comes out a rounding error either side of
            // it, which makes `floor(uv * n)` flicker between two values).
            let has_uv = m.texcoord_indices.len() == corners && m.texcoords.len() > 2;
            let has_normals = m.normal_indices.len() == corners && !m.normals.is_empty();
            let arities: Vec<u32> =
                if m.face_arities.is_empty() { vec![3; corners / 3] } else { m.face_arities.clone() };
            // Single-index the corners: one vertex per (position, uv, normal).
            let mut piece = Mesh::default();
            let mut map: HashMap<(u32, u32, u32), u32> = HashMap::new();
            let mut corner_vertex = Vec::with_capacity(corners);
            for c in 0..corners {
                let p = m.indices[c];
                let t = if has_uv { m.texcoord_indices[c] } else { u32::MAX };
                let n = if has_normals { m.normal_indices[c] } else { u32::MAX };
                let index = *map.entry((p, t, n)).or_insert_with(|| {
                    let pi = p as usize * 3;
                    piece.positions.push([m.positions[pi], m.positions[pi + 1], m.positions[pi + 2]]);
                    piece.uvs.push(if has_uv {
                        let ti = t as usize * 2;
                        [m.texcoords[ti], m.texcoords[ti + 1]]
                    } else {
                        [0.0, 0.0]
                    });
                    piece.normals.push(if has_normals {
                        let ni = n as usize * 3;
                        normalize([m.normals[ni], m.normals[ni + 1], m.normals[ni + 2]])
                    } else {
                        [0.0, 0.0, 0.0]
                    });
                    piece.materials.push(material);
                    (piece.positions.len() - 1) as u32
                });
                corner_vertex.push(index);
            }
            let mut start = 0usize;
            for &arity in &arities {
                let end = (start + arity as usize).min(corner_vertex.len());
                let polygon = &corner_vertex[start..end];
                start = end;
                if polygon.len() >= 3 {
                    triangulate(&piece.positions, polygon, &mut piece.indices);
                } else {
                    degenerate += 1;
                }
            }
            degenerate += drop_degenerate_triangles(&piece.positions, &mut piece.indices);
            pieces.push((piece, has_normals));
        }
        let mut mesh = Mesh { material_names, ..Default::default() };
        if degenerate > 0 {
            mesh.warnings.push(MeshWarning::DegenerateFaces { count: degenerate });
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        read_mtl_materials(&mut mesh, dir, &libraries);
        if pieces.iter().all(|(_, has_normals)| !has_normals) {
            // No normals anywhere: smooth over the whole model, so that
            // surfaces split across objects or materials stay continuous.
            for (piece, _) in &pieces {
                mesh.append(piece);
            }
            mesh.compute_normals(DEFAULT_CREASE_ANGLE);
        } else {
            for (mut piece, has_normals) in pieces {
                if !has_normals {
                    piece.compute_normals(DEFAULT_CREASE_ANGLE);
                }
                mesh.append(&piece);
            }
        }
        if mesh.indices.is_empty() {
            return Err(MeshError::Empty { path: path.to_path_buf() });
        }
        mesh.ensure_tangents();
        Ok(mesh)
    }

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
        let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
        let mut buffers: Vec<Vec<u8>> = vec![];
        for buffer in gltf.buffers() {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => {
                    gltf.blob.clone().ok_or_else(|| error("buffer refers to a missing GLB binary chunk".into()))?
                }
                gltf::buffer::Source::Uri(uri) => {
                    if let Some(rest) = uri.strip_prefix("data:") {
                        let (_, data) = rest.split_once(";base64,").ok_or_else(|| {
                            error(format!("buffer {}: only base64 data URIs are supported", buffer.index()))
                        })?;
                        base64_decode(data)
                            .ok_or_else(|| error(format!("buffer {}: invalid base64 data", buffer.index())))?
                    } else {
                        let file = path.parent().unwrap_or(Path::new(".")).join(percent_decode(uri));
                        std::fs::read(&file).map_err(|source| MeshError::Io { path: file, source })?
                    }
                }
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

        let mut mesh = Mesh {
            material_names: gltf
                .materials()
                .map(|m| m.name().map(str::to_string).unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))))
                .collect(),
            ..Default::default()
        };
        let mut images: HashMap<usize, Option<Arc<TextureImage>>> = HashMap::new();
        for material in gltf.materials() {
            let params = gltf_material(&material, path, &buffers, &mut images, &mut mesh.warnings);
            mesh.material_params.push(params);
        }
        if gltf.extensions_used().any(|e| e == "KHR_texture_transform") {
            mesh.warnings.push(MeshWarning::Unsupported {
                material: "(any)".into(),
                feature: "KHR_texture_transform (texture coordinates are used untransformed)".into(),
            });
        }
        let mut default_material: Option<u32> = None;
        let mut degenerate = 0usize;
        let identity = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
        let mut instances: Vec<(gltf::Mesh, [[f32; 4]; 4])> = vec![];
        match gltf.default_scene().or_else(|| gltf.scenes().next()) {
            Some(scene) => {
                let mut stack: Vec<(gltf::Node, [[f32; 4]; 4])> = scene.nodes().map(|n| (n, identity)).collect();
                let mut visited = 0usize;
                while let Some((node, parent)) = stack.pop() {
                    visited += 1;
                    if visited > 1_000_000 {
                        return Err(error("the node hierarchy has a cycle".into()));
                    }
                    let world = mat4_mul(parent, node.transform().matrix());
                    if let Some(m) = node.mesh() {
                        instances.push((m, world));
                    }
                    stack.extend(node.children().map(|c| (c, world)));
                }
            }
            None => instances.extend(gltf.meshes().map(|m| (m, identity))),
        }
        for (gmesh, world) in instances {
            let normal_matrix = normal_matrix(world);
            let mirrored = det3(world) < 0.0;
            for primitive in gmesh.primitives() {
                let mode = primitive.mode();
                if !matches!(
                    mode,
                    gltf::mesh::Mode::Triangles | gltf::mesh::Mode::TriangleStrip | gltf::mesh::Mode::TriangleFan
                ) {
                    continue;
                }
                let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| d.as_slice()));
                let Some(positions) = reader.read_positions() else { continue };
                let positions: Vec<[f32; 3]> = positions.map(|p| transform_point(world, p)).collect();
                let n = positions.len();
                let normals: Option<Vec<[f32; 3]>> = reader
                    .read_normals()
                    .map(|ns| ns.map(|v| normalize(mat3_mul(normal_matrix, v))).collect::<Vec<_>>())
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
                // Tangents follow the node transform like directions; a
                // mirroring transform turns the bitangent's handedness.
                let tangents: Vec<[f32; 4]> = reader
                    .read_tangents()
                    .map(|ts| {
                        ts.map(|t| {
                            let d = normalize(transform_vector(world, [t[0], t[1], t[2]]));
                            let w = if t[3] < 0.0 { -1.0 } else { 1.0 };
                            [d[0], d[1], d[2], if mirrored { -w } else { w }]
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
                    return Err(error(format!(
                        "mesh {} has index {bad} but only {n} vertices",
                        gmesh.name().map(str::to_string).unwrap_or_else(|| gmesh.index().to_string())
                    )));
                }
                let mut indices = triangle_list(mode, &raw);
                if mirrored {
                    for t in indices.chunks_exact_mut(3) {
                        t.swap(1, 2);
                    }
                }
                degenerate += drop_degenerate_triangles(&positions, &mut indices);
                let material = match primitive.material().index() {
                    Some(i) => i as u32,
                    None => *default_material.get_or_insert_with(|| {
                        mesh.material_names.push("default".into());
                        mesh.material_names.len() as u32 - 1
                    }),
                };
                let mut piece = Mesh {
                    normals: normals.clone().unwrap_or_else(|| vec![[0.0; 3]; n]),
                    positions,
                    uvs,
                    materials: vec![material; n],
                    indices,
                    tangents,
                    colors,
                    ..Default::default()
                };
                if normals.is_none() {
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

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The bounds of the vertices that triangles use, or `None` for a mesh
    /// without triangles.
    pub fn bounds(&self) -> Option<Bounds> {
        let mut it = self.indices.iter().filter_map(|&i| self.positions.get(i as usize));
        let first = *it.next()?;
        let mut b = Bounds { min: first, max: first };
        for p in it {
            for (k, &v) in p.iter().enumerate() {
                b.min[k] = b.min[k].min(v);
                b.max[k] = b.max[k].max(v);
            }
        }
        Some(b)
    }

    /// Checks the mesh's invariants: one normal, uv and material per
    /// position, whole triangles, and indices in range.
    pub fn validate(&self) -> Result<(), MeshError> {
        let n = self.positions.len();
        for (what, len) in
            [("normals", self.normals.len()), ("uvs", self.uvs.len()), ("materials", self.materials.len())]
        {
            if len != n {
                return Err(MeshError::Invalid(format!("{len} {what} for {n} positions")));
            }
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(MeshError::Invalid(format!(
                "{} indices is not a whole number of triangles",
                self.indices.len()
            )));
        }
        for (what, len) in [("tangents", self.tangents.len()), ("colors", self.colors.len())] {
            if len != 0 && len != n {
                return Err(MeshError::Invalid(format!("{len} {what} for {n} positions (expected 0 or {n})")));
            }
        }
        if let Some(bad) = self.indices.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::Invalid(format!("index {bad} is out of range ({n} vertices)")));
        }
        Ok(())
    }

    /// The material of id `id` (the default for ids without parameters).
    pub fn material(&self, id: u32) -> Material {
        self.material_params.get(id as usize).cloned().unwrap_or_default()
    }

    /// Appends `other`'s triangles; its material ids are kept as they are
    /// (and so are this mesh's names, parameters and warnings).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len();
        extend_optional(&mut self.tangents, base, &other.tangents, other.positions.len(), [0.0; 4]);
        extend_optional(&mut self.colors, base, &other.colors, other.positions.len(), [1.0; 4]);
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.uvs.extend_from_slice(&other.uvs);
        self.materials.extend_from_slice(&other.materials);
        self.indices.extend(other.indices.iter().map(|i| i + base as u32));
    }

    /// Gives tangents to the triangles of normal-mapped materials that lack
    /// them, by MikkTSpace (what glTF prescribes for files without
    /// tangents), from their positions, normals and texture coordinates.
    /// Vertices are split where corners that share one need different
    /// tangents. Failures become a [`MeshWarning::Tangents`].
    pub fn ensure_tangents(&mut self) {
        let mapped: Vec<bool> = (0..self.material_names.len().max(self.material_params.len()))
            .map(|id| self.material_params.get(id).is_some_and(Material::has_normal_map))
            .collect();
        // MikkTSpace is given texture coordinates whose second axis runs up
        // the image (OpenGL's convention, which glTF's normal maps follow:
        // +Y is up), so the bitangent points up the texture.
        let flip: Vec<bool> = self.material_params.iter().map(|m| m.flip_v).collect();
        let needs = |mesh: &Mesh, t: &[u32]| {
            let id = mesh.materials[t[0] as usize] as usize;
            mapped.get(id).copied().unwrap_or(false)
                && t.iter().any(|&i| mesh.tangents.get(i as usize).is_none_or(|v| v[3] == 0.0))
        };
        let faces: Vec<usize> =
            (0..self.indices.len() / 3).filter(|&f| needs(self, &self.indices[3 * f..3 * f + 3])).collect();
        if faces.is_empty() {
            return;
        }
        if self.tangents.is_empty() {
            self.tangents = vec![[0.0; 4]; self.positions.len()];
        }
        struct Geometry<'a> {
            mesh: &'a Mesh,
            faces: &'a [usize],
            flip: &'a [bool],
            out: Vec<[f32; 4]>,
        }
        impl bevy_mikktspace::Geometry for Geometry<'_> {
            fn num_faces(&self) -> usize {
                self.faces.len()
            }
            fn num_vertices_of_face(&self, _face: usize) -> usize {
                3
            }
            fn position(&self, face: usize, vert: usize) -> [f32; 3] {
                self.mesh.positions[self.mesh.indices[3 * self.faces[face] + vert] as usize]
            }
            fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
                self.mesh.normals[self.mesh.indices[3 * self.faces[face] + vert] as usize]
            }
            fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
                let i = self.mesh.indices[3 * self.faces[face] + vert] as usize;
                let [u, v] = self.mesh.uvs[i];
                // v already runs up for OBJ materials; glTF's runs down.
                if self.flip.get(self.mesh.materials[i] as usize).copied().unwrap_or(false) {
                    [u, v]
                } else {
                    [u, 1.0 - v]
                }
            }
            fn set_tangent(&mut self, tangent: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
                self.out[3 * face + vert] = tangent.map(|t| t.tangent_encoded()).unwrap_or([0.0; 4]);
            }
        }
        let mut geometry = Geometry { mesh: self, faces: &faces, flip: &flip, out: vec![[0.0; 4]; 3 * faces.len()] };
        if let Err(e) = bevy_mikktspace::generate_tangents::<_, bevy_mikktspace::StdOps>(&mut geometry) {
            self.warnings.push(MeshWarning::Tangents {
                message: format!("MikkTSpace failed on {} normal-mapped triangles: {e}", faces.len()),
            });
            return;
        }
        let generated = geometry.out;
        let mut split: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
        let mut claimed: std::collections::HashSet<u32> = std::collections::HashSet::new();
        for (k, &f) in faces.iter().enumerate() {
            for v in 0..3 {
                let old = self.indices[3 * f + v];
                let t = generated[3 * k + v];
                // MikkTSpace's sign is ±1; a zero tangent (no uv gradient)
                // keeps w = 0 so that the rasteriser skips the normal map there.
                let t = if t[0] == 0.0 && t[1] == 0.0 && t[2] == 0.0 { [0.0; 4] } else { t };
                let index = *split.entry((old, t.map(f32::to_bits))).or_insert_with(|| {
                    let i = old as usize;
                    if claimed.insert(old) {
                        // First use: the vertex itself takes the tangent.
                        self.tangents[i] = t;
                        return old;
                    }
                    self.positions.push(self.positions[i]);
                    self.normals.push(self.normals[i]);
                    self.uvs.push(self.uvs[i]);
                    self.materials.push(self.materials[i]);
                    if !self.colors.is_empty() {
                        self.colors.push(self.colors[i]);
                    }
                    self.tangents.push(t);
                    (self.positions.len() - 1) as u32
                });
                self.indices[3 * f + v] = index;
            }
        }
    }

    /// Replaces the normals by smooth ones: at each corner, the normals of
    /// the triangles around the corner's position (vertices are matched by
    /// position, so seams in uv or material do not show), weighted by the
    /// corner angle, counting only triangles whose face normal is within
    /// `crease_degrees` of the corner's own triangle. Faces meeting at a
    /// sharper angle stay flat. Vertices are split where a position needs
    /// more than one normal.
    pub fn compute_normals(&mut self, crease_degrees: f32) {
        let triangles = self.indices.len() / 3;
        let cos_crease = crease_degrees.to_radians().cos();
        let mut face = vec![[0.0f32; 3]; triangles];
        let mut angle = vec![0.0f32; triangles * 3];
        for t in 0..triangles {
            let [a, b, c] = [0, 1, 2].map(|k| self.positions[self.indices[3 * t + k] as usize]);
            face[t] = normalize(cross(sub(b, a), sub(c, a)));
            for (k, (p, q, r)) in [(a, b, c), (b, c, a), (c, a, b)].into_iter().enumerate() {
                let (u, v) = (normalize(sub(q, p)), normalize(sub(r, p)));
                angle[3 * t + k] = dot(u, v).clamp(-1.0, 1.0).acos();
            }
        }
        let key = |p: [f32; 3]| p.map(|x| (x + 0.0).to_bits());
        let mut groups: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
        for (c, &i) in self.indices.iter().enumerate() {
            groups.entry(key(self.positions[i as usize])).or_default().push(c as u32);
        }
        let mut corner_normal = vec![[0.0f32; 3]; self.indices.len()];
        for corners in groups.values() {
            for &c in corners {
                let own = face[c as usize / 3];
                let mut sum = [0.0f32; 3];
                for &d in corners {
                    let other = face[d as usize / 3];
                    if dot(own, other) >= cos_crease {
                        let w = angle[d as usize];
                        sum = [sum[0] + w * other[0], sum[1] + w * other[1], sum[2] + w * other[2]];
                    }
                }
                let n = if dot(sum, sum) > 0.0 { normalize(sum) } else { own };
                corner_normal[c as usize] = if dot(n, n) > 0.0 { n } else { [0.0, 1.0, 0.0] };
            }
        }
        // Rebuild the vertices: one per (old vertex, normal). Tangents
        // depend on the normals, so they are made again afterwards.
        let had_tangents = self.tangents.iter().any(|t| t[3] != 0.0);
        let mut map: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
        let mut out = Mesh {
            material_names: std::mem::take(&mut self.material_names),
            material_params: std::mem::take(&mut self.material_params),
            warnings: std::mem::take(&mut self.warnings),
            ..Default::default()
        };
        for (c, &i) in self.indices.iter().enumerate() {
            let n = corner_normal[c];
            let index = *map.entry((i, n.map(f32::to_bits))).or_insert_with(|| {
                let i = i as usize;
                out.positions.push(self.positions[i]);
                out.normals.push(n);
                out.uvs.push(self.uvs[i]);
                out.materials.push(self.materials[i]);
                if let Some(color) = self.colors.get(i) {
                    out.colors.push(*color);
                }
                (out.positions.len() - 1) as u32
            });
            out.indices.push(index);
        }
        *self = out;
        if had_tangents {
            self.ensure_tangents();
        }
    }
}

/// Appends `src` (per vertex of `src_len` vertices, or empty) to `dst`
/// (per vertex of `dst_len`, or empty), filling in `default` where one side
/// has the attribute and the other does not; both empty stays empty.
fn extend_optional<T: Copy>(dst: &mut Vec<T>, dst_len: usize, src: &[T], src_len: usize, default: T) {
    if dst.is_empty() && src.is_empty() {
        return;
    }
    if dst.is_empty() {
        dst.resize(dst_len, default);
    }
    if src.is_empty() {
        dst.extend(std::iter::repeat_n(default, src_len));
    } else {
        dst.extend_from_slice(src);
    }
}

/// Removes the triangles without area (two corners at the same position,
/// or three on a line: a cross product of exactly zero), which cover no
/// pixel; returns how many.
fn drop_degenerate_triangles(positions: &[[f32; 3]], indices: &mut Vec<u32>) -> usize {
    let before = indices.len() / 3;
    let mut kept = Vec::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
        if cross(sub(b, a), sub(c, a)) != [0.0; 3] {
            kept.extend_from_slice(t);
        }
    }
    *indices = kept;
    before - indices.len() / 3
}

/// Reads the OBJ's material libraries (relative to `dir`) and gives each of
/// `mesh.material_names` its parameters, reporting what cannot be used.
fn read_mtl_materials(mesh: &mut Mesh, dir: &Path, libraries: &[String]) {
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
        let (material, unsupported) = Material::from_mtl(m, |key, file| {
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

/// A glTF material's parameters, its textures decoded (once per image, in
/// `images`) from GLB chunks, data URIs or files next to the model.
fn gltf_material(
    material: &gltf::Material,
    path: &Path,
    buffers: &[Vec<u8>],
    images: &mut HashMap<usize, Option<Arc<TextureImage>>>,
    warnings: &mut Vec<MeshWarning>,
) -> Material {
    let name =
        material.name().map(str::to_string).unwrap_or_else(|| format!("material{}", material.index().unwrap_or(0)));
    let pbr = material.pbr_metallic_roughness();
    let mut out = Material {
        base_color: pbr.base_color_factor(),
        roughness: pbr.roughness_factor(),
        metallic: pbr.metallic_factor(),
        alpha_cutoff: match material.alpha_mode() {
            gltf::material::AlphaMode::Mask => Some(material.alpha_cutoff().unwrap_or(0.5)),
            _ => None,
        },
        ..Material::default()
    };
    if material.alpha_mode() == gltf::material::AlphaMode::Blend {
        warnings.push(MeshWarning::Unsupported {
            material: name.clone(),
            feature: "alpha blending (drawn opaque; alpha is in the albedo channel)".into(),
        });
    }
    let mut texture = |slot: &str, texture: gltf::Texture, tex_coord: u32, out: &mut Material| {
        if tex_coord != 0 {
            warnings.push(MeshWarning::Unsupported {
                material: name.clone(),
                feature: format!("{slot} on texture coordinates {tex_coord} (only TEXCOORD_0 is read)"),
            });
            return None;
        }
        let sampler = texture.sampler();
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
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
fn gltf_image(image: &gltf::Image, path: &Path, buffers: &[Vec<u8>]) -> Result<TextureImage, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
            let bytes =
                data.get(view.offset()..view.offset() + view.length()).ok_or("its buffer view is out of range")?;
            TextureImage::decode(bytes, &format!("image {}", image.index()))
        }
        gltf::image::Source::Uri { uri, .. } => {
            if let Some(rest) = uri.strip_prefix("data:") {
                let (_, data) = rest.split_once(";base64,").ok_or("only base64 data URIs are supported")?;
                let bytes = base64_decode(data).ok_or("invalid base64 data")?;
                TextureImage::decode(&bytes, &format!("image {}", image.index()))
            } else {
                let file = path.parent().unwrap_or(Path::new(".")).join(percent_decode(uri));
                TextureImage::load(&file).map_err(|e| format!("{}: {e}", file.display()))
            }
        }
    }
}

/// Triangulates one polygon (vertex indices in order) by ear clipping in the
/// plane of its Newell normal, appending triangles with the polygon's
/// winding. Falls back to a fan where the polygon is degenerate.
fn triangulate(positions: &[[f32; 3]], polygon: &[u32], out: &mut Vec<u32>) {
    let n = polygon.len();
    if n == 3 {
        out.extend_from_slice(polygon);
        return;
    }
    let fan = |out: &mut Vec<u32>, poly: &[u32]| {
        for k in 1..poly.len() - 1 {
            out.extend_from_slice(&[poly[0], poly[k], poly[k + 1]]);
        }
    };
    // Newell normal, and the two axes of the projection plane.
    let mut normal = [0.0f64; 3];
    for k in 0..n {
        let p = positions[polygon[k] as usize].map(f64::from);
        let q = positions[polygon[(k + 1) % n] as usize].map(f64::from);
        normal[0] += (p[1] - q[1]) * (p[2] + q[2]);
        normal[1] += (p[2] - q[2]) * (p[0] + q[0]);
        normal[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    let drop = (0..3).max_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs())).unwrap_or(2);
    if normal[drop].abs() < 1e-20 {
        fan(out, polygon);
        return;
    }
    let (ax, ay) = match drop {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    // With these axes the projected polygon is counter-clockwise exactly
    // when normal[drop] > 0; `sign` makes the convexity test orientation-free.
    let sign = normal[drop].signum();
    let pt = |i: u32| {
        let p = positions[i as usize];
        [p[ax] as f64, p[ay] as f64]
    };
    let cross2 = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut ring: Vec<u32> = polygon.to_vec();
    while ring.len() > 3 {
        let m = ring.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
            let (a, b, c) = (pt(ia), pt(ib), pt(ic));
            if sign * cross2(a, b, c) <= 0.0 {
                continue; // reflex or degenerate corner
            }
            let blocked = ring.iter().any(|&j| {
                let p = pt(j);
                if p == a || p == b || p == c {
                    return false;
                }
                sign * cross2(a, b, p) >= 0.0 && sign * cross2(b, c, p) >= 0.0 && sign * cross2(c, a, p) >= 0.0
            });
            if !blocked {
                out.extend_from_slice(&[ia, ib, ic]);
                ring.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            // Self-intersecting or numerically degenerate remainder.
            fan(out, &ring);
            return;
        }
    }
    out.extend_from_slice(&ring);
}

/// A glTF primitive's indices as a triangle list.
fn triangle_list(mode: gltf::mesh::Mode, raw: &[u32]) -> Vec<u32> {
    match mode {
        gltf::mesh::Mode::TriangleStrip => (2..raw.len())
            .flat_map(|k| if k % 2 == 0 { [raw[k - 2], raw[k - 1], raw[k]] } else { [raw[k - 1], raw[k - 2], raw[k]] })
            .collect(),
        gltf::mesh::Mode::TriangleFan => (2..raw.len()).flat_map(|k| [raw[0], raw[k - 1], raw[k]]).collect(),
        _ => raw[..raw.len() / 3 * 3].to_vec(),
    }
}

/// The Sponza path the application chose ([`set_sponza_path`]).
static SPONZA_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Tells [`sponza_path`] where the Dabrovic Sponza OBJ file is. The library
/// does not go looking for it: the command-line tool and the tests find it
/// in cargo's registry ([`find_sponza_in_cargo_home`]) and say so here.
pub fn set_sponza_path(path: PathBuf) {
    *SPONZA_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The path of the Dabrovic Sponza OBJ file: the one given to
/// [`set_sponza_path`], else `$MRSL_SPONZA`.
pub fn sponza_path() -> Result<PathBuf, MeshError> {
    let mut searched = vec![];
    let chosen = SPONZA_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for candidate in chosen.into_iter().chain(std::env::var_os("MRSL_SPONZA").map(PathBuf::from)) {
        if candidate.is_file() {
            return Ok(candidate);
        }
        searched.push(candidate);
    }
    Err(MeshError::SponzaNotFound { searched })
}

/// Where cargo unpacked `obj-rs` 0.7.4's Sponza under `cargo_home`
/// (`$CARGO_HOME`, by default `~/.cargo`): `registry/src/*/obj-rs-0.7.4/tests/fixtures/sponza.obj`.
/// Building this crate makes cargo download and unpack that package.
pub fn find_sponza_in_cargo_home(cargo_home: &Path) -> Option<PathBuf> {
    let mut registries: Vec<PathBuf> = std::fs::read_dir(cargo_home.join("registry").join("src"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    registries.sort();
    registries
        .into_iter()
        .map(|r| r.join(format!("{SPONZA_PACKAGE}-{SPONZA_VERSION}")).join(SPONZA_IN_PACKAGE))
        .find(|p| p.is_file())
}

/// The Sponza mesh, loaded once per process and shared.
pub fn sponza_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(mesh) = guard.as_ref() {
        return Ok(mesh.clone());
    }
    let mesh = Arc::new(Mesh::sponza()?);
    *guard = Some(mesh.clone());
    Ok(mesh)
}

/// The dungeon path the application chose ([`set_dungeon_path`]).
static DUNGEON_PATH: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Where the dungeon level lies in Debian's `castle-game-engine-doc` package.
const DUNGEON_IN_PACKAGE: &str =
    "/usr/share/doc/castle-game-engine-doc/examples/third_person_navigation/data/level/level-dungeon.gltf";

/// Tells [`dungeon_path`] where the dungeon's `level-dungeon.gltf` is.
pub fn set_dungeon_path(path: PathBuf) {
    *DUNGEON_PATH.lock().unwrap_or_else(|e| e.into_inner()) = Some(path);
}

/// The places [`dungeon_path`] looks, in order: the path given to
/// [`set_dungeon_path`], `$MRSL_DUNGEON`, where `scripts/fetch-dungeon.sh`
/// puts it (`$XDG_DATA_HOME/mrsl/castle-dungeon/level-dungeon.gltf`,
/// `XDG_DATA_HOME` defaulting to `~/.local/share`), and where Debian's
/// package installs it.
pub fn dungeon_candidates() -> Vec<PathBuf> {
    let chosen = DUNGEON_PATH.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let data_home = std::env::var_os("XDG_DATA_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share")));
    chosen
        .into_iter()
        .chain(std::env::var_os("MRSL_DUNGEON").map(PathBuf::from))
        .chain(data_home.map(|d| d.join("mrsl/castle-dungeon/level-dungeon.gltf")))
        .chain(std::iter::once(PathBuf::from(DUNGEON_IN_PACKAGE)))
        .collect()
}

/// The path of the dungeon level: the first of [`dungeon_candidates`] that exists.
pub fn dungeon_path() -> Result<PathBuf, MeshError> {
    let searched = dungeon_candidates();
    searched.iter().find(|p| p.is_file()).cloned().ok_or(MeshError::DungeonNotFound { searched })
}

/// The dungeon mesh with its materials and textures, loaded once per process and shared.
pub fn dungeon_shared() -> Result<Arc<Mesh>, MeshError> {
    static CACHE: Mutex<Option<Arc<Mesh>>> = Mutex::new(None);
    let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(mesh) = guard.as_ref() {
        return Ok(mesh.clone());
    }
    let mesh = Arc::new(Mesh::load_gltf(dungeon_path()?)?);
    *guard = Some(mesh.clone());
    Ok(mesh)
}

fn base64_decode(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let symbols: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace() && *c != b'=').collect();
    let mut out = Vec::with_capacity(symbols.len() * 3 / 4);
    for chunk in symbols.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * k);
        }
        let bytes = [(acc >> 16) as u8, (acc >> 8) as u8, acc as u8];
        match chunk.len() {
            4 => out.extend_from_slice(&bytes),
            3 => out.extend_from_slice(&bytes[..2]),
            2 => out.push(bytes[0]),
            _ => return None,
        }
    }
    Some(out)
}

fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = bytes.get(k + 1..k + 3).and_then(|h| std::str::from_utf8(h).ok());
        if let (b'%', Some(Ok(v))) = (bytes[k], hex.map(|h| u8::from_str_radix(h, 16))) {
            out.push(v);
            k += 3;
            continue;
        }
        out.push(bytes[k]);
        k += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn mat4_mul(a: [[f32; 4]; 4], b: [[f32; 4]; 4]) -> [[f32; 4]; 4] {
    // Column-major: (a * b)[col][row] = sum_k a[k][row] * b[col][k].
    std::array::from_fn(|col| std::array::from_fn(|row| (0..4).map(|k| a[k][row] * b[col][k]).sum()))
}

fn transform_point(m: [[f32; 4]; 4], p: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|row| m[0][row] * p[0] + m[1][row] * p[1] + m[2][row] * p[2] + m[3][row])
}

fn transform_vector(m: [[f32; 4]; 4], v: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|row| m[0][row] * v[0] + m[1][row] * v[1] + m[2][row] * v[2])
}

fn det3(m: [[f32; 4]; 4]) -> f32 {
    dot([m[0][0], m[0][1], m[0][2]], cross([m[1][0], m[1][1], m[1][2]], [m[2][0], m[2][1], m[2][2]]))
}

/// The matrix that transforms normals (the inverse transpose of the upper
/// 3x3, up to a positive factor), as rows.
fn normal_matrix(m: [[f32; 4]; 4]) -> [[f32; 3]; 3] {
    let c = |k: usize| [m[k][0], m[k][1], m[k][2]];
    // Rows of the cofactor matrix: the cross products of the columns.
    let rows = [cross(c(1), c(2)), cross(c(2), c(0)), cross(c(0), c(1))];
    let s = if det3(m) < 0.0 { -1.0 } else { 1.0 };
    // n' = sum_k n[k] * rows[k] (the cofactor matrix applied to n).
    std::array::from_fn(|row| std::array::from_fn(|k| s * rows[k][row]))
}

fn mat3_mul(m: [[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|row| dot(m[row], v))
}

pub(crate) fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub(crate) fn length(a: [f32; 3]) -> f32 {
    dot(a, a).sqrt()
}

/// `a` scaled to unit length, or zero for a zero vector.
pub(crate) fn normalize(a: [f32; 3]) -> [f32; 3] {
    let l = length(a);
    if l > 0.0 { [a[0] / l, a[1] / l, a[2] / l] } else { [0.0; 3] }
}
