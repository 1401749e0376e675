//! What every command sets up before it renders: the program compiled for
//! the modes that run, the scene bound (its G-buffer, mesh scene, light rig
//! and scene file), and the resources a program binds besides the G-buffer
//! (outputs, textures, samplers, the shading-rate image).

use anyhow::{Result, anyhow, bail};
use mrsl::Options;
use mrsl_abi::ChannelAccess;
use mrsl_lab::camera_path::CameraPath;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::mesh_scene::MeshScene;
use mrsl_lab::scene::Scene;
use mrsl_lab::scene_file::SceneFile;
use mrsl_runtime::{Bindings, Mode, Shader};
use std::path::Path;

/// Image size when neither `--size` nor a scene file gives one.
pub const DEFAULT_SIZE: (u32, u32) = (960, 540);

/// The built-in demo program (examples/demo.mrsl).
pub const DEMO_PROGRAM: &str = include_str!("../../examples/demo.mrsl");

/// The default workload of `bench` (examples/sponza_lights.mrsl).
pub const WORKLOAD_PROGRAM: &str = include_str!("../../examples/sponza_lights.mrsl");

/// Reads and compiles the program at `path`, or the built-in `(name,
/// source)`, to the kernels of `modes` alone; returns its name for messages
/// and the program, or the diagnostics rendered.
pub fn compile_program(path: Option<&Path>, builtin: (&str, &str), modes: &[Mode]) -> Result<(String, mrsl::Program)> {
    let (name, source) = read_program(path, builtin)?;
    let program = compile(&name, &source, Options::for_modes(modes))?;
    Ok((name, program))
}

/// A program compiled for the device it runs on, and that device.
pub struct DeviceProgram {
    /// The program's name, for messages.
    pub name: String,
    /// Its source, for diagnostics found when binding it.
    pub source: String,
    pub program: mrsl::Program,
    pub gpu: Gpu,
}

/// Reads and compiles the program as [`compile_program`] does, and makes the
/// device. The kernels read the G-buffer through read-only storage bindings
/// (`Options::storage_channels`), for which llvmpipe charges about a third
/// of a sampled read, where the adapter grants the storage textures that
/// adds to every kernel (one per channel) on top of WebGPU's default limit:
/// so a mode that the default limit refuses with sampled channels is refused
/// with storage channels too. Where it does not, they read the channels
/// sampled, and a note says so. Likewise the hierarchical kernel packs its
/// records four words to a texel (`Options::packed_records`) where the
/// adapter allows read-write storage access to `Rgba32Uint`, for which
/// llvmpipe charges a load per texel rather than per word. The images are
/// the same either way.
pub fn compile_for_device(path: Option<&Path>, builtin: (&str, &str), modes: &[Mode]) -> Result<DeviceProgram> {
    let (name, source) = read_program(path, builtin)?;
    let wished = Options { storage_channels: true, packed_records: true, ..Options::for_modes(modes) };
    let program = compile(&name, &source, wished.clone())?;
    let channels = program.layout.channels.iter().filter(|c| c.access == ChannelAccess::Storage).count() as u32;
    let wanted = wgpu::Limits::default().max_storage_textures_per_shader_stage + channels;
    let gpu = Gpu::with_packed_records(wanted)?;
    let granted = gpu.device.limits().max_storage_textures_per_shader_stage;
    let options = Options { storage_channels: granted >= wanted, packed_records: gpu.packs_records, ..wished };
    if !options.storage_channels {
        eprintln!(
            "note: {} allows {granted} storage textures per shader stage, fewer than the {wanted} that reading the \
             G-buffer's {channels} channels through storage bindings takes: the kernels read them sampled",
            gpu.adapter_info.name
        );
    }
    if !options.packed_records && modes.contains(&Mode::Hierarchical) {
        eprintln!(
            "note: {} allows no read-write storage access to Rgba32Uint: the hierarchical kernel keeps a texel per \
             word of its records",
            gpu.adapter_info.name
        );
    }
    if options.storage_channels && options.packed_records {
        return Ok(DeviceProgram { name, source, program, gpu });
    }
    let program = compile(&name, &source, options)?;
    Ok(DeviceProgram { name, source, program, gpu })
}

/// The program at `path`, or the built-in `(name, source)`: its name for messages and its source.
fn read_program(path: Option<&Path>, builtin: (&str, &str)) -> Result<(String, String)> {
    Ok(match path {
        Some(path) => (path.display().to_string(), crate::read_source(path)?),
        None => (format!("{} (built in)", builtin.0), builtin.1.to_string()),
    })
}

/// `source` compiled with `options`, its diagnostics naming the file `name`.
fn compile(name: &str, source: &str, options: Options) -> Result<mrsl::Program> {
    let options = Options { file_name: name.to_string(), ..options };
    mrsl::compile(source, &options).map_err(|d| anyhow!(mrsl::render_all(&d, name, source)))
}

/// A scene ready to bind: its G-buffer textures, the image size, the
/// mesh scene (camera, light rig, shadow map) for scenes made of a mesh, and
/// the scene file, if any (its uniforms and images).
pub struct BoundScene {
    pub channels: Vec<(String, wgpu::Texture)>,
    /// The light rig of a scene made on the CPU (`Scene::cpu_rig`: the demo's).
    pub rig: Option<mrsl_lab::rig::LightRig>,
    pub size: (u32, u32),
    pub mesh: Option<MeshScene>,
    /// The camera path of `--frames`, if the scene has one.
    pub path: Option<CameraPath>,
    pub file: Option<SceneFile>,
}

impl BoundScene {
    /// Sets the uniforms the scene provides (the mesh scene's rig and
    /// camera, then the scene file's), by name and type, and renders the
    /// shadow map if the program samples `shadow_map`. Returns the textures
    /// to bind by name (the shadow map and the scene file's images) and
    /// what could not be set ([`Prepared::warnings`]).
    pub fn prepare(&mut self, gpu: &Gpu, shader: &mut Shader) -> Result<Prepared> {
        let mut textures = vec![];
        let mut warnings = vec![];
        if let Some(mesh) = &mut self.mesh {
            let applied = mesh.set_uniforms(shader, &mesh.camera.clone())?;
            if applied.set.iter().any(|name| name == "shadow_map") {
                textures.push(("shadow_map".to_string(), mesh.shadow_map(gpu)?.clone()));
            }
            warnings.extend(applied.warnings.iter().map(ToString::to_string));
        }
        if let Some(rig) = &self.rig {
            warnings.extend(rig.apply_point_lights(shader)?.warnings.iter().map(ToString::to_string));
        }
        if let Some(file) = &self.file {
            let bound = file.bind(gpu, shader)?;
            warnings.extend(bound.applied.warnings.iter().map(ToString::to_string));
            warnings.extend(bound.applied.ignored.iter().map(ToString::to_string));
            textures.extend(bound.textures);
        }
        Ok(Prepared { textures, warnings })
    }
}

/// What [`BoundScene::prepare`] provides besides uniform values.
pub struct Prepared {
    pub textures: Vec<(String, wgpu::Texture)>,
    /// What the scene could not set, rendered: names the program declares
    /// with another type, names a scene file sets that it does not declare.
    pub warnings: Vec<String>,
}

impl Prepared {
    /// Prints the warnings; returns the textures.
    pub fn warn(self) -> Vec<(String, wgpu::Texture)> {
        for warning in &self.warnings {
            eprintln!("warning: {warning}");
        }
        self.textures
    }
}

/// A program bound over a scene as every command binds it.
pub struct BoundProgram {
    pub shader: Shader,
    pub resources: Resources,
    /// [`Prepared::warnings`].
    pub warnings: Vec<String>,
}

/// Makes `program`'s shader over `scene` (called `scene_name` in errors):
/// the scene's uniforms ([`BoundScene::prepare`]), then `sets` (the
/// command line's `--set`), then the [`Resources`].
pub fn bind_program(
    gpu: &Gpu,
    scene: &mut BoundScene,
    scene_name: &str,
    program: &mrsl::Program,
    sets: &[(String, Vec<f64>)],
    rate_tile: u32,
) -> Result<BoundProgram> {
    let mut shader = Shader::new(&gpu.device, program)?;
    let prepared = scene.prepare(gpu, &mut shader).map_err(|e| anyhow!("{scene_name}: {e}"))?;
    for (name, values) in sets {
        shader.set_uniform(name, values)?;
    }
    let resources = Resources::new(gpu, program, scene.size, prepared.textures, rate_tile)?;
    Ok(BoundProgram { shader, resources, warnings: prepared.warnings })
}

/// `--scene`: a built-in scene's name, or a `.toml` scene file (see
/// docs/scenes.md). A scene file's `size` applies unless `--size` was given.
/// What loading a mesh skipped or could not use is printed as warnings.
pub fn bind_scene(gpu: &Gpu, scene: &str, size: Option<(u32, u32)>) -> Result<BoundScene> {
    let bound = bind_scene_quietly(gpu, scene, size)?;
    for warning in bound.mesh.iter().flat_map(|m| &m.warnings) {
        eprintln!("warning: {scene}: {warning}");
    }
    Ok(bound)
}

/// [`bind_scene`] without printing: what loading a mesh skipped is in the
/// mesh scene's `warnings`.
pub fn bind_scene_quietly(gpu: &Gpu, scene: &str, size: Option<(u32, u32)>) -> Result<BoundScene> {
    if let Some(builtin) = Scene::parse(scene) {
        let size = size.unwrap_or(DEFAULT_SIZE);
        let mesh = builtin.mesh_scene(gpu)?;
        let channels = match &mesh {
            Some(m) => m.gbuffer(gpu, &m.camera, size)?,
            None => builtin.textures_on(gpu, size.0, size.1)?,
        };
        let rig = if mesh.is_none() { builtin.cpu_rig() } else { None };
        return Ok(BoundScene { channels, size, mesh, rig, path: builtin.camera_path(), file: None });
    }
    let path = Path::new(scene);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        let file = SceneFile::load(path)?;
        // The command line's --size wins over the file's.
        let size = size.or(file.size).unwrap_or(DEFAULT_SIZE);
        let mesh = file.mesh_scene(gpu, size)?;
        let channels = mesh.gbuffer(gpu, &mesh.camera, size).map_err(|e| anyhow!("{scene}: {e}"))?;
        return Ok(BoundScene { channels, size, mesh: Some(mesh), rig: None, path: file.path(), file: Some(file) });
    }
    bail!("unknown scene `{scene}` (expected {}, or a .toml scene file)", Scene::NAMES.join(", "))
}

/// What a program binds besides the G-buffer: its outputs, and for each of
/// its textures the scene's texture of that name (the shadow map, a scene
/// file's image), else a procedural checker; every sampler is
/// [`SAMPLER`].
pub struct Resources {
    pub size: (u32, u32),
    pub outputs: Vec<(String, wgpu::Texture)>,
    checker: (wgpu::Texture, wgpu::TextureView),
    textures: Vec<(String, wgpu::Texture, wgpu::TextureView)>,
    /// The program's textures that get the checker.
    checkered: Vec<String>,
    sampler: wgpu::Sampler,
    /// The rate-image mode's shading-rate image (full rate until a rate source writes it).
    pub shading_rate: wgpu::Texture,
}

impl Resources {
    pub fn new(
        gpu: &Gpu,
        program: &mrsl::Program,
        size: (u32, u32),
        textures: Vec<(String, wgpu::Texture)>,
        rate_tile: u32,
    ) -> Result<Resources> {
        let shading_rate = mrsl_runtime::rate_source::create_rate_image(&gpu.device, size, rate_tile)?;
        let outputs = program
            .layout
            .outputs
            .iter()
            .map(|o| (o.name.clone(), gpu.output_texture(&o.name, size, mrsl_runtime::wgpu_format(o.format))))
            .collect();
        let textures: Vec<(String, wgpu::Texture, wgpu::TextureView)> = textures
            .into_iter()
            .map(|(name, t)| {
                let view = t.create_view(&Default::default());
                (name, t, view)
            })
            .collect();
        let checkered = program
            .layout
            .textures
            .iter()
            .filter(|t| !textures.iter().any(|(name, ..)| *name == t.name))
            .map(|t| t.name.clone())
            .collect();
        let checker = checker_texture(gpu);
        let checker_view = checker.create_view(&Default::default());
        Ok(Resources {
            size,
            outputs,
            checker: (checker, checker_view),
            textures,
            checkered,
            sampler: gpu.device.create_sampler(&SAMPLER),
            shading_rate,
        })
    }

    /// The program's textures that get the procedural checker.
    pub fn checkered(&self) -> &[String] {
        &self.checkered
    }

    /// Says which textures get the procedural checker, and how to give them an image.
    pub fn note_fallbacks(&self) {
        for name in &self.checkered {
            eprintln!("note: {}", checker_note(name));
        }
    }

    /// The texture and view bound to the program's texture `name`: the
    /// scene's of that name, else the checker.
    pub fn texture(&self, name: &str) -> (&wgpu::Texture, &wgpu::TextureView) {
        let (texture, view) = &self.checker;
        self.textures.iter().find(|(n, ..)| n == name).map_or((texture, view), |(_, t, v)| (t, v))
    }

    /// The bindings of `program` over the G-buffer `channels`.
    pub fn bindings<'a>(&'a self, program: &mrsl::Program, channels: &'a [(String, wgpu::Texture)]) -> Bindings<'a> {
        let mut bindings = Bindings { size: self.size, ..Default::default() };
        for (name, texture) in channels {
            bindings.channels.insert(name.clone(), texture);
        }
        for t in &program.layout.textures {
            bindings.textures.insert(t.name.clone(), self.texture(&t.name).1);
        }
        for s in &program.layout.samplers {
            bindings.samplers.insert(s.name.clone(), &self.sampler);
        }
        for (name, texture) in &self.outputs {
            bindings.outputs.insert(name.clone(), texture);
        }
        bindings.shading_rate = Some(&self.shading_rate);
        bindings
    }
}

/// What a texture that gets the checker is told.
pub fn checker_note(name: &str) -> String {
    format!(
        "texture `{name}` gets a procedural 64x64 checker (a scene file binds an image to it: \
         `{name} = \"FILE.png\"` under [uniforms])"
    )
}

/// The sampler every `sampler` uniform of a program gets: linear, repeating.
pub const SAMPLER: wgpu::SamplerDescriptor<'static> = wgpu::SamplerDescriptor {
    label: Some("mrsl linear sampler"),
    address_mode_u: wgpu::AddressMode::Repeat,
    address_mode_v: wgpu::AddressMode::Repeat,
    address_mode_w: wgpu::AddressMode::Repeat,
    mag_filter: wgpu::FilterMode::Linear,
    min_filter: wgpu::FilterMode::Linear,
    mipmap_filter: wgpu::MipmapFilterMode::Linear,
    lod_min_clamp: 0.0,
    lod_max_clamp: 32.0,
    compare: None,
    anisotropy_clamp: 1,
    border_color: None,
};

fn checker_texture(gpu: &Gpu) -> wgpu::Texture {
    let n = 64u32;
    let mut data = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let odd = ((x / 8) + (y / 8)) % 2 == 1;
            let (r, g, b) = if odd { (200, 80, 60) } else { (235, 225, 200) };
            data.extend_from_slice(&[r, g, b, 255]);
        }
    }
    gpu.texture_with_data("checker", (n, n), wgpu::TextureFormat::Rgba8UnormSrgb, &data)
}
