//! A real scene: the demo program over the rasterised Dabrovic Sponza in
//! every mode, and the pieces that make it (mesh loaders, the rasteriser,
//! scene files) checked on small inputs with known answers.

use crate::{Output, adaptive_modes, compile, psnr_of as psnr, render_color};
use mrsl_lab::camera::Camera;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::mesh::{Mesh, MeshError};
use mrsl_lab::raster::{self, RasterError};
use mrsl_lab::scene::{BACKGROUND, ChannelData, GBuffer, Scene};
use mrsl_lab::scene_file::{MeshSource, SceneFile, SceneFileError, UniformValue};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::path::PathBuf;

/// A cheap program with world-unit keys (once the demo shader; see the file).
const DEMO: &str = include_str!("data/phong.mrsl");
const SIZE: (u32, u32) = (192, 108);

/// Runs `program` over G-buffer textures already on the device (what the
/// rasteriser returns), setting `camera_pos` where given.
fn shade(
    gpu: &Gpu,
    program: &mrsl::Program,
    channels: &[(String, wgpu::Texture)],
    mode: Mode,
    camera_pos: Option<[f32; 3]>,
) -> Output {
    let size = (channels[0].1.width(), channels[0].1.height());
    let mut shader = Shader::new(&gpu.device, program).unwrap();
    if let Some(eye) = camera_pos {
        shader.set_uniform("camera_pos", &eye.map(f64::from)).unwrap();
    }
    let color = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let mut bindings = Bindings { size, ..Default::default() };
    for (name, texture) in channels {
        bindings.channels.insert(name.clone(), texture);
    }
    bindings.outputs.insert("color".into(), &color);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(mode)).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let stats = shader.read_stats(&gpu.device).unwrap();
    Output { pixels: gpu.read_rgba32f(&color).unwrap(), stats, width: size.0 }
}

/// The Phong test program (`data/phong.mrsl`) over Sponza at 192x108, from the scene's camera.
/// Measured on lavapipe (llvmpipe, Mesa 22.3): coarse2x2 56.4 dB and
/// coarse4x4 56.4 dB against the reference, at shaded fractions 0.819 and
/// 0.814. (At this size most of Sponza's blocks straddle a silhouette or a
/// crease. Before the fine kernel resampled the corners on a pixel's side
/// of an edge, it refined every such block: 57.2 and 60.5 dB at 0.885 and
/// 0.906.) The bars are 3 dB below the measurements: the refine
/// decisions compare derivatives and keys with thresholds, so another
/// driver's rounding can flip a few blocks; the 3 dB leave room for that.
/// Blending across silhouettes costs far more: the same program without the
/// geometric keys (with `@key` on `material`, which no coarse effect reads)
/// measured 45.4 dB (2x2) and 45.0 dB (4x4), under both bars.
pub fn sponza_coarse_modes_stay_close_to_the_reference(gpu: &Gpu) {
    let program = compile(DEMO);
    let channels = Scene::Sponza.textures_on(gpu, SIZE.0, SIZE.1).unwrap();
    let eye = Scene::sponza_camera().eye;
    let pixels = (SIZE.0 * SIZE.1) as u64;

    let reference = shade(gpu, &program, &channels, Mode::Reference, Some(eye));
    assert_eq!(reference.stats.shaded_fraction, 1.0);
    assert_eq!(reference.stats.coarse_samples, 0);
    for e in &reference.stats.effects {
        assert_eq!((e.coarse_evaluations, e.pixel_evaluations, e.resampled), (0, pixels, 0), "reference: {e:?}");
    }
    // The G-buffer read back and uploaded again is the same G-buffer: the
    // readback keeps every bit, and the formats match the CPU scenes'.
    let gbuffer = raster::read_gbuffer(gpu, &channels).unwrap();
    let uploaded = gbuffer.upload(gpu);
    for ((name, a), (_, b)) in channels.iter().zip(&uploaded) {
        assert_eq!(a.format(), b.format(), "{name}");
    }
    let again = shade(gpu, &program, &uploaded, Mode::Reference, Some(eye));
    assert!(again.pixels == reference.pixels, "the uploaded readback shades differently");

    let mut fractions = vec![reference.stats.shaded_fraction];
    for (mode, bar) in [(Mode::Coarse2x2, 53.3), (Mode::Coarse4x4, 53.3)] {
        let out = shade(gpu, &program, &channels, mode, Some(eye));
        let db = psnr(&out.pixels, &reference.pixels);
        eprintln!(
            "sponza {}x{} {mode}: PSNR {db:.2} dB, shaded fraction {:.4}",
            SIZE.0, SIZE.1, out.stats.shaded_fraction
        );
        assert!(db >= bar, "{mode}: PSNR {db:.2} dB is below the {bar} dB bar");
        assert!(out.pixels.iter().all(|p| p[3] == 1.0), "{mode}: a pixel was not written");

        // The stats add up: every coarse effect was shaded once per coarse
        // sample of the grid plus once per refining pixel, every other
        // effect once per pixel, and the total is the reported fraction.
        // Independently of the runtime's formula: every B-th pixel along each
        // axis, plus the last pixel when the lattice misses it.
        let block = mode.block_size().unwrap();
        let per_axis = |n: u32| u64::from(n.div_ceil(block) + u32::from(!(n - 1).is_multiple_of(block)));
        let samples = per_axis(SIZE.0) * per_axis(SIZE.1);
        assert_eq!(out.stats.coarse_samples, samples);
        let mut shaded = 0u64;
        for e in &out.stats.effects {
            assert_eq!(e.pixel_evaluations + e.resampled, pixels, "{mode}: {e:?}");
            if e.rate == mrsl_abi::Rate::Coarse {
                assert_eq!(e.coarse_evaluations, samples, "{mode}: {e:?}");
                assert!(e.pixel_evaluations < pixels, "{mode}: `{}` refined everywhere", e.name);
            } else {
                assert_eq!((e.coarse_evaluations, e.pixel_evaluations), (0, pixels), "{mode}: {e:?}");
            }
            let fraction = (e.coarse_evaluations + e.pixel_evaluations) as f64 / pixels as f64;
            assert!((e.shaded_fraction - fraction).abs() < 1e-12, "{mode}: {e:?}");
            shaded += e.coarse_evaluations + e.pixel_evaluations;
        }
        let expected = shaded as f64 / (pixels * out.stats.effects.len() as u64) as f64;
        assert!(
            (out.stats.shaded_fraction - expected).abs() < 1e-12,
            "{mode}: {} vs {expected}",
            out.stats.shaded_fraction
        );
        fractions.push(out.stats.shaded_fraction);
    }
    // Both shade less than the reference. (At this size most blocks hold a
    // silhouette or a crease, so 4x4, whose blocks cover more of them, may
    // shade as much as 2x2: 0.906 against 0.885, measured.)
    assert!(fractions[1] < fractions[0] && fractions[2] < fractions[0], "shaded fractions {fractions:?}");
}

/// The model as obj-rs 0.7.4 ships it: 76,154 triangles once its polygons
/// (up to 78-gons) are triangulated, 35 materials numbered in the order the
/// file first uses them, all used, unit normals everywhere.
pub fn sponza_loads_with_its_35_materials() {
    let path = mrsl_lab::fixtures::sponza_path().unwrap();
    assert!(path.ends_with("obj-rs-0.7.4/tests/fixtures/sponza.obj"), "{}", path.display());
    let mesh = mrsl_lab::fixtures::sponza_shared().unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.triangle_count(), 76_154);
    assert_eq!(mesh.material_names.len(), 35);
    assert_eq!(mesh.material_names[0], "sp_00_zid");
    assert_eq!(mesh.material_names[34], "sp_00_svod_zid");
    let mut used = [false; 35];
    for t in mesh.indices.chunks_exact(3) {
        let m = mesh.materials[t[0] as usize];
        assert!(t.iter().all(|&i| mesh.materials[i as usize] == m), "a triangle mixes materials");
        used[m as usize] = true;
    }
    assert!(used.iter().all(|&u| u), "unused material ids: {used:?}");
    assert!(mesh.normals.iter().all(|n| ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-5));
    let b = mesh.bounds().unwrap();
    let expected = ([-17.0, -1.0, -7.6], [17.0, 15.0, 7.6]);
    for k in 0..3 {
        assert!((b.min[k] - expected.0[k]).abs() < 1.0 && (b.max[k] - expected.1[k]).abs() < 1.0, "bounds {b:?}");
    }
    // The default camera is inside the model.
    let eye = Scene::sponza_camera().eye;
    assert!((0..3).all(|k| b.min[k] < eye[k] && eye[k] < b.max[k]));
}

/// Two quads side by side in the plane y + z = 0 (normal (0, 1, 1)/sqrt 2),
/// left material 3, right material 7, with uv = (x, y).
fn tilted_quads(with_normals: bool) -> Mesh {
    let n = [0.0, std::f32::consts::FRAC_1_SQRT_2, std::f32::consts::FRAC_1_SQRT_2];
    let mut mesh = Mesh::default();
    for (x0, x1, material) in [(-2.0f32, 0.0f32, 3u32), (0.0, 2.0, 7)] {
        let base = mesh.positions.len() as u32;
        for (x, t) in [(x0, -1.0f32), (x1, -1.0), (x1, 1.0), (x0, 1.0)] {
            mesh.positions.push([x, t, -t]);
            mesh.normals.push(if with_normals { n } else { [0.0; 3] });
            mesh.uvs.push([x, t]);
            mesh.materials.push(material);
        }
        mesh.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    mesh.material_names = (0..8).map(|i| format!("m{i}")).collect();
    if !with_normals {
        mesh.compute_normals(45.0);
    }
    mesh
}

pub fn floats<'a>(g: &'a GBuffer, name: &str) -> (&'a [f32], usize) {
    match g.channel(name) {
        Some(ChannelData::Float { components, data }) => (data, *components as usize),
        other => panic!("{name}: {other:?}"),
    }
}

/// The rasteriser against analytic answers: ray-plane intersections for
/// position and depth, the face normal, uv, material ids, the background
/// convention; seen from behind, the normal flips to face the camera.
pub fn rasterised_quads_match_the_analytic_gbuffer(gpu: &Gpu) {
    let (w, h) = (96u32, 54u32);
    for (with_normals, eye, normal_sign) in
        [(true, [0.0, 0.0, 5.0], 1.0f32), (false, [0.0, 0.0, 5.0], 1.0), (true, [0.0, 0.0, -5.0], -1.0)]
    {
        let mesh = tilted_quads(with_normals);
        let camera = Camera::look_at(eye, [0.0, 0.0, 0.0], 50.0);
        let g = raster::rasterize_gbuffer(gpu, &mesh, &camera, (w, h)).unwrap();
        assert_eq!((g.width, g.height), (w, h));
        let names: Vec<&str> = g.channels.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            ["position", "normal", "uv", "material", "depth", "albedo", "roughness", "metallic", "velocity"]
        );
        let (position, _) = floats(&g, "position");
        let (normal, _) = floats(&g, "normal");
        let (uv, _) = floats(&g, "uv");
        let (depth, _) = floats(&g, "depth");
        let Some(ChannelData::Uint(material)) = g.channel("material") else { panic!() };
        let face = [0.0, normal_sign * std::f32::consts::FRAC_1_SQRT_2, normal_sign * std::f32::consts::FRAC_1_SQRT_2];
        let mut covered = 0;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let d = camera.ray(x, y, (w, h)).unwrap();
                // Ray-plane intersection with y + z = 0.
                let t = -(eye[1] + eye[2]) / (d[1] + d[2]);
                let hit = [eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2]];
                let p = &position[3 * i..3 * i + 3];
                let n = &normal[3 * i..3 * i + 3];
                let inside = t > 0.0 && hit[0].abs() < 2.0 && hit[1].abs() < 1.0;
                let margin = hit[0].abs() > 1.95 || hit[1].abs() > 0.95 || hit[0].abs() < 0.05;
                if margin {
                    continue; // edge pixels: coverage is the rasteriser's call
                }
                if inside {
                    covered += 1;
                    assert_eq!(material[i], if hit[0] < 0.0 { 3 } else { 7 }, "pixel ({x}, {y})");
                    for k in 0..3 {
                        assert!((p[k] - hit[k]).abs() < 1e-4, "position at ({x}, {y}): {p:?} vs {hit:?}");
                        assert!((n[k] - face[k]).abs() < 1e-3, "normal at ({x}, {y}): {n:?} vs {face:?}");
                    }
                    assert!((depth[i] - t).abs() < 1e-4 * t, "depth at ({x}, {y}): {} vs {t}", depth[i]);
                    assert!((uv[2 * i] - hit[0]).abs() < 1e-4 && (uv[2 * i + 1] - hit[1]).abs() < 1e-4);
                } else {
                    assert_eq!(material[i], BACKGROUND, "pixel ({x}, {y})");
                    let far = depth[i];
                    assert_eq!(far, 50.0, "background depth at ({x}, {y})");
                    for k in 0..3 {
                        assert!((n[k] + d[k]).abs() < 1e-5, "background normal at ({x}, {y})");
                        assert!((p[k] - (eye[k] + far * d[k])).abs() < 1e-3, "background position at ({x}, {y})");
                    }
                }
            }
        }
        assert!(covered > (w * h) as usize / 8, "only {covered} pixels on the quads");
        // Up a column through a quad the plane recedes: depth grows row by row.
        let x = 3 * w / 8;
        let column: Vec<f32> =
            (0..h).map(|y| (y * w + x) as usize).filter(|&i| material[i] != BACKGROUND).map(|i| depth[i]).collect();
        assert!(column.len() > h as usize / 3);
        if eye[2] > 0.0 {
            assert!(column.windows(2).all(|p| p[0] > p[1]), "depth does not grow upwards: {column:?}");
        } else {
            // From behind, the top of the plane is the near end.
            assert!(column.windows(2).all(|p| p[0] < p[1]), "depth does not fall upwards: {column:?}");
        }
    }
}

/// A folder of its own under the system's temporary folder.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrsl-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A unit cube of quads on 8 shared vertices (no normals, no uvs), and a
/// concave "C" polygon, with two materials.
const OBJ: &str = "\
# test model
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
usemtl stone
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
o c
v 3 0 0
v 6 0 0
v 6 1 0
v 4 1 0
v 4 2 0
v 6 2 0
v 6 3 0
v 3 3 0
vt 0 0
usemtl brass
f 9/1 10/1 11/1 12/1 13/1 14/1 15/1 16/1
";

/// OBJ files written here load: polygons are triangulated correctly (the
/// C's area is kept, which a fan from its first corner would not), the
/// cube's normals stay flat across its 90 degree creases, and materials are
/// numbered in order of use.
pub fn obj_written_to_a_temp_dir_loads() {
    let dir = temp_dir("obj");
    let path = dir.join("model.obj");
    std::fs::write(&path, OBJ).unwrap();
    let mesh = Mesh::load(&path).unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.material_names, ["stone", "brass"]);
    assert_eq!(mesh.triangle_count(), 12 + 6);
    let mut c_area = 0.0;
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let len = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        let face = [cr[0] / len, cr[1] / len, cr[2] / len];
        let material = mesh.materials[t[0] as usize];
        for &i in t {
            let n = mesh.normals[i as usize];
            assert!((0..3).all(|k| (n[k] - face[k]).abs() < 1e-6), "normal {n:?} of a face {face:?}");
            assert_eq!(mesh.materials[i as usize], material);
        }
        if material == 1 {
            assert!(cr[2] > 0.0, "the C's triangles keep its counter-clockwise winding");
            c_area += 0.5 * len;
        } else {
            // The cube's faces point outwards.
            let centre =
                [(a[0] + b[0] + c[0]) / 3.0 - 0.5, (a[1] + b[1] + c[1]) / 3.0 - 0.5, (a[2] + b[2] + c[2]) / 3.0 - 0.5];
            assert!(face[0] * centre[0] + face[1] * centre[1] + face[2] * centre[2] > 0.0);
        }
    }
    assert!((c_area - 7.0).abs() < 1e-5, "the C's triangles cover {c_area}, not 7");
    let b = mesh.bounds().unwrap();
    assert_eq!((b.min, b.max), ([0.0, 0.0, 0.0], [6.0, 3.0, 1.0]));
    // A 45 degree crease keeps the cube flat; 100 degrees smooths it.
    let mut smooth = mesh.clone();
    smooth.compute_normals(100.0);
    let corner = smooth.positions.iter().position(|p| *p == [1.0, 1.0, 1.0]).unwrap();
    let n = smooth.normals[corner];
    assert!((0..3).all(|k| (n[k] - 1.0 / 3f32.sqrt()).abs() < 1e-5), "smoothed corner normal {n:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A glTF file with an embedded (base64) buffer and a GLB with the same
/// content: one triangle without normals under a translated node.
pub fn gltf_and_glb_written_to_a_temp_dir_load() {
    let dir = temp_dir("gltf");
    let mut bin: Vec<u8> = vec![];
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend(i.to_le_bytes()); // 3 indices and 2 bytes of padding
    }
    let json = |uri: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"translation":[10,0,0]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
            "materials":[{{"name":"gold"}}],
            "buffers":[{{{uri}"byteLength":{}}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
            bin.len()
        )
    };
    let data_uri = format!(r#""uri":"data:application/octet-stream;base64,{}","#, base64(&bin));
    std::fs::write(dir.join("tri.gltf"), json(&data_uri)).unwrap();
    let mut glb_json = json("").into_bytes();
    while glb_json.len() % 4 != 0 {
        glb_json.push(b' ');
    }
    let mut glb: Vec<u8> = vec![];
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + glb_json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((glb_json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&glb_json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    std::fs::write(dir.join("tri.glb"), glb).unwrap();
    for name in ["tri.gltf", "tri.glb"] {
        let mesh = Mesh::load(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        mesh.validate().unwrap();
        assert_eq!(mesh.triangle_count(), 1, "{name}");
        assert_eq!(mesh.material_names, ["gold"], "{name}");
        let mut positions = mesh.positions.clone();
        positions.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(positions, [[10.0, 0.0, 0.0], [10.0, 1.0, 0.0], [11.0, 0.0, 0.0]], "{name}");
        assert!(mesh.normals.iter().all(|n| *n == [0.0, 0.0, 1.0]), "{name}: {:?}", mesh.normals);
        assert!(mesh.materials.iter().all(|&m| m == 0));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let v = chunk.iter().enumerate().fold(0u32, |acc, (k, &b)| acc | (b as u32) << (16 - 8 * k));
        for k in 0..4 {
            out.push(if k <= chunk.len() { A[(v >> (18 - 6 * k)) as usize & 63] as char } else { '=' });
        }
    }
    out
}

/// Unreadable files and formats are typed errors, never panics.
pub fn bad_mesh_files_are_typed_errors() {
    let dir = temp_dir("bad");
    match Mesh::load(dir.join("missing.obj")) {
        Err(MeshError::Io { path, source }) => {
            assert!(path.ends_with("missing.obj"));
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(Mesh::load(dir.join("missing.glb")), Err(MeshError::Io { .. })));
    assert!(matches!(Mesh::load(dir.join("model.stl")), Err(MeshError::UnsupportedFormat { .. })));
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    assert!(matches!(Mesh::load(dir.join("bad.obj")), Err(MeshError::Obj { .. })));
    std::fs::write(dir.join("empty.obj"), "# nothing\nv 0 0 0\n").unwrap();
    assert!(matches!(Mesh::load(dir.join("empty.obj")), Err(MeshError::Empty { .. })));
    std::fs::write(dir.join("bad.gltf"), "{ not json").unwrap();
    let err = Mesh::load(dir.join("bad.gltf")).unwrap_err();
    assert!(matches!(err, MeshError::Gltf { .. }), "{err:?}");
    assert!(err.to_string().contains("bad.gltf"), "{err}");
    std::fs::write(dir.join("bad.glb"), b"glTF\x02\0\0\0garbage").unwrap();
    assert!(matches!(Mesh::load(dir.join("bad.glb")), Err(MeshError::Gltf { .. })));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Scene files: relative mesh paths, camera, size and uniforms; each
/// mistake names the file and the key.
pub fn scene_files_parse_and_name_their_mistakes(gpu: &Gpu) {
    let dir = temp_dir("scene");
    std::fs::create_dir_all(dir.join("models")).unwrap();
    std::fs::write(dir.join("models/model.obj"), OBJ).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(
        &path,
        r#"
mesh = "models/model.obj"
size = [64, 32]
[camera]
eye = [3, 1.5, 8]
target = [3, 1.5, 0]
fov = 40
[uniforms]
light_dir = [0.3, 0.9, 0.3]
shininess = 20
show_checker = false
"#,
    )
    .unwrap();
    let scene = SceneFile::load(&path).unwrap();
    assert_eq!(scene.mesh, MeshSource::File(dir.join("models/model.obj")));
    assert_eq!(scene.size, Some((64, 32)));
    let camera = scene.camera.unwrap();
    assert_eq!(
        (camera.eye, camera.target, camera.up, camera.fov_y_degrees),
        ([3.0, 1.5, 8.0], [3.0, 1.5, 0.0], [0.0, 1.0, 0.0], 40.0)
    );
    assert_eq!(
        scene.uniforms,
        [
            ("light_dir".to_string(), UniformValue::Numbers(vec![0.3, 0.9, 0.3])),
            ("shininess".to_string(), UniformValue::Numbers(vec![20.0])),
            ("show_checker".to_string(), UniformValue::Numbers(vec![0.0]))
        ]
    );
    assert_eq!(SceneFile::parse("mesh = \"sponza\"", &path).unwrap().mesh, MeshSource::Sponza);

    let key_of = |text: &str| match SceneFile::parse(text, &path) {
        Err(SceneFileError::Key { path: p, key, message }) => {
            assert_eq!(p, path);
            assert!(!message.is_empty());
            key
        }
        other => panic!("{text}: {other:?}"),
    };
    assert_eq!(key_of("size = [1, 2]"), "mesh");
    assert_eq!(key_of("mesh = 3"), "mesh");
    assert_eq!(key_of("mesh = \"a.obj\"\nsize = [0, 2]"), "size");
    assert_eq!(key_of("mesh = \"a.obj\"\nsize = \"big\""), "size");
    assert_eq!(key_of("mesh = \"a.obj\"\n[camera]\neye = [1, 2]\ntarget = [0, 0, 0]"), "camera.eye");
    assert_eq!(key_of("mesh = \"a.obj\"\n[camera]\neye = [1, 2, 3]"), "camera.target");
    assert_eq!(key_of("mesh = \"a.obj\"\n[camera]\neye = [1, 2, 3]\ntarget = [0, 0, 0]\nfov = 200"), "camera.fov");
    assert_eq!(key_of("mesh = \"a.obj\"\n[camera]\neye = [1, 2, 3]\ntarget = [1, 2, 3]"), "camera");
    assert_eq!(key_of("mesh = \"a.obj\"\n[camera]\nposition = [1, 2, 3]"), "camera.position");
    assert_eq!(key_of("mesh = \"a.obj\"\n[uniforms]\ncolor = [1, \"red\"]"), "uniforms.color");
    assert_eq!(key_of("mesh = \"a.obj\"\nlights = 3"), "lights");
    match SceneFile::parse("mesh = ", &path) {
        Err(e @ SceneFileError::Syntax { .. }) => assert!(e.to_string().contains("scene.toml"), "{e}"),
        other => panic!("{other:?}"),
    }
    match SceneFile::load(dir.join("nope.toml")) {
        Err(SceneFileError::Io { source, .. }) => assert_eq!(source.kind(), std::io::ErrorKind::NotFound),
        other => panic!("{other:?}"),
    }
    let missing_mesh = SceneFile::parse("mesh = \"gone.obj\"", &path).unwrap();
    match missing_mesh.load_mesh() {
        Err(SceneFileError::Mesh { path: p, source: MeshError::Io { .. } }) => assert_eq!(p, path),
        other => panic!("{other:?}"),
    }

    // Rendered: the C (material 1) seen straight on, its notch open to the
    // background, its normal +z.
    let size = scene.size.unwrap();
    let g = scene.render_on(gpu, size).unwrap();
    assert_eq!((g.width, g.height), size);
    let Some(ChannelData::Uint(material)) = g.channel("material") else { panic!() };
    let (normal, _) = floats(&g, "normal");
    let (mut on_bar, mut in_notch) = (0, 0);
    for y in 0..size.1 {
        for x in 0..size.0 {
            let d = camera.ray(x, y, size).unwrap();
            let t = -camera.eye[2] / d[2];
            let (hx, hy) = (camera.eye[0] + t * d[0], camera.eye[1] + t * d[1]);
            let i = (y * size.0 + x) as usize;
            if (3.1..5.9).contains(&hx) && (0.1..0.9).contains(&hy) {
                on_bar += 1;
                assert_eq!(material[i], 1, "pixel ({x}, {y}) on the C");
                assert!((normal[3 * i + 2] - 1.0).abs() < 1e-5);
            } else if (4.1..5.9).contains(&hx) && (1.1..1.9).contains(&hy) {
                in_notch += 1;
                assert_eq!(material[i], BACKGROUND, "pixel ({x}, {y}) in the C's notch");
            }
        }
    }
    assert!(on_bar > 10 && in_notch > 10, "{on_bar} {in_notch}");
    // A camera looking straight along `up` is a typed error.
    let mesh = scene.load_mesh().unwrap();
    let bad = Camera { eye: [0.0, 5.0, 0.0], target: [0.0, 0.0, 0.0], up: [0.0, 1.0, 0.0], fov_y_degrees: 50.0 };
    assert!(matches!(raster::rasterize(gpu, &mesh, &bad, (8, 8)), Err(RasterError::BadCamera(_))));
    assert!(matches!(raster::rasterize(gpu, &mesh, &camera, (0, 8)), Err(RasterError::BadSize { .. })));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The expensive workload (examples/sponza_lights.mrsl) with the scene's
/// light rig and the sun's shadow map, as `mrslc render` and `mrslc bench`
/// bind it: the rig reaches the program, the shadow map agrees with the
/// view's G-buffer, every mode with every predicate forced is bit-identical
/// to the reference, and the adaptive modes stay close to it.
pub fn sponza_lights_workload_matches_its_reference(gpu: &Gpu) {
    let program = compile(include_str!("../../examples/sponza_lights.mrsl"));
    let mut scene = Scene::Sponza.mesh_scene(gpu).unwrap().expect("Sponza is a mesh scene");
    let channels = scene.gbuffer(gpu, &scene.camera, SIZE).unwrap();
    let shadow_map = scene.shadow_map(gpu).unwrap().clone();

    // The shadow map against the view: a visible point p lies on a surface,
    // so the nearest surface the sun sees through p's texel is no farther
    // than p (up to a texel's footprint where the texel's centre ray passes
    // beside p). Decoded here from the two halves, independently of the program.
    let rig = &scene.rig;
    let m = rig.sun_view_proj().unwrap();
    let n = shadow_map.width();
    let halves: Vec<half::f16> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&shadow_map).unwrap());
    let gbuffer = raster::read_gbuffer(gpu, &channels).unwrap();
    let (Some(ChannelData::Float { data: position, .. }), Some(ChannelData::Uint(material))) =
        (gbuffer.channel("position"), gbuffer.channel("material"))
    else {
        panic!("G-buffer channels")
    };
    let (mut visible, mut consistent) = (0, 0);
    for (p, &id) in position.chunks_exact(3).zip(material) {
        if id == BACKGROUND {
            continue;
        }
        let clip: [f32; 4] = std::array::from_fn(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
        let (x, y) = ((clip[0] / clip[3] * 0.5 + 0.5) * n as f32, (0.5 - clip[1] / clip[3] * 0.5) * n as f32);
        let texel = (y as usize).min(n as usize - 1) * n as usize + (x as usize).min(n as usize - 1);
        let stored = halves[2 * texel].to_f32() + halves[2 * texel + 1].to_f32();
        let distance = rig.sun_distance([p[0], p[1], p[2]]);
        visible += 1;
        // A texel covers about distance / (focal * n) world units.
        if stored <= distance * (1.0 + 4.0 / n as f32) {
            consistent += 1;
        }
    }
    assert!(visible > 1000);
    assert!(consistent as f64 >= 0.98 * visible as f64, "{consistent} of {visible} points agree with the shadow map");

    let checker = gpu.texture_with_data(
        "albedo",
        (2, 2),
        wgpu::TextureFormat::Rgba8Unorm,
        &[200, 80, 60, 255, 235, 225, 200, 255, 235, 225, 200, 255, 200, 80, 60, 255],
    );
    let views = [
        ("shadow_map", shadow_map.create_view(&Default::default())),
        ("albedo_map", checker.create_view(&Default::default())),
    ];
    let sampler = gpu.device.create_sampler(&Default::default());
    let run = |mode: Mode, force_refine: bool| {
        let mut shader = Shader::new(&gpu.device, &program).unwrap();
        let applied = scene.set_uniforms(&mut shader, &scene.camera).unwrap();
        assert_eq!(applied.warnings, [], "the workload declares the rig's uniforms with the rig's types");
        let set = applied.set;
        for name in ["light_pos", "light_color", "light_count", "sun_pos", "sun_view_proj", "sun_focal", "sun_size"] {
            assert!(set.iter().any(|s| s == name), "the rig did not set `{name}`: {set:?}");
        }
        let textures: Vec<(&str, &wgpu::TextureView)> = views.iter().map(|(name, view)| (*name, view)).collect();
        let options = DispatchOptions { force_refine, ..DispatchOptions::new(mode) };
        render_color(gpu, &mut shader, &channels, &textures, &[("linear", &sampler)], SIZE, options)
    };
    let reference = run(Mode::Reference, false);
    // The image is lit: no NaN, and both the lights and the sun reach it.
    assert!(reference.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
    let mean: f32 =
        reference.pixels.iter().map(|p| p[0] + p[1] + p[2]).sum::<f32>() / (3 * reference.pixels.len()) as f32;
    assert!(mean > 0.1, "mean {mean}");
    for mode in adaptive_modes() {
        let forced = run(mode, true);
        assert!(forced.pixels == reference.pixels, "{mode}: forced refinement differs from the reference");
    }
    // Adaptive quality at the program's defaults, measured on lavapipe
    // (Mesa 22.3) at 192x108: coarse4x4 42.1 dB at shaded fraction 0.759,
    // hierarchical 43.6 dB at 0.715 (the fractions count the sun's cosine,
    // a fine effect, as shaded at every pixel). At this size almost every 4x4 block
    // holds a silhouette or a crease, and a block spans metres of wall: a
    // pixel resampled from the corners on its side of an edge extrapolates
    // the 32 lights' falloff across it (52.7 dB at 0.967 when every such
    // block was refined), and the hierarchical mode interpolates along an
    // edge from the neighbours on a pixel's side (56.0 dB at 0.751 when it
    // shaded at every edge); at 1920x1080 both are above MSSIM 0.99
    // (docs/eval/evaluation.md). The bars are 3 dB below, as in the test above:
    // threshold comparisons may flip a few blocks on another driver.
    // (20,427 of 20,504 visible points agreed with the shadow map.)
    for (mode, bar) in [(Mode::Coarse4x4, 39.1), (Mode::Hierarchical, 40.6)] {
        let out = run(mode, false);
        let db = psnr(&out.pixels, &reference.pixels);
        eprintln!("sponza_lights 192x108 {mode}: PSNR {db:.2} dB, shaded fraction {:.4}", out.stats.shaded_fraction);
        assert!(db >= bar, "{mode}: {db:.1} dB < {bar} dB");
        assert!(out.stats.shaded_fraction < 0.99, "{mode}: shaded {}", out.stats.shaded_fraction);
    }
}
