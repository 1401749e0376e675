//! The headless example's Bevy app, shared with its test: spheres on a
//! ground plane under point lights in Bevy's deferred renderer, a camera
//! rendering to an image, and `lighting.mrsl` run by bevy_mrsl in each
//! requested mode; each mode's output is read back once it is stable.

use bevy::app::{AppExit, ScheduleRunnerPlugin};
use bevy::camera::RenderTarget;
use bevy::core_pipeline::prepass::{DeferredPrepass, DepthPrepass};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::pbr::DefaultOpaqueRendererMethod;
use bevy::prelude::*;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::window::ExitCondition;
use bevy::world_serialization::WorldAsset;
use bevy::world_serialization::WorldAssetRoot;
use bevy_mrsl::{Mode, MrslCamera, MrslOutputs, MrslPlugin, MrslProgram, MrslReport, MrslUniforms, Stats};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

pub mod bench;

/// The example's program.
pub const PROGRAM: &str = include_str!("../lighting.mrsl");

/// The sky: Bevy's clear colour, which the program leaves in place (alpha 0).
pub const SKY: Color = Color::linear_rgb(0.35, 0.48, 0.7);

/// One image to render: a mode, refinement forced or not; with the
/// camera's composited image too, or not.
#[derive(Debug, Clone)]
pub struct Capture {
    pub name: String,
    pub mode: Mode,
    pub force_refine: bool,
    pub composite: bool,
}

/// A captured output: linear RGBA, row-major, top row first.
pub struct Captured {
    pub capture: Capture,
    pub pixels: Vec<[f32; 4]>,
    /// The camera's image (`Rgba8UnormSrgb`) with the output composited
    /// over Bevy's, when the capture asked for it.
    pub composite: Option<Vec<[u8; 4]>>,
    /// The statistics bevy_mrsl reported for this mode.
    pub stats: Option<Stats>,
}

/// Which image a readback reads.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    Output,
    Target,
}

/// Frames after which a capture that never became stable fails.
const FRAME_LIMIT: u32 = 2000;
/// Frames after the scene has loaded before the first capture.
const AFTER_LOAD: u32 = 30;
/// Readbacks dropped after a mode switch: they may carry frames recorded
/// before the switch reached the render world.
const STALE_READBACKS: u32 = 3;

/// Renders the scene at `size` once per capture, in order, in one app.
pub fn render(size: (u32, u32), scene: &Scene, captures: Vec<Capture>) -> Result<Vec<Captured>, String> {
    let result = Arc::new(Mutex::new(None));
    let sequence = Sequence {
        captures,
        index: 0,
        frames: 0,
        readbacks: 0,
        previous: None,
        loaded_frames: 0,
        source: Source::Output,
        done: Vec::new(),
        result: Arc::clone(&result),
    };
    app(size, scene)?.insert_resource(sequence).add_systems(Update, advance).run();
    let outcome = result.lock().unwrap().take();
    outcome.unwrap_or_else(|| Err("the app stopped before every capture was taken".into()))
}

/// The app without its driver: the scene, the camera (in the reference
/// mode) and bevy_mrsl, headless.
fn app(size: (u32, u32), scene: &Scene) -> Result<App, String> {
    let program = MrslProgram::compile(PROGRAM, "lighting.mrsl").map_err(|e| e.to_string())?;
    // A glTF file loads from its own folder.
    let assets = match scene {
        Scene::Spheres => "assets".to_string(),
        Scene::Gltf { path, .. } => path.parent().unwrap_or(Path::new(".")).display().to_string(),
    };
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
            .set(AssetPlugin { file_path: assets, ..default() })
            .set(bevy::log::LogPlugin { level: bevy::log::Level::WARN, ..default() }),
    )
    .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
    .add_plugins(MrslPlugin)
    .insert_resource(DefaultOpaqueRendererMethod::deferred())
    .insert_resource(ClearColor(SKY))
    .insert_resource(SceneSetup { size, program, scene: scene.clone() })
    .add_systems(Startup, setup)
    .add_systems(Update, scene_uniforms);
    Ok(app)
}

/// The camera's render target.
#[derive(Resource)]
struct TargetImage(Handle<Image>);

#[derive(Resource)]
struct SceneSetup {
    size: (u32, u32),
    program: MrslProgram,
    scene: Scene,
}

/// What the camera looks at.
#[derive(Debug, Clone)]
pub enum Scene {
    /// Four spheres on a ground plane under six point lights, built here.
    Spheres,
    /// A glTF file's first scene with its lights (`KHR_lights_punctual`),
    /// seen from `eye` towards `target` with a vertical field of view of
    /// `fov_y_degrees`.
    Gltf { path: PathBuf, eye: Vec3, target: Vec3, fov_y_degrees: f32 },
}

/// The glTF scene being loaded; captures wait until it and its textures are.
#[derive(Resource)]
struct Loading(Handle<WorldAsset>);

/// A sphere of the scene, for the program's shadows and occlusion.
#[derive(Component)]
struct Ball {
    radius: f32,
}

/// The demo's four spheres: centre and radius.
const BALLS: [(Vec3, f32); 4] = [
    (Vec3::new(-1.3, 0.7, 0.0), 0.7),
    (Vec3::new(0.5, 0.5, 0.9), 0.5),
    (Vec3::new(1.6, 0.9, -1.2), 0.9),
    (Vec3::new(-0.2, 0.35, -1.6), 0.35),
];

fn setup(
    mut commands: Commands,
    setup: Res<SceneSetup>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
    assets: Res<AssetServer>,
) {
    let (width, height) = setup.size;
    let mut target = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
    target.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    let target = images.add(target);
    commands.insert_resource(TargetImage(target.clone()));
    let (eye, look_at, fov) = match &setup.scene {
        Scene::Spheres => {
            spheres(&mut commands, &mut meshes, &mut materials);
            (Vec3::new(0.0, 1.5, 5.0), Vec3::new(0.0, 0.5, 0.0), 45.0)
        }
        Scene::Gltf { path, eye, target, fov_y_degrees } => {
            let file = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
            let scene = assets.load(GltfAssetLabel::Scene(0).from_asset(file));
            commands.insert_resource(Loading(scene.clone()));
            commands.spawn(WorldAssetRoot(scene));
            (*eye, *target, *fov_y_degrees)
        }
    };
    commands.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.into()),
        Projection::Perspective(PerspectiveProjection { fov: fov.to_radians(), ..default() }),
        Msaa::Off,
        // No tonemapping: the composited image is the program's output, encoded as sRGB.
        Tonemapping::None,
        DepthPrepass,
        DeferredPrepass,
        Transform::from_translation(eye).looking_at(look_at, Vec3::Y),
        MrslCamera::new(setup.program.clone(), Mode::Reference),
        MrslUniforms::default(),
    ));
}

/// Whether the scene is ready to capture: a glTF scene with its textures loaded.
fn loaded(loading: Option<Res<Loading>>, assets: &AssetServer) -> bool {
    loading.is_none_or(|l| assets.is_loaded_with_dependencies(&l.0))
}

/// The built-in scene: the demo's four spheres on a ground plane, six point lights.
fn spheres(commands: &mut Commands, meshes: &mut Assets<Mesh>, materials: &mut Assets<StandardMaterial>) {
    let ground = materials.add(StandardMaterial { base_color: Color::srgb(0.75, 0.72, 0.65), ..default() });
    commands.spawn((Mesh3d(meshes.add(Plane3d::default().mesh().size(12.0, 12.0))), MeshMaterial3d(ground)));
    let colours = [
        Color::srgb(0.8, 0.25, 0.2),
        Color::srgb(0.25, 0.6, 0.3),
        Color::srgb(0.3, 0.4, 0.85),
        Color::srgb(0.9, 0.75, 0.3),
    ];
    for ((centre, radius), colour) in BALLS.into_iter().zip(colours) {
        commands.spawn((
            Mesh3d(meshes.add(Sphere::new(radius).mesh().uv(64, 32))),
            MeshMaterial3d(materials.add(StandardMaterial { base_color: colour, ..default() })),
            Transform::from_translation(centre),
            Ball { radius },
        ));
    }
    for i in 0..6 {
        let a = i as f32 * std::f32::consts::TAU / 6.0;
        let hue = i as f32 * 60.0;
        commands.spawn((
            PointLight { color: Color::hsl(hue, 0.7, 0.65), intensity: 400_000.0, range: 30.0, ..default() },
            Transform::from_xyz(2.6 * a.cos(), 1.3 + 0.5 * (3.0 * a).sin(), 2.6 * a.sin()),
        ));
    }
}

/// Copies the scene into the program's uniforms: the camera, the point
/// lights (colour times intensity, in units of 100 000 lumens) and the spheres.
fn scene_uniforms(
    mut cameras: Query<(&GlobalTransform, &mut MrslUniforms)>,
    lights: Query<(&GlobalTransform, &PointLight)>,
    balls: Query<(&GlobalTransform, &Ball)>,
) {
    let mut light_pos = vec![0.0; 32];
    let mut light_color = vec![0.0; 32];
    let mut light_count = 0;
    for (i, (transform, light)) in lights.iter().take(8).enumerate() {
        let p = transform.translation();
        let c = light.color.to_linear();
        let power = f64::from(light.intensity) / 100_000.0;
        light_pos[4 * i..4 * i + 3].copy_from_slice(&[p.x as f64, p.y as f64, p.z as f64]);
        light_color[4 * i..4 * i + 3].copy_from_slice(&[
            c.red as f64 * power,
            c.green as f64 * power,
            c.blue as f64 * power,
        ]);
        light_count += 1;
    }
    let mut spheres = vec![0.0; 32];
    let mut sphere_count = 0;
    for (i, (transform, ball)) in balls.iter().take(8).enumerate() {
        let p = transform.translation();
        spheres[4 * i..4 * i + 4].copy_from_slice(&[p.x as f64, p.y as f64, p.z as f64, ball.radius as f64]);
        sphere_count += 1;
    }
    for (camera, mut uniforms) in &mut cameras {
        let eye = camera.translation();
        uniforms
            .set("camera_pos", [eye.x as f64, eye.y as f64, eye.z as f64])
            .set("light_pos", light_pos.clone())
            .set("light_color", light_color.clone())
            .set("light_count", [light_count as f64])
            .set("spheres", spheres.clone())
            .set("sphere_count", [sphere_count as f64]);
    }
}

/// What the app hands back when it exits: the captures, or what went wrong.
type SharedResult = Arc<Mutex<Option<Result<Vec<Captured>, String>>>>;

#[derive(Resource)]
struct Sequence {
    captures: Vec<Capture>,
    index: usize,
    frames: u32,
    /// Readbacks seen since the current capture's mode was set.
    readbacks: u32,
    previous: Option<Vec<u8>>,
    /// Frames since the scene was loaded.
    loaded_frames: u32,
    source: Source,
    done: Vec<Captured>,
    result: SharedResult,
}

/// Sets the camera to the current capture's mode, and starts reading its
/// output back once the plugin has made the output image.
#[allow(clippy::too_many_arguments, reason = "a Bevy system takes its parameters as arguments")]
fn advance(
    mut commands: Commands,
    mut sequence: ResMut<Sequence>,
    target: Res<TargetImage>,
    mut cameras: Query<(&mut MrslCamera, Option<&MrslOutputs>, Option<&MrslReport>)>,
    readers: Query<(), With<Readback>>,
    mut exit: MessageWriter<AppExit>,
    loading: Option<Res<Loading>>,
    assets: Res<AssetServer>,
) {
    if !loaded(loading, &assets) {
        sequence.loaded_frames = 0;
        return;
    }
    // A loaded glTF scene still spawns its entities and uploads its meshes
    // and textures over the next frames.
    sequence.loaded_frames += 1;
    if sequence.loaded_frames < AFTER_LOAD {
        return;
    }
    let Ok((mut camera, outputs, report)) = cameras.single_mut() else { return };
    sequence.frames += 1;
    if let Some(error) = report.and_then(|r| r.error.clone()) {
        return finish(&mut sequence, &mut exit, Err(format!("bevy_mrsl: {error}")));
    }
    if sequence.frames > FRAME_LIMIT {
        let name = sequence.captures[sequence.index].name.clone();
        return finish(&mut sequence, &mut exit, Err(format!("`{name}` did not settle in {FRAME_LIMIT} frames")));
    }
    let Some(capture) = sequence.captures.get(sequence.index).cloned() else { return };
    if camera.mode != capture.mode || camera.force_refine != capture.force_refine {
        camera.mode = capture.mode;
        camera.force_refine = capture.force_refine;
    }
    let image = match sequence.source {
        Source::Output => outputs.and_then(|o| o.images.first()).map(|(_, h)| h.clone()),
        Source::Target => Some(target.0.clone()),
    };
    if readers.is_empty()
        && let Some(image) = image
    {
        commands.spawn(Readback::texture(image)).observe(on_readback);
    }
}

/// Takes the capture when two readbacks in a row agree (and show something
/// drawn), after the stale ones.
fn on_readback(
    readback: On<ReadbackComplete>,
    mut commands: Commands,
    mut sequence: ResMut<Sequence>,
    cameras: Query<(&Camera, Option<&MrslReport>)>,
    mut exit: MessageWriter<AppExit>,
) {
    if sequence.index >= sequence.captures.len() {
        return;
    }
    sequence.readbacks += 1;
    if sequence.readbacks <= STALE_READBACKS {
        return;
    }
    let data = readback.data.clone();
    let drawn = match sequence.source {
        Source::Output => data.chunks_exact(16).any(|t| f32::from_le_bytes(t[12..16].try_into().unwrap()) > 0.0),
        Source::Target => true,
    };
    if !drawn || sequence.previous.as_ref() != Some(&data) {
        sequence.previous = Some(data);
        return;
    }
    let Ok((camera, report)) = cameras.single() else { return };
    let Some(size) = camera.physical_viewport_size() else { return };
    let capture = sequence.captures[sequence.index].clone();
    commands.entity(readback.entity).despawn();
    sequence.readbacks = 0;
    sequence.previous = None;
    sequence.frames = 0;
    if sequence.source == Source::Output {
        let stats = report.and_then(|r| r.stats.clone()).filter(|(mode, _)| *mode == capture.mode).map(|(_, s)| s);
        let pixels = rows(&data, size.x, size.y, 16).map(|t| [0, 1, 2, 3].map(|c| f32_at(t, c))).collect();
        let composite = capture.composite;
        sequence.done.push(Captured { capture, pixels, composite: None, stats });
        if composite {
            sequence.source = Source::Target;
            return;
        }
    } else {
        let pixels = rows(&data, size.x, size.y, 4).map(|t| [t[0], t[1], t[2], t[3]]).collect();
        sequence.done.last_mut().expect("the output was captured first").composite = Some(pixels);
        sequence.source = Source::Output;
    }
    sequence.index += 1;
    if sequence.index == sequence.captures.len() {
        let done = std::mem::take(&mut sequence.done);
        finish(&mut sequence, &mut exit, Ok(done));
    }
}

fn finish(sequence: &mut Sequence, exit: &mut MessageWriter<AppExit>, result: Result<Vec<Captured>, String>) {
    sequence.index = sequence.captures.len();
    *sequence.result.lock().unwrap() = Some(result);
    exit.write(AppExit::Success);
}

/// The texels of a readback (`bytes` each), row by row: its rows are
/// padded to 256 bytes.
fn rows(data: &[u8], width: u32, height: u32, bytes: usize) -> impl Iterator<Item = &[u8]> {
    let row = (width as usize * bytes).div_ceil(256) * 256;
    data.chunks(row).take(height as usize).flat_map(move |line| line[..width as usize * bytes].chunks_exact(bytes))
}

fn f32_at(texel: &[u8], component: usize) -> f32 {
    f32::from_le_bytes(texel[4 * component..4 * component + 4].try_into().unwrap())
}
