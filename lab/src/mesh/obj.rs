//! Wavefront OBJ files, read through `tobj` and single-indexed and
//! triangulated here: tobj's single-index mode misaligns texture
//! coordinates when some faces have `vt` and others do not (Sponza has
//! both), and its triangulation is a fan, which fills Sponza's concave
//! polygons (up to 78 corners) wrongly.

use std::collections::HashMap;
use std::io::{BufRead, Read};
use std::path::Path;

use super::{DEFAULT_CREASE_ANGLE, Mesh, MeshError, MeshWarning, drop_degenerate_triangles};
use crate::vector::normalize;
use glam::Vec3;

/// The name of the material library put in front of the file (see [`read_models`]).
const SYNTHETIC: &str = "<mrsl usemtl names>";

/// What a first pass over the file's lines finds.
struct Scan {
    /// `usemtl` names in the order of first use.
    names: Vec<String>,
    /// `mtllib` files, as written.
    libraries: Vec<String>,
    /// Faces of one or two corners: tobj reads them as points or lines and
    /// drops them unseen, so they are counted here.
    degenerate: usize,
}

impl Mesh {
    /// Loads a Wavefront OBJ file: polygons are triangulated by ear clipping,
    /// `usemtl` names become material ids in the order of first use, with
    /// the parameters of the `mtllib` libraries' materials of those names
    /// (the default material where a library or an entry is missing), and
    /// objects without normals get smooth normals with
    /// [`DEFAULT_CREASE_ANGLE`]. Faces before any `usemtl` get a material
    /// named `default`. Objects without texture coordinates (and objects
    /// whose corners all share one) get uv (0, 0).
    pub fn load_obj(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let text = std::fs::read(path).map_err(|source| MeshError::Io { path: path.to_path_buf(), source })?;
        let obj_error = |message: String| MeshError::Obj { path: path.to_path_buf(), message };
        let Scan { names, libraries, mut degenerate } = scan(&text).map_err(obj_error)?;
        let models = read_models(&text, &names).map_err(obj_error)?;

        let mut material_names = names;
        let mut default_material: Option<u32> = None;
        let mut pieces: Vec<(Mesh, bool)> = vec![];
        for model in &models {
            if model.mesh.indices.is_empty() {
                continue;
            }
            let material = match model.mesh.material_id {
                Some(id) => id as u32,
                None => *default_material.get_or_insert_with(|| {
                    material_names.push("default".into());
                    material_names.len() as u32 - 1
                }),
            };
            let (piece, has_normals, dropped) = single_indexed(&model.mesh, material);
            degenerate += dropped;
            pieces.push((piece, has_normals));
        }
        let mut mesh = Mesh { material_names, ..Default::default() };
        if degenerate > 0 {
            mesh.warnings.push(MeshWarning::DegenerateFaces { count: degenerate });
        }
        super::mtl::read_materials(&mut mesh, path.parent().unwrap_or(Path::new(".")), &libraries);
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
}

/// The material names, libraries and short faces of the file's lines.
fn scan(text: &[u8]) -> Result<Scan, String> {
    let mut scan = Scan { names: vec![], libraries: vec![], degenerate: 0 };
    for line in text.lines() {
        let line = line.map_err(|e| e.to_string())?;
        if let Some(rest) = line.trim_start().strip_prefix("usemtl") {
            let name = rest.trim();
            if !name.is_empty() && rest.starts_with(char::is_whitespace) && !scan.names.iter().any(|n| n == name) {
                scan.names.push(name.to_string());
            }
        } else if let Some(rest) = line.trim_start().strip_prefix("mtllib")
            && rest.starts_with(char::is_whitespace)
        {
            scan.libraries.push(rest.trim().to_string());
        } else if let Some(rest) = line.trim_start().strip_prefix("f ")
            && rest.split_whitespace().count() < 3
        {
            scan.degenerate += 1;
        }
    }
    Ok(scan)
}

/// The file's models as tobj reads them, with material ids in the order of
/// `names`: tobj only numbers materials it found in an .mtl file, so a
/// synthetic material library with exactly these names is put in front of
/// the file (the real libraries are read by [`super::mtl`]).
fn read_models(text: &[u8], names: &[String]) -> Result<Vec<tobj::Model>, String> {
    let header = format!("mtllib {SYNTHETIC}\n");
    let mut reader = std::io::BufReader::new(header.as_bytes().chain(text));
    let options =
        tobj::LoadOptions { single_index: false, triangulate: false, ignore_points: true, ignore_lines: true };
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| {
        if mtl == Path::new(SYNTHETIC) {
            let materials: Vec<tobj::Material> =
                names.iter().map(|n| tobj::Material { name: n.clone(), ..Default::default() }).collect();
            Ok((materials, names.iter().enumerate().map(|(i, n)| (n.clone(), i)).collect()))
        } else {
            Err(tobj::LoadError::OpenFileFailed)
        }
    })
    .map_err(|e| e.to_string())?;
    Ok(models)
}

/// One tobj model as a mesh of `material`: one vertex per (position, uv,
/// normal) of its corners, its polygons triangulated; whether it has
/// normals, and how many faces were degenerate.
fn single_indexed(m: &tobj::Mesh, material: u32) -> (Mesh, bool, usize) {
    let corners = m.indices.len();
    // For corners without `vt`, tobj repeats the previous corner's (or the
    // file's first) texture coordinate, so an object whose faces have none
    // comes out with a single coordinate everywhere: such objects get uv (0,
    // 0), which interpolates exactly (a constant like 1.0 comes out a
    // rounding error either side of it, which makes `floor(uv * n)` flicker
    // between two values).
    let has_uv = m.texcoord_indices.len() == corners && m.texcoords.len() > 2;
    let has_normals = m.normal_indices.len() == corners && !m.normals.is_empty();
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
                normalize(Vec3::new(m.normals[ni], m.normals[ni + 1], m.normals[ni + 2])).to_array()
            } else {
                [0.0, 0.0, 0.0]
            });
            piece.materials.push(material);
            (piece.positions.len() - 1) as u32
        });
        corner_vertex.push(index);
    }
    let arities: Vec<u32> = if m.face_arities.is_empty() { vec![3; corners / 3] } else { m.face_arities.clone() };
    let mut degenerate = 0;
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
    (piece, has_normals, degenerate)
}

/// Triangulates one polygon (vertex indices in order) by ear clipping in the
/// plane of its Newell normal, appending triangles with the polygon's
/// winding. Falls back to a fan where the polygon is degenerate.
pub(super) fn triangulate(positions: &[[f32; 3]], polygon: &[u32], out: &mut Vec<u32>) {
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
