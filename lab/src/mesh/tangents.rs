//! Tangents for normal-mapped materials, by MikkTSpace (what glTF
//! prescribes for files without tangents), through Bevy's safe port.

use std::collections::{HashMap, HashSet};

use super::{Mesh, MeshWarning};
use crate::material::Material;

impl Mesh {
    /// Gives tangents to the triangles of normal-mapped materials that lack
    /// them, from their positions, normals and texture coordinates.
    /// Vertices are split where corners that share one need different
    /// tangents. Failures become a [`MeshWarning::Tangents`].
    pub fn ensure_tangents(&mut self) {
        let faces = self.faces_without_tangents();
        if faces.is_empty() {
            return;
        }
        if self.tangents.is_empty() {
            self.tangents = vec![[0.0; 4]; self.positions.len()];
        }
        // MikkTSpace is given texture coordinates whose second axis runs up
        // the image (OpenGL's convention, which glTF's normal maps follow:
        // +Y is up), so the bitangent points up the texture.
        let flip: Vec<bool> = self.material_params.iter().map(|m| m.flip_v).collect();
        let mut geometry = Geometry { mesh: self, faces: &faces, flip: &flip, out: vec![[0.0; 4]; 3 * faces.len()] };
        if let Err(e) = bevy_mikktspace::generate_tangents::<_, bevy_mikktspace::StdOps>(&mut geometry) {
            self.warnings.push(MeshWarning::Tangents {
                message: format!("MikkTSpace failed on {} normal-mapped triangles: {e}", faces.len()),
            });
            return;
        }
        let generated = geometry.out;
        self.set_tangents(&faces, &generated);
    }

    /// The triangles of normal-mapped materials with a corner that has no tangent (w = 0).
    fn faces_without_tangents(&self) -> Vec<usize> {
        let mapped: Vec<bool> = (0..self.material_names.len().max(self.material_params.len()))
            .map(|id| self.material_params.get(id).is_some_and(Material::has_normal_map))
            .collect();
        let needs = |t: &[u32]| {
            let id = self.materials[t[0] as usize] as usize;
            mapped.get(id).copied().unwrap_or(false)
                && t.iter().any(|&i| self.tangents.get(i as usize).is_none_or(|v| v[3] == 0.0))
        };
        (0..self.indices.len() / 3).filter(|&f| needs(&self.indices[3 * f..3 * f + 3])).collect()
    }

    /// Gives the corners of `faces` the tangents MikkTSpace `generated` (three
    /// per face): a vertex takes the first tangent asked of it, and is
    /// copied for each other one.
    fn set_tangents(&mut self, faces: &[usize], generated: &[[f32; 4]]) {
        let mut split: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
        let mut claimed: HashSet<u32> = HashSet::new();
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
}

/// The triangles MikkTSpace is run on, and where it writes their tangents.
struct Geometry<'a> {
    mesh: &'a Mesh,
    faces: &'a [usize],
    /// Per material: whether its texture coordinates' v already runs up.
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
        if self.flip.get(self.mesh.materials[i] as usize).copied().unwrap_or(false) { [u, v] } else { [u, 1.0 - v] }
    }
    fn set_tangent(&mut self, tangent: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
        self.out[3 * face + vert] = tangent.map(|t| t.tangent_encoded()).unwrap_or([0.0; 4]);
    }
}
