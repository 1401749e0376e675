//! Triangle meshes for the G-buffer rasteriser, one concern a module:
//! loaders for Wavefront OBJ ([`obj`], through `tobj`, with its MTL
//! materials in [`mtl`]), glTF 2.0 / GLB ([`gltf`], through the `gltf`
//! crate) and AC3D text, TORCS's `.acc` included ([`ac3d`], hand-written), smooth normals with a crease angle for models that have none
//! ([`normals`]) and MikkTSpace tangents for normal maps ([`tangents`]).
//! The test models (the Dabrovic Sponza, the dungeon) are found and shared
//! by [`crate::fixtures`].
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

mod ac3d;
mod gltf;
mod mtl;
mod normals;
mod obj;
mod tangents;

use std::path::{Path, PathBuf};

use crate::material::Material;
use glam::Vec3;

pub use ac3d::{SURF_DOUBLE_SIDED, SURF_SHADED, TORCS_ALPHA_CUTOFF};

/// Default crease angle (degrees) for computed normals: faces meeting at a
/// sharper angle keep their own normal, so boxes stay boxes while Sponza's
/// columns and arches shade smoothly.
pub const DEFAULT_CREASE_ANGLE: f32 = 45.0;

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
    #[error("{}:{line}: not a valid AC3D file: {message}", path.display())]
    Ac3d { path: PathBuf, line: usize, message: String },
    #[error("{}: unsupported mesh format (expected .obj, .gltf, .glb, .ac or .acc)", path.display())]
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
    #[error(
        "the outdoor scene (forza.acc, TORCS's \"forza\" track from Debian's torcs-data package) was not found; \
         run scripts/fetch-outdoor.sh in the workspace, or set MRSL_OUTDOOR to the file. Looked at: {}",
        searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    OutdoorNotFound { searched: Vec<PathBuf> },
    #[error(
        "the small scene (link6.obj, the Franka Panda arm's link 6 from the PyPI package pybullet) was not found; \
         run scripts/fetch-small.sh in the workspace, or set MRSL_SMALL to the file. Looked at: {}",
        searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    SmallNotFound { searched: Vec<PathBuf> },
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
        (0.5 * (Vec3::from(self.min) + Vec3::from(self.max))).to_array()
    }
    pub fn extent(&self) -> [f32; 3] {
        (Vec3::from(self.max) - Vec3::from(self.min)).to_array()
    }
    /// Length of the diagonal.
    pub fn diagonal(&self) -> f32 {
        Vec3::from(self.extent()).length()
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
    /// Parts of the file that are not triangles (AC3D lines) were left out.
    Skipped { count: usize, what: String },
    /// The file ended before some of the child objects it declares (AC3D
    /// `kids`); the objects before were read.
    MissingObjects { count: usize },
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
            MeshWarning::Skipped { count, what } => write!(f, "{count} {what} left out"),
            MeshWarning::MissingObjects { count } => {
                write!(f, "the file ends before {count} of the child objects it declares; the objects before are kept")
            }
        }
    }
}

impl Mesh {
    /// Loads an `.obj`, `.gltf`, `.glb`, `.ac` or `.acc` file (by extension, case-insensitive).
    pub fn load(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("obj") => Mesh::load_obj(path),
            Some("gltf" | "glb") => Mesh::load_gltf(path),
            Some("ac" | "acc") => Mesh::load_ac3d(path),
            _ => Err(MeshError::UnsupportedFormat { path: path.to_path_buf() }),
        }
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
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(positions[t[k] as usize]));
        if (b - a).cross(c - a) != Vec3::ZERO {
            kept.extend_from_slice(t);
        }
    }
    *indices = kept;
    before - indices.len() / 3
}
