//! Smooth normals with a crease angle, for models that have none (Sponza's
//! OBJ, glTF primitives without `NORMAL`).

use std::collections::HashMap;

use super::Mesh;
use crate::vector::normalize;
use glam::Vec3;

impl Mesh {
    /// Replaces the normals by smooth ones: at each corner, the normals of
    /// the triangles around the corner's position (vertices are matched by
    /// position, so seams in uv or material do not show), weighted by the
    /// corner angle, counting only triangles whose face normal is within
    /// `crease_degrees` of the corner's own triangle. Faces meeting at a
    /// sharper angle stay flat. Vertices are split where a position needs
    /// more than one normal.
    pub fn compute_normals(&mut self, crease_degrees: f32) {
        let corner_normal = self.corner_normals(crease_degrees);
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

    /// The smooth normal of every corner (see [`Mesh::compute_normals`]).
    fn corner_normals(&self, crease_degrees: f32) -> Vec<[f32; 3]> {
        let triangles = self.indices.len() / 3;
        let cos_crease = crease_degrees.to_radians().cos();
        let mut face = vec![Vec3::ZERO; triangles];
        let mut angle = vec![0.0f32; triangles * 3];
        for t in 0..triangles {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(self.positions[self.indices[3 * t + k] as usize]));
            face[t] = normalize((b - a).cross(c - a));
            for (k, (p, q, r)) in [(a, b, c), (b, c, a), (c, a, b)].into_iter().enumerate() {
                let (u, v) = (normalize(q - p), normalize(r - p));
                angle[3 * t + k] = u.dot(v).clamp(-1.0, 1.0).acos();
            }
        }
        // Corners by position; `+ 0.0` makes -0.0 and 0.0 one key.
        let key = |p: [f32; 3]| p.map(|x| (x + 0.0).to_bits());
        let mut groups: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
        for (c, &i) in self.indices.iter().enumerate() {
            groups.entry(key(self.positions[i as usize])).or_default().push(c as u32);
        }
        let mut corner_normal = vec![[0.0f32; 3]; self.indices.len()];
        for corners in groups.values() {
            for &c in corners {
                let own = face[c as usize / 3];
                let mut sum = Vec3::ZERO;
                for &d in corners {
                    let other = face[d as usize / 3];
                    if own.dot(other) >= cos_crease {
                        sum += angle[d as usize] * other;
                    }
                }
                let n = if sum.dot(sum) > 0.0 { normalize(sum) } else { own };
                corner_normal[c as usize] = if n.dot(n) > 0.0 { n.to_array() } else { [0.0, 1.0, 0.0] };
            }
        }
        corner_normal
    }
}
