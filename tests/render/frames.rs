//! Frames along a camera path: the rasteriser's velocity channel against
//! the analytic projection difference of a known camera move, and a
//! rate-image sequence that feeds each frame's output and motion vectors to
//! the rate source for the next frame, as `mrslc render --frames` does.

use crate::compile;
use mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
use mrsl_lab::camera::Camera;
use mrsl_lab::camera_path::{CameraPath, Keyframe};
use mrsl_lab::gpu::Gpu;
use mrsl_lab::mesh::Mesh;
use mrsl_lab::mesh_scene::MeshScene;
use mrsl_lab::raster;
use mrsl_lab::scene::{BACKGROUND, ChannelData};
use mrsl_runtime::rate_source::{
    RateInputs, RateOptions, RateSource, create_rate_image, rate_fraction, read_rate_image,
};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};

/// A program whose albedo is a checker from uv (8 squares per unit): the high contrast a rate source keeps fine.
const DEMO: &str = include_str!("data/phong.mrsl");

/// Axis-aligned quads facing +z: (x0, x1, y0, y1, z, material).
type Quad = (f32, f32, f32, f32, f32, u32);

/// A back wall at z = 0 and a nearer panel at z = 1.5, so that a camera
/// move shows parallax (the panel's pixels move farther than the wall's).
const QUADS: [Quad; 2] = [(-3.0, 3.0, -2.0, 2.0, 0.0, 1), (-0.8, 0.6, -0.7, 0.9, 1.5, 2)];

fn quads(quads: &[Quad]) -> Mesh {
    let mut mesh = Mesh::default();
    for &(x0, x1, y0, y1, z, material) in quads {
        let base = mesh.positions.len() as u32;
        for (x, y) in [(x0, y0), (x1, y0), (x1, y1), (x0, y1)] {
            mesh.positions.push([x, y, z]);
            mesh.normals.push([0.0, 0.0, 1.0]);
            mesh.uvs.push([x, y]);
            mesh.materials.push(material);
        }
        mesh.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    mesh.material_names = (0..3).map(|i| format!("m{i}")).collect();
    mesh
}

/// Where `camera` projects the world point `p`, in pixels (f64), with the
/// conventions of docs/scenes.md: pixel (x, y)'s centre is (x + 0.5, y + 0.5).
fn project(camera: &Camera, p: [f64; 3], size: (u32, u32)) -> [f64; 2] {
    let (forward, right, up) = camera.basis().unwrap();
    let d: [f64; 3] = std::array::from_fn(|k| p[k] - f64::from(camera.eye[k]));
    let dot = |a: [f32; 3]| (0..3).map(|k| f64::from(a[k]) * d[k]).sum::<f64>();
    let tan_half = (f64::from(camera.fov_y_degrees).to_radians() / 2.0).tan();
    let aspect = f64::from(size.0) / f64::from(size.1);
    let (sx, sy) = (dot(right) / dot(forward) / (tan_half * aspect), dot(up) / dot(forward) / tan_half);
    [(sx + 1.0) / 2.0 * f64::from(size.0), (1.0 - sy) / 2.0 * f64::from(size.1)]
}

/// The nearest quad the ray through pixel (x, y)'s centre hits, in f64:
/// the hit point, and whether it is within 0.05 of the quad's edge (where
/// coverage is the rasteriser's call).
fn hit(camera: &Camera, x: u32, y: u32, size: (u32, u32)) -> Option<([f64; 3], bool)> {
    let d = camera.ray(x, y, size).unwrap().map(f64::from);
    let eye = camera.eye.map(f64::from);
    let mut best: Option<(f64, [f64; 3], bool)> = None;
    for &(x0, x1, y0, y1, z, _) in &QUADS {
        let t = (f64::from(z) - eye[2]) / d[2];
        let p: [f64; 3] = std::array::from_fn(|k| eye[k] + t * d[k]);
        let (x0, x1, y0, y1) = (f64::from(x0), f64::from(x1), f64::from(y0), f64::from(y1));
        let inside = |m: f64| p[0] > x0 - m && p[0] < x1 + m && p[1] > y0 - m && p[1] < y1 + m;
        if t > 0.0 && inside(0.05) && best.is_none_or(|b| t < b.0) {
            best = Some((t, p, !inside(-0.05)));
        }
    }
    best.map(|(_, p, edge)| (p, edge))
}

fn velocity_of(gpu: &Gpu, channels: &[(String, wgpu::Texture)]) -> (Vec<f32>, Vec<u32>) {
    let g = raster::read_gbuffer(gpu, channels).unwrap();
    let Some(ChannelData::Float { components: 2, data }) = g.channel("velocity") else { panic!("no velocity") };
    let Some(ChannelData::Uint(material)) = g.channel("material") else { panic!("no material") };
    (data.clone(), material.clone())
}

/// A camera that moves right, up, back and turns: every pixel's velocity is
/// where the current camera projects its surface point minus where the
/// previous camera did, within 1e-3 px of the same difference computed
/// analytically in f64 from the ray's intersection with the quads.
pub fn velocity_is_the_projection_difference_of_a_camera_move(gpu: &Gpu) {
    let size = (96u32, 64u32);
    let mesh = quads(&QUADS);
    let scene = MeshScene::new(gpu, &mesh, Camera::look_at([0.0, 0.0, 6.0], [0.0; 3], 50.0)).unwrap();
    let camera = Camera::look_at([0.0, 0.1, 6.0], [0.0, 0.0, 0.0], 50.0);
    let previous = Camera::look_at([-0.35, -0.2, 6.4], [0.3, 0.1, 0.0], 50.0);
    let channels = scene.gbuffer_moving(gpu, &camera, Some(&previous), size).unwrap();
    let (velocity, material) = velocity_of(gpu, &channels);
    let (mut checked, mut worst, mut fastest) = (0, 0.0f64, 0.0f64);
    for y in 0..size.1 {
        for x in 0..size.0 {
            let i = (y * size.0 + x) as usize;
            let v = [f64::from(velocity[2 * i]), f64::from(velocity[2 * i + 1])];
            match hit(&camera, x, y, size) {
                None => {
                    assert_eq!(material[i], BACKGROUND, "pixel ({x}, {y})");
                    assert_eq!(v, [0.0, 0.0], "background velocity at ({x}, {y})");
                }
                Some((_, true)) => {}
                Some((p, false)) => {
                    let now = [f64::from(x) + 0.5, f64::from(y) + 0.5];
                    let before = project(&previous, p, size);
                    let expected = [now[0] - before[0], now[1] - before[1]];
                    let error = (v[0] - expected[0]).abs().max((v[1] - expected[1]).abs());
                    assert!(error < 1e-3, "velocity at ({x}, {y}): {v:?}, analytic {expected:?}");
                    worst = worst.max(error);
                    fastest = fastest.max(expected[0].hypot(expected[1]));
                    checked += 1;
                }
            }
        }
    }
    // The move is not trivial: every pixel on a quad was checked, and they move by pixels.
    assert!(checked > (size.0 * size.1) as usize / 3, "only {checked} pixels checked");
    assert!(fastest > 3.0, "the fastest pixel moved only {fastest} px");
    println!("velocity: {checked} pixels, largest error {worst:.2e} px, fastest {fastest:.2} px");
}

/// Without a move (the same camera, or no previous camera) every velocity is exactly 0.
pub fn an_unmoved_camera_gives_zero_velocity(gpu: &Gpu) {
    let size = (64u32, 48u32);
    let camera = Camera::look_at([0.4, 0.3, 5.0], [0.0; 3], 55.0);
    let scene = MeshScene::new(gpu, &quads(&QUADS), camera).unwrap();
    for previous in [Some(&camera), None] {
        let (velocity, material) = velocity_of(gpu, &scene.gbuffer_moving(gpu, &camera, previous, size).unwrap());
        assert!(material.iter().any(|m| *m != BACKGROUND), "the quads are in view");
        assert!(velocity.iter().all(|v| *v == 0.0), "previous {previous:?}: a nonzero velocity");
    }
    // The plain `render` (what a still frame uses) writes the same zeros.
    let (velocity, _) = velocity_of(gpu, &scene.gbuffer(gpu, &camera, size).unwrap());
    assert!(velocity.iter().all(|v| *v == 0.0));
}

/// The rates of the last frame of a rate-image sequence: `frames` frames
/// of the Phong test program over a checkered floor along `path`, each frame's
/// rates from the rate source on the previous frame's output and velocity.
/// Returns the fraction of shading cells the last rate image asks for and
/// the last frame's shaded fraction.
fn sequence(gpu: &Gpu, path: &CameraPath, motion: bool, frames: usize) -> (f64, f64) {
    let size = (128u32, 80u32);
    let tile = DEFAULT_RATE_TILE;
    // A floor with 8 checker squares per uv unit (the demo program's albedo).
    let mut floor = quads(&[(-20.0, 20.0, -20.0, 20.0, 0.0, 1)]);
    for p in &mut floor.positions {
        *p = [p[0], 0.0, -p[1]];
    }
    floor.normals.iter_mut().for_each(|n| *n = [0.0, 1.0, 0.0]);
    floor.uvs.iter_mut().for_each(|uv| *uv = [uv[0] / 4.0, uv[1] / 4.0]);
    let base = Camera::look_at([0.0, 2.0, 6.0], [0.0, 0.0, 0.0], 50.0);
    let scene = MeshScene::new(gpu, &floor, base).unwrap();
    let program = compile(DEMO);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    let color = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let history = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("previous frame"),
        size: color.size(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let rates = create_rate_image(&gpu.device, size, tile).unwrap();
    let options = RateOptions { motion, reproject: true, tile, ..RateOptions::default() };
    let mut source = RateSource::new(&gpu.device).unwrap();
    let (mut previous_camera, mut previous_channels): (Option<Camera>, Option<Vec<(String, wgpu::Texture)>>) =
        (None, None);
    let mut shaded = 0.0;
    for k in 0..frames {
        let camera = path.camera(&base, k, frames);
        let channels = scene.gbuffer_moving(gpu, &camera, previous_camera.as_ref(), size).unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        if let Some(previous) = &previous_channels {
            let velocity = &previous.iter().find(|(n, _)| n == "velocity").unwrap().1;
            let inputs = RateInputs { velocity: Some(velocity), ..RateInputs::new(&history) };
            source.encode(&gpu.device, &mut encoder, &inputs, &options, &rates).unwrap();
        }
        shader.set_uniform("camera_pos", &camera.eye.map(f64::from)).unwrap();
        let mut bindings = Bindings { size, ..Default::default() };
        for (name, texture) in &channels {
            bindings.channels.insert(name.clone(), texture);
        }
        bindings.outputs.insert("color".into(), &color);
        bindings.shading_rate = Some(&rates);
        let dispatch = DispatchOptions { rate_tile: tile, ..DispatchOptions::new(Mode::RateImage) };
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, dispatch).unwrap();
        encoder.copy_texture_to_texture(color.as_image_copy(), history.as_image_copy(), color.size());
        gpu.queue.submit([encoder.finish()]);
        shaded = shader.read_stats(&gpu.device).unwrap().shaded_fraction;
        previous_camera = Some(camera);
        previous_channels = Some(channels);
    }
    let last = read_rate_image(&gpu.device, &gpu.queue, &rates).unwrap();
    (rate_fraction(&last, size, tile).unwrap(), shaded)
}

/// A fast pan (about 25 px a frame) with motion on shades the last frames
/// at coarser rates than a still camera, and than the same pan with the
/// velocity terms off: the rate source reads the rasteriser's velocity.
pub fn a_fast_pan_lowers_the_rates_through_the_velocity(gpu: &Gpu) {
    let frames = 6;
    let key = |x: f32| Keyframe { eye: [0.0, 2.0, 6.0], target: [x, 0.0, 0.0] };
    let still = CameraPath::Keyframes(vec![key(0.0), key(0.0)]);
    let pan = CameraPath::Keyframes(vec![key(-4.0), key(4.0)]);
    let (still_rates, still_shaded) = sequence(gpu, &still, true, frames);
    let (pan_rates, pan_shaded) = sequence(gpu, &pan, true, frames);
    let (unmoved_rates, unmoved_shaded) = sequence(gpu, &pan, false, frames);
    println!(
        "rate fractions: still {still_rates:.3} (shaded {still_shaded:.3}), pan with motion {pan_rates:.3} \
         (shaded {pan_shaded:.3}), pan without motion {unmoved_rates:.3} (shaded {unmoved_shaded:.3})"
    );
    // The still camera's checker keeps many tiles fine: there is something to lower.
    assert!(still_rates > 0.3, "still: {still_rates}");
    assert!(pan_rates < 0.8 * still_rates, "pan {pan_rates} vs still {still_rates}");
    assert!(pan_rates < 0.8 * unmoved_rates, "pan with motion {pan_rates} vs without {unmoved_rates}");
    // The same frames shade less with the velocity terms on. (Against the
    // still camera the shaded fraction also depends on what is in view and
    // on the program's own refinement, so only the rates are compared there.)
    assert!(pan_shaded < unmoved_shaded, "shaded: pan {pan_shaded} with motion vs {unmoved_shaded} without");
}
