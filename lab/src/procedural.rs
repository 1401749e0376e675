//! The `generated` scene: a city made here, with no file to fetch and the
//! same triangles on every run and machine — blocks of box towers and
//! spheres on a ground plane, at the scale of kilometres (a hundred times
//! Sponza's), under open sky. See docs/scenes.md, "Generated".
//!
//! The ground is a square [`GROUND`] metres wide at y = 0; streets run
//! every [`BLOCK`] metres along x and z over the middle [`CITY`] metres,
//! and each block holds up to three towers (boxes, 12 to 240 m tall, the
//! tallest near the centre) or, on some blocks, a sphere (a dome or a
//! tank, 15 to 55 m in radius). Every number comes from a fixed hash of the
//! block's coordinates, not from a random-number generator.

use std::sync::Arc;

use crate::image_texture::TextureImage;
use crate::material::Material;
use crate::mesh::Mesh;
use glam::Vec3;

/// Width of the ground square, metres.
pub const GROUND: f32 = 4000.0;
/// Width of the part with buildings, metres.
pub const CITY: f32 = 3000.0;
/// Street spacing, metres (one block and its street).
pub const BLOCK: f32 = 120.0;
/// Width of a street, metres.
const STREET: f32 = 24.0;

/// Material ids (see [`materials`]).
const GROUND_MATERIAL: u32 = 0;
const FACADES: [u32; 4] = [1, 2, 3, 4];
const SPHERES: [u32; 3] = [5, 6, 7];

/// A small deterministic hash of a block and a slot, in [0, 1).
fn hash(i: i32, j: i32, slot: u32) -> f32 {
    crate::hash::hash01(
        (i as u32).wrapping_mul(73_856_093) ^ (j as u32).wrapping_mul(19_349_663) ^ slot.wrapping_mul(83_492_791),
    )
}

/// The generated city (see the module documentation): 8 materials, the
/// ground and the facades textured (images made here).
pub fn city() -> Mesh {
    let mut mesh = Mesh { material_names: material_names(), material_params: materials(), ..Default::default() };
    ground(&mut mesh);
    let blocks = (CITY / BLOCK) as i32;
    for i in 0..blocks {
        for j in 0..blocks {
            block(&mut mesh, i, j, blocks);
        }
    }
    mesh
}

fn material_names() -> Vec<String> {
    [
        "ground",
        "facade stone",
        "facade glass",
        "facade brick",
        "facade concrete",
        "sphere gold",
        "sphere red",
        "sphere white",
    ]
    .map(String::from)
    .to_vec()
}

/// The materials: a textured ground (streets and pavements), four facades
/// sharing a window texture under different tints, roughness and
/// metalness, and three spheres: a gold metal, a glossy red, a rough white.
fn materials() -> Vec<Material> {
    let windows = Arc::new(window_texture());
    let facade = |tint: [f32; 3], roughness: f32, metallic: f32| Material {
        base_color: [tint[0], tint[1], tint[2], 1.0],
        roughness,
        metallic,
        base_color_texture: Some(windows.clone()),
        flip_v: true,
        ..Material::default()
    };
    let plain = |color: [f32; 3], roughness: f32, metallic: f32| Material {
        base_color: [color[0], color[1], color[2], 1.0],
        roughness,
        metallic,
        ..Material::default()
    };
    vec![
        Material { base_color_texture: Some(Arc::new(ground_texture())), roughness: 0.9, ..plain([1.0; 3], 0.9, 0.0) },
        facade([0.95, 0.9, 0.8], 0.7, 0.0),
        facade([0.55, 0.7, 0.85], 0.2, 0.6),
        facade([0.85, 0.5, 0.4], 0.8, 0.0),
        facade([0.75, 0.75, 0.75], 0.6, 0.0),
        plain([1.0, 0.77, 0.34], 0.3, 1.0),
        plain([0.8, 0.1, 0.08], 0.25, 0.0),
        plain([0.9, 0.9, 0.88], 0.85, 0.0),
    ]
}

/// 64 x 64 texels, sRGB: one block of ground, its streets dark asphalt
/// with a dashed centre line, the pavement inside a light concrete.
fn ground_texture() -> TextureImage {
    let n = 64u32;
    let street = (STREET / BLOCK * n as f32 / 2.0).round() as u32;
    let rgba = (0..n * n)
        .flat_map(|k| {
            let (x, y) = (k % n, k / n);
            let edge = |c: u32| c < street || c >= n - street;
            let on_line = |c: u32, along: u32| c == 0 && (along / 4).is_multiple_of(2);
            if on_line(x, y) || on_line(y, x) {
                [230, 220, 180, 255]
            } else if edge(x) || edge(y) {
                [60, 60, 64, 255]
            } else {
                let noise = (crate::hash::hash01(k) * 24.0) as u8;
                [130 + noise, 126 + noise, 118 + noise, 255]
            }
        })
        .collect();
    TextureImage { width: n, height: n, rgba, source: "generated ground".into() }
}

/// 32 x 32 texels, sRGB: one storey's bay of a facade, a light wall around
/// a dark window (the texture repeats every 6 m across and 4 m up).
fn window_texture() -> TextureImage {
    let n = 32u32;
    let rgba = (0..n * n)
        .flat_map(|k| {
            let (x, y) = (k % n, k / n);
            if (6..26).contains(&x) && (8..26).contains(&y) {
                let shade = 40 + (y - 8) * 3;
                [shade as u8, (shade + 10) as u8, (shade + 30) as u8, 255]
            } else {
                [170, 167, 160, 255]
            }
        })
        .collect();
    TextureImage { width: n, height: n, rgba, source: "generated facade".into() }
}

/// The ground: a grid of 16 x 16 squares at y = 0, normal +y, uv one unit per block.
fn ground(mesh: &mut Mesh) {
    let n = 16;
    let step = GROUND / n as f32;
    let base = mesh.positions.len() as u32;
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (-GROUND / 2.0 + i as f32 * step, -GROUND / 2.0 + j as f32 * step);
            mesh.positions.push([x, 0.0, z]);
            mesh.normals.push([0.0, 1.0, 0.0]);
            mesh.uvs.push([(x + CITY / 2.0) / BLOCK, (z + CITY / 2.0) / BLOCK]);
            mesh.materials.push(GROUND_MATERIAL);
        }
    }
    let row = n as u32 + 1;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = base + j * row + i;
            // Counter-clockwise seen from above (+y).
            mesh.indices.extend([a, a + row, a + 1, a + 1, a + row, a + row + 1]);
        }
    }
}

/// Block (i, j) of `blocks` x `blocks`: a sphere on one block in nine,
/// else one to three towers, taller towards the city's centre.
fn block(mesh: &mut Mesh, i: i32, j: i32, blocks: i32) {
    let x0 = -CITY / 2.0 + i as f32 * BLOCK + STREET / 2.0;
    let z0 = -CITY / 2.0 + j as f32 * BLOCK + STREET / 2.0;
    let inner = BLOCK - STREET;
    let centre = (blocks as f32 - 1.0) / 2.0;
    let from_centre = ((i as f32 - centre).hypot(j as f32 - centre) / centre).min(1.0);
    if hash(i, j, 0) < 0.11 {
        // A ball resting on the ground, or a dome (its upper half).
        let radius = 15.0 + 40.0 * hash(i, j, 1);
        let dome = hash(i, j, 2) < 0.5;
        let material = SPHERES[(hash(i, j, 3) * 3.0) as usize % 3];
        let lift = if dome { 0.0 } else { radius };
        sphere(mesh, Vec3::new(x0 + inner / 2.0, lift, z0 + inner / 2.0), radius, dome, material);
        return;
    }
    let towers = 1 + (hash(i, j, 4) * 3.0) as u32;
    for t in 0..towers {
        // Split the block along x into `towers` lots, each with a tower set back.
        let lot = inner / towers as f32;
        let setback = 3.0 + 8.0 * hash(i, j, 10 + t);
        let depth = inner * (0.5 + 0.45 * hash(i, j, 20 + t));
        let tall = 12.0 + 228.0 * (1.0 - from_centre).powi(2) * hash(i, j, 30 + t) + 20.0 * hash(i, j, 40 + t);
        let min = Vec3::new(x0 + t as f32 * lot + setback, 0.0, z0 + setback);
        let max = Vec3::new(x0 + (t + 1) as f32 * lot - setback, tall, z0 + setback + depth);
        let material = FACADES[(hash(i, j, 50 + t) * 4.0) as usize % 4];
        tower(mesh, min, max, material);
    }
}

/// A box from `min` to `max` without its bottom face: flat normals, the
/// walls' uv in facade bays (6 m across, 4 m up), the roof's (0.5, 0.5)
/// (a dark window texel of the facade texture: tar).
fn tower(mesh: &mut Mesh, min: Vec3, max: Vec3, material: u32) {
    let (bay, storey) = (6.0, 4.0);
    // Each face: its normal, the corner it starts at, and its two edges (u then v).
    let size = max - min;
    let faces = [
        (Vec3::Z, Vec3::new(min.x, min.y, max.z), Vec3::X * size.x, Vec3::Y * size.y),
        (Vec3::NEG_Z, Vec3::new(max.x, min.y, min.z), Vec3::NEG_X * size.x, Vec3::Y * size.y),
        (Vec3::X, Vec3::new(max.x, min.y, max.z), Vec3::NEG_Z * size.z, Vec3::Y * size.y),
        (Vec3::NEG_X, Vec3::new(min.x, min.y, min.z), Vec3::Z * size.z, Vec3::Y * size.y),
        (Vec3::Y, Vec3::new(min.x, max.y, max.z), Vec3::X * size.x, Vec3::NEG_Z * size.z),
    ];
    for (k, (normal, corner, u, v)) in faces.into_iter().enumerate() {
        let roof = k == 4;
        let base = mesh.positions.len() as u32;
        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            mesh.positions.push((corner + a * u + b * v).to_array());
            mesh.normals.push(normal.to_array());
            mesh.uvs.push(if roof { [0.5, 0.5] } else { [a * u.length() / bay, b * v.length() / storey] });
            mesh.materials.push(material);
        }
        mesh.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
}

/// A sphere of 32 segments and 16 rings (its upper 8 for a dome): smooth
/// normals, uv by longitude and latitude.
fn sphere(mesh: &mut Mesh, centre: Vec3, radius: f32, dome: bool, material: u32) {
    let segments = 32u32;
    let rings = if dome { 8 } else { 16 };
    let base = mesh.positions.len() as u32;
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / 16.0;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            // The equator exactly at the centre's height (a dome's rim on the ground).
            let y = if 2 * r == 16 { 0.0 } else { theta.cos() };
            let n = Vec3::new(theta.sin() * phi.cos(), y, theta.sin() * phi.sin());
            mesh.positions.push((centre + radius * n).to_array());
            mesh.normals.push(n.to_array());
            mesh.uvs.push([s as f32 / segments as f32, r as f32 / 16.0]);
            mesh.materials.push(material);
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = base + r * row + s;
            // Counter-clockwise seen from outside; the poles' slivers have no area.
            if r > 0 {
                mesh.indices.extend([a, a + 1, a + row]);
            }
            if r + 1 < 16 {
                mesh.indices.extend([a + 1, a + row + 1, a + row]);
            }
        }
    }
}
