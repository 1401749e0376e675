//! `mrslc gbuffer`: a scene's G-buffer, and with a program everything else
//! the program binds as `mrslc render` binds it (the uniforms the scene and
//! `--set` set, every texture with all its mip levels, the samplers), as
//! files another runtime reads to render the same image: the format
//! `mrsl-gbuffer/1` of docs/gbuffer-format.md. `mrslc serve` exports
//! through [`export`] too.
//!
//! Nothing here decides what a program gets: the scene is bound by
//! [`crate::setup::bind_scene_quietly`] and the program by
//! [`crate::setup::bind_program`], and the export reads back what they
//! bound (the values from [`mrsl_runtime::Shader::uniform`]).

use crate::setup::{BoundScene, Resources, SAMPLER, bind_program, bind_scene_quietly, checker_note};
use anyhow::{Context, Result, bail};
use mrsl_lab::gpu::Gpu;
use serde::{Deserialize, Serialize};

/// The format name `gbuffer.json` carries.
pub const FORMAT: &str = "mrsl-gbuffer/1";

/// The manifest's file name.
pub const MANIFEST: &str = "gbuffer.json";

/// The most pixels `mrslc gbuffer` exports (3840x2160): the nine channels
/// of a scene take 80 bytes a pixel, 660 MB at this size.
pub const MAX_PIXELS: u64 = 3840 * 2160;

/// The longest side of an export: WebGPU's default `maxTextureDimension2D`.
pub const MAX_SIDE: u32 = 8192;

/// `gbuffer.json`: what the files are and what the program binds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format: String,
    pub scene: String,
    pub size: [u32; 2],
    /// Every channel the scene provides.
    pub channels: Vec<Channel>,
    /// The program's file name; `None` for a G-buffer alone.
    pub program: Option<String>,
    /// The uniforms the scene and `--set` set; the others keep the program's defaults.
    pub uniforms: Vec<Uniform>,
    /// Every `uniform texture2d` of the program.
    pub textures: Vec<Texture>,
    /// Every `uniform sampler` of the program.
    pub samplers: Vec<Sampler>,
    pub warnings: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    pub name: String,
    /// WebGPU's name of the texture format (`rgba32float`).
    pub format: String,
    pub file: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Uniform {
    pub name: String,
    /// mrsl's type name (`float3`, `float4[32]`).
    #[serde(rename = "type")]
    pub ty: String,
    /// The components in the order `Shader::set_uniform` takes them.
    pub values: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Texture {
    pub name: String,
    pub format: String,
    pub size: [u32; 2],
    /// Level 0 first.
    pub mips: Vec<Mip>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mip {
    pub file: String,
    pub size: [u32; 2],
}

/// A sampler as WebGPU's `GPUSamplerDescriptor` spells its values; the
/// address mode applies to u, v and w.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sampler {
    pub name: String,
    pub address_mode: String,
    pub mag_filter: String,
    pub min_filter: String,
    pub mipmap_filter: String,
}

/// An export: the manifest and the texel files it names.
pub struct Export {
    pub manifest: Manifest,
    /// `(file name, bytes)`, in the manifest's order.
    pub files: Vec<(String, Vec<u8>)>,
}

impl Export {
    /// Every file, `gbuffer.json` first.
    pub fn into_files(self) -> Result<Vec<(String, Vec<u8>)>> {
        let manifest = serde_json::to_vec_pretty(&self.manifest)?;
        Ok(std::iter::once((MANIFEST.to_string(), manifest)).chain(self.files).collect())
    }
}

/// A program to export the bindings of, and its file name for the manifest.
#[derive(Clone, Copy)]
pub struct ProgramRef<'a> {
    pub name: &'a str,
    pub program: &'a mrsl::Program,
}

/// Refuses a size with more than `max_pixels` pixels or a side over [`MAX_SIDE`].
pub fn check_size((w, h): (u32, u32), max_pixels: u64) -> Result<()> {
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE || u64::from(w) * u64::from(h) > max_pixels {
        bail!(
            "an export is at most {max_pixels} pixels, at most {MAX_SIDE} on a side: {w}x{h} is {} pixels",
            u64::from(w) * u64::from(h)
        );
    }
    Ok(())
}

/// Exports `scene` at `size` (else a scene file's size, else 960x540),
/// with `program`'s bindings if one is given; `sets` (NAME=VALUES) are set
/// after the scene's uniforms, as `render --set` sets them.
pub fn export(
    gpu: &Gpu,
    scene: &str,
    size: Option<(u32, u32)>,
    program: Option<ProgramRef>,
    sets: &[(String, Vec<f64>)],
) -> Result<Export> {
    if let Some(size) = size {
        check_size(size, MAX_PIXELS)?;
    }
    if program.is_none() && !sets.is_empty() {
        bail!("--set sets a program's uniforms: give the program too");
    }
    let mut bound = bind_scene_quietly(gpu, scene, size)?;
    check_size(bound.size, MAX_PIXELS)?;
    let mut warnings: Vec<String> =
        bound.mesh.iter().flat_map(|m| &m.warnings).map(|w| format!("{scene}: {w}")).collect();
    let mut files = vec![];
    let channels = channels(gpu, &bound, &mut files)?;
    let mut manifest = Manifest {
        format: FORMAT.into(),
        scene: scene.into(),
        size: [bound.size.0, bound.size.1],
        channels,
        program: program.map(|p| p.name.to_string()),
        uniforms: vec![],
        textures: vec![],
        samplers: vec![],
        warnings: vec![],
    };
    if let Some(p) = program {
        let rate_tile = mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
        let b = bind_program(gpu, &mut bound, scene, p.program, sets, rate_tile)?;
        warnings.extend(b.warnings.iter().map(ToString::to_string));
        warnings.extend(b.resources.checkered().iter().map(|name| checker_note(name)));
        manifest.uniforms = uniforms(&b.shader);
        manifest.textures = textures(gpu, p.program, &b.resources, &mut files)?;
        manifest.samplers = samplers(p.program)?;
    }
    manifest.warnings = warnings;
    Ok(Export { manifest, files })
}

/// Reads back every channel of the scene's G-buffer.
fn channels(gpu: &Gpu, bound: &BoundScene, files: &mut Vec<(String, Vec<u8>)>) -> Result<Vec<Channel>> {
    let mut channels = vec![];
    for (name, texture) in &bound.channels {
        let file = format!("channel.{name}.bin");
        files.push((file.clone(), gpu.read_texture(texture)?));
        channels.push(Channel { name: name.clone(), format: format_name(texture.format())?.into(), file });
    }
    Ok(channels)
}

/// The uniforms set on `shader`, in the layout's order.
fn uniforms(shader: &mrsl_runtime::Shader) -> Vec<Uniform> {
    let fields = shader.layout().uniforms.iter().flat_map(|u| &u.fields);
    fields
        .filter_map(|f| {
            let values = shader.uniform(&f.name)?;
            Some(Uniform { name: f.name.clone(), ty: f.ty.to_string(), values: values.to_vec() })
        })
        .collect()
}

/// Reads back every level of each texture the program binds.
fn textures(
    gpu: &Gpu,
    program: &mrsl::Program,
    resources: &Resources,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Result<Vec<Texture>> {
    let mut textures = vec![];
    for t in &program.layout.textures {
        let (texture, _) = resources.texture(&t.name);
        let mut mips = vec![];
        for level in 0..texture.mip_level_count() {
            let size = texture.size().mip_level_size(level, texture.dimension());
            let file = format!("texture.{}.{level}.bin", t.name);
            files.push((file.clone(), gpu.read_texture_level(texture, level)?));
            mips.push(Mip { file, size: [size.width, size.height] });
        }
        let format = format_name(texture.format()).with_context(|| format!("texture `{}`", t.name))?;
        textures.push(Texture {
            name: t.name.clone(),
            format: format.into(),
            size: [texture.width(), texture.height()],
            mips,
        });
    }
    Ok(textures)
}

/// Every sampler of the program: each gets [`SAMPLER`].
fn samplers(program: &mrsl::Program) -> Result<Vec<Sampler>> {
    let s = &SAMPLER;
    if s.address_mode_u != s.address_mode_v || s.address_mode_u != s.address_mode_w {
        bail!("the format has one address mode for u, v and w");
    }
    let address_mode = match s.address_mode_u {
        wgpu::AddressMode::Repeat => "repeat",
        wgpu::AddressMode::MirrorRepeat => "mirror-repeat",
        wgpu::AddressMode::ClampToEdge => "clamp-to-edge",
        other => bail!("WebGPU has no address mode {other:?}"),
    };
    let filter = |f: wgpu::FilterMode| match f {
        wgpu::FilterMode::Linear => "linear",
        wgpu::FilterMode::Nearest => "nearest",
    };
    let mipmap_filter = match s.mipmap_filter {
        wgpu::MipmapFilterMode::Linear => "linear",
        wgpu::MipmapFilterMode::Nearest => "nearest",
    };
    let sampler = |name: &str| Sampler {
        name: name.into(),
        address_mode: address_mode.into(),
        mag_filter: filter(s.mag_filter).into(),
        min_filter: filter(s.min_filter).into(),
        mipmap_filter: mipmap_filter.into(),
    };
    Ok(program.layout.samplers.iter().map(|s| sampler(&s.name)).collect())
}

/// WebGPU's name of a format the lab binds: the layout's formats by their
/// names, and the two the lab's textures add.
pub fn format_name(format: wgpu::TextureFormat) -> Result<&'static str> {
    if let Some(f) = mrsl_runtime::gpu::layout_format(format) {
        return Ok(f.name());
    }
    Ok(match format {
        wgpu::TextureFormat::Rg16Float => "rg16float",
        wgpu::TextureFormat::Rgba8UnormSrgb => "rgba8unorm-srgb",
        other => bail!("no name for texture format {other:?} in {FORMAT}"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_past_the_limits_are_refused_with_both_limits() {
        check_size((3840, 2160), MAX_PIXELS).unwrap();
        check_size((8192, 1), MAX_PIXELS).unwrap();
        let e = check_size((3841, 2160), MAX_PIXELS).unwrap_err().to_string();
        assert_eq!(e, "an export is at most 8294400 pixels, at most 8192 on a side: 3841x2160 is 8296560 pixels");
        assert!(check_size((8193, 1), MAX_PIXELS).is_err());
        assert!(check_size((0, 10), MAX_PIXELS).is_err());
        assert!(check_size((1921, 1080), 1920 * 1080).is_err());
    }

    #[test]
    fn formats_have_webgpu_names() {
        assert_eq!(format_name(wgpu::TextureFormat::Rgba32Float).unwrap(), "rgba32float");
        assert_eq!(format_name(wgpu::TextureFormat::R32Uint).unwrap(), "r32uint");
        assert_eq!(format_name(wgpu::TextureFormat::Rgba8UnormSrgb).unwrap(), "rgba8unorm-srgb");
        assert_eq!(format_name(wgpu::TextureFormat::Rg16Float).unwrap(), "rg16float");
        assert!(format_name(wgpu::TextureFormat::Depth24Plus).is_err());
    }

    #[test]
    fn the_sampler_is_described_as_webgpu_spells_it() {
        let source = "in float2 uv;\nuniform texture2d t;\nuniform sampler s;\nfine out float4 c = sample(t, s, uv);\n";
        let program = mrsl::compile(source, &mrsl::Options::for_modes(&[])).unwrap();
        let described = samplers(&program).unwrap();
        let expected = Sampler {
            name: "s".into(),
            address_mode: "repeat".into(),
            mag_filter: "linear".into(),
            min_filter: "linear".into(),
            mipmap_filter: "linear".into(),
        };
        assert_eq!(described, [expected]);
    }
}
