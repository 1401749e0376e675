//! What a scene provides reaches a program by name AND type: the light rig's
//! uniforms, `camera_pos`, and a scene file's values and images
//! (`mrsl_lab::uniforms`). The case that used to go wrong silently:
//! `examples/textured_materials.mrsl` declares `uniform float3 light_color`,
//! the rig's `light_color` is a `float4[32]`, and binding by name alone
//! zeroed the program's light, leaving an ambient-only image that every
//! mode matched exactly.

use mrsl_lab::gpu::Gpu;
use mrsl_lab::image_texture::ColorSpace;
use mrsl_lab::raster;
use mrsl_lab::rig::RigError;
use mrsl_lab::scene::{BACKGROUND, ChannelData};
use mrsl_lab::scene_file::{SceneFile, SceneFileError, UniformValue};
use mrsl_lab::uniforms::Offered;
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::path::{Path, PathBuf};

/// The albedo image's one colour, sRGB-encoded.
const ALBEDO_SRGB: [u8; 3] = [90, 160, 210];

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrsl-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A unit sphere at the origin as OBJ: positions and texture coordinates,
/// no normals (the loader computes smooth ones), one material.
fn sphere_obj(rings: usize, segments: usize) -> String {
    let mut obj = String::from("# unit sphere\no sphere\n");
    for i in 0..=rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..=segments {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
            let (x, y, z) = (theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos());
            obj += &format!("v {x:.6} {y:.6} {z:.6}\n");
            obj += &format!("vt {:.6} {:.6}\n", j as f64 / segments as f64, 1.0 - i as f64 / rings as f64);
        }
    }
    obj += "usemtl paint\n";
    let index = |i: usize, j: usize| i * (segments + 1) + j + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
            // One triangle at the poles, where two corners coincide.
            if i != 0 {
                obj += &format!("f {a}/{a} {b}/{b} {d}/{d}\n");
            }
            if i != rings - 1 {
                obj += &format!("f {b}/{b} {c}/{c} {d}/{d}\n");
            }
        }
    }
    obj
}

/// A scene file over the sphere that binds two images: the albedo (sRGB
/// colour) and the roughness (data).
fn write_scene(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("sphere.obj"), sphere_obj(24, 48)).unwrap();
    let [r, g, b] = ALBEDO_SRGB;
    image::RgbImage::from_pixel(8, 8, image::Rgb([r, g, b])).save(dir.join("albedo.png")).unwrap();
    image::GrayImage::from_pixel(8, 8, image::Luma([150])).save(dir.join("rough.png")).unwrap();
    let path = dir.join("sphere.toml");
    std::fs::write(
        &path,
        r#"
mesh = "sphere.obj"
size = [96, 64]
[camera]
eye = [0, 0.6, 3.2]
target = [0, 0, 0]
fov = 45
[uniforms]
albedo_map = "albedo.png"
roughness_map = { image = "rough.png", srgb = false }
exposure = 1.5
"#,
    )
    .unwrap();
    path
}

fn srgb_to_linear(v: u8) -> f32 {
    let s = f32::from(v) / 255.0;
    if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }
}

/// `examples/textured_materials.mrsl` over a mesh scene, bound as `mrslc
/// render` binds it (rig, `camera_pos`, the scene file's images), is lit by
/// its own light: the rig's `float4[32]` `light_color` is refused with a
/// warning naming both types instead of zeroing the program's `float3`.
///
/// Independent of the program's arithmetic beyond its structure, the test
/// renders the reference twice, as bound and with `light_color` set to zero
/// (ambient only), and reads the G-buffer's normals back:
///
/// - where the surface faces away from `light_dir` (N.L < -0.02 on the CPU;
///   the margin covers rounding between CPU and GPU near the terminator),
///   both the diffuse term (saturate(N.L)) and the microfacet lobe (a factor
///   max(N.L, 0)) are exactly 0, so the images must agree to 1e-6;
/// - where it faces the light (N.L > 0.3), the light adds at least
///   0.3 x albedo x light_color to the luminance: with the albedo image's
///   linear luminance (0.32) and the program's light (0.92 or more per
///   channel), at least 0.088; the test asks for 0.05, so only a light that
///   is missing or several times too dark fails. With the old binding the
///   difference was exactly 0 everywhere.
/// - the ambient-only image is the albedo times `ambient` (0.06): it checks
///   that the scene file's image is bound (not the checker fallback) and
///   decoded from sRGB (read as stored, it would be 0.015 to 0.017 too
///   bright per channel; the tolerance, 0.002, is 8-bit rounding with
///   room to spare).
pub fn textured_materials_are_lit_over_a_mesh_scene(gpu: &Gpu) {
    let dir = temp_dir("binding");
    let file = SceneFile::load(write_scene(&dir)).unwrap();
    let size = file.size.unwrap();
    let scene = file.mesh_scene(gpu, size).unwrap();
    let channels = scene.gbuffer(gpu, &scene.camera, size).unwrap();
    let program = crate::compile(include_str!("../../examples/textured_materials.mrsl"));
    let mut shader = Shader::new(&gpu.device, &program).unwrap();

    let applied = scene.set_uniforms(&mut shader, &scene.camera.clone()).unwrap();
    assert_eq!(applied.set, ["camera_pos"], "of the rig, the program declares only light_color, with another type");
    assert_eq!(applied.warnings.len(), 1, "{:?}", applied.warnings);
    let warning = &applied.warnings[0];
    assert_eq!((warning.name.as_str(), &warning.offered), ("light_color", &Offered::Float4Array(32)));
    assert_eq!(
        warning.to_string(),
        "light rig sets `light_color` as float4[32] but the program declares `uniform float3 light_color`; \
         left at the program's default"
    );
    let bound = file.bind(gpu, &mut shader).unwrap();
    assert_eq!(bound.applied.set, ["albedo_map", "roughness_map"]);
    assert_eq!(bound.applied.warnings, []);
    // A scene file written for several programs: a name this one does not
    // declare is left out with a warning, and the render goes on.
    let ignored: Vec<String> = bound.applied.ignored.iter().map(ToString::to_string).collect();
    assert_eq!(ignored.len(), 1, "{ignored:?}");
    assert!(
        ignored[0].starts_with("scene file ")
            && ignored[0].ends_with("sets `exposure`, which the program does not declare; ignored"),
        "{ignored:?}"
    );
    let formats: Vec<(&str, wgpu::TextureFormat, u32)> =
        bound.textures.iter().map(|(n, t)| (n.as_str(), t.format(), t.mip_level_count())).collect();
    assert_eq!(
        formats,
        [("albedo_map", wgpu::TextureFormat::Rgba8UnormSrgb, 4), ("roughness_map", wgpu::TextureFormat::Rgba8Unorm, 4)]
    );

    let views: Vec<(String, wgpu::TextureView)> =
        bound.textures.iter().map(|(n, t)| (n.clone(), t.create_view(&Default::default()))).collect();
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    });
    let color = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let render = |shader: &mut Shader| {
        let mut bindings = Bindings { size, ..Default::default() };
        for (name, texture) in &channels {
            bindings.channels.insert(name.clone(), texture);
        }
        for (name, view) in &views {
            bindings.textures.insert(name.clone(), view);
        }
        bindings.samplers.insert("linear".into(), &sampler);
        bindings.outputs.insert("color".into(), &color);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(Mode::Reference)).unwrap();
        gpu.queue.submit([encoder.finish()]);
        gpu.read_rgba32f(&color).unwrap()
    };
    let lit = render(&mut shader);
    shader.set_uniform("light_color", &[0.0, 0.0, 0.0]).unwrap();
    let ambient = render(&mut shader);

    let gbuffer = raster::read_gbuffer(gpu, &channels).unwrap();
    let (Some(ChannelData::Float { data: normal, components }), Some(ChannelData::Uint(material))) =
        (gbuffer.channel("normal"), gbuffer.channel("material"))
    else {
        panic!("G-buffer channels")
    };
    let components = *components as usize;
    let l = [-0.4f32, 0.8, 0.45];
    let norm = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
    let albedo = ALBEDO_SRGB.map(srgb_to_linear);
    let luminance = |p: [f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (mut away, mut facing) = (0, 0);
    for (i, &id) in material.iter().enumerate() {
        if id == BACKGROUND {
            continue;
        }
        let n = &normal[i * components..][..3];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let ndl = (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]) / (len * norm);
        let (x, y) = (i as u32 % size.0, i as u32 / size.0);
        for c in 0..3 {
            let expected = 0.06 * albedo[c];
            assert!(
                (ambient[i][c] - expected).abs() < 0.002,
                "pixel ({x}, {y}) channel {c}: ambient-only {} but albedo x ambient is {expected}",
                ambient[i][c]
            );
        }
        if ndl < -0.02 {
            away += 1;
            for c in 0..3 {
                assert!(
                    (lit[i][c] - ambient[i][c]).abs() < 1e-6,
                    "pixel ({x}, {y}) faces away but is lit: {:?}",
                    lit[i]
                );
            }
        } else if ndl > 0.3 {
            facing += 1;
            let added = luminance(lit[i]) - luminance(ambient[i]);
            assert!(added > 0.05, "pixel ({x}, {y}), N.L {ndl}: the light adds only {added} to the luminance");
        }
    }
    assert!(away > 100 && facing > 300, "too few pixels to judge: {away} facing away, {facing} facing the light");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A name the program declares with another type and no default would leave
/// its value missing: a typed error, from the rig and from a scene file.
pub fn mismatches_without_defaults_are_typed_errors(gpu: &Gpu) {
    let dir = temp_dir("binding-errors");
    let file = SceneFile::load(write_scene(&dir)).unwrap();
    let scene = file.mesh_scene(gpu, file.size.unwrap()).unwrap();
    let program = crate::compile(
        "in float2 uv;\nuniform float3 light_color;\nuniform float3 albedo_map;\n\
         uniform texture2d roughness_map;\nuniform sampler linear;\n\
         fine out float4 color = float4(light_color * albedo_map * sample(roughness_map, linear, uv).r, 1.0);",
    );
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    match scene.set_uniforms(&mut shader, &scene.camera) {
        Err(RigError::Type(e)) => {
            assert_eq!(e.0.name, "light_color");
            assert!(e.to_string().contains("float4[32]") && e.to_string().contains("no default"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // The scene file's image for a float3 without a default.
    match file.bind(gpu, &mut shader) {
        Err(SceneFileError::UniformType { key, source, .. }) => {
            assert_eq!(key, "uniforms.albedo_map");
            assert!(source.to_string().contains("as texture2d but the program declares `uniform float3 albedo_map`"));
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Images under `[uniforms]`: a file name (sRGB colour) or
/// `{ image = FILE, srgb = BOOL }`, resolved against the scene file; the
/// mistakes name their key.
pub fn scene_file_images_parse_and_name_their_mistakes() {
    let path = Path::new("/scenes/hall.toml");
    let file = SceneFile::parse(
        "mesh = \"m.obj\"\n[uniforms]\nalbedo_map = \"tex/a.png\"\nrough = { image = \"/abs/r.png\", srgb = false }\n\
         normal_map = { image = \"n.png\", srgb = true }",
        path,
    )
    .unwrap();
    let image = |p: &str, color_space| UniformValue::Image { path: PathBuf::from(p), color_space };
    assert_eq!(
        file.uniforms,
        [
            ("albedo_map".to_string(), image("/scenes/tex/a.png", ColorSpace::Srgb)),
            ("rough".to_string(), image("/abs/r.png", ColorSpace::Linear)),
            ("normal_map".to_string(), image("/scenes/n.png", ColorSpace::Srgb)),
        ]
    );
    for (text, needle) in [
        ("x = { srgb = false }", "missing `image"),
        ("x = { image = 3 }", "expected a file name"),
        ("x = { image = \"a.png\", srgb = \"no\" }", "expected true or false"),
        ("x = { image = \"a.png\", gamma = 2.2 }", "unknown key `gamma`"),
        ("x = [\"a.png\"]", "or an image file"),
    ] {
        match SceneFile::parse(&format!("mesh = \"m.obj\"\n[uniforms]\n{text}"), path) {
            Err(SceneFileError::Key { key, message, .. }) => {
                assert_eq!(key, "uniforms.x", "{text}");
                assert!(message.contains(needle), "{text}: {message}");
            }
            other => panic!("{text}: {other:?}"),
        }
    }
}
