//! Binding a program to a scene, checked before anything renders: a
//! channel the scene lacks, or one whose scalar type the scene's texture
//! cannot give, is a diagnostic at the program's `in` declaration (E0801,
//! E0802), with what the scene provides; a uniform without a default that
//! neither the scene nor `--set` gives is one at its `uniform` declaration
//! (E0803). The runtime refuses the same bindings later with a typed error;
//! this says it in the program's terms. `render` checks before it renders;
//! `check --scene` binds and checks without rendering ([`on_scene`]).

use mrsl::{Diagnostic, Label};
use mrsl_abi::{Layout, Scalar};

/// The scene's channels that the program's channels cannot read, as
/// rendered diagnostics (`Err`), or `Ok` when every channel can be bound.
/// `file` names the program in them, `scene` the scene.
pub fn check_channels(
    file: &str,
    source: &str,
    layout: &Layout,
    scene: &str,
    channels: &[(String, wgpu::Texture)],
) -> Result<(), String> {
    rendered(file, source, channel_diagnostics(source, layout, scene, channels))
}

/// The program's uniforms that have no default and were not set (by the
/// scene or `--set`), as rendered diagnostics (`Err`).
pub fn check_uniforms(file: &str, source: &str, shader: &mrsl_runtime::Shader, scene: &str) -> Result<(), String> {
    rendered(file, source, uniform_diagnostics(source, shader, scene))
}

fn rendered(file: &str, source: &str, diagnostics: Vec<Diagnostic>) -> Result<(), String> {
    if diagnostics.is_empty() { Ok(()) } else { Err(mrsl::render_all(&diagnostics, file, source)) }
}

/// `mrslc check --scene`: binds `source`'s program to `scene` as `render`
/// does (the scene's uniforms, then `sets`), without rendering, and returns
/// E0801-E0803 for what the binding lacks, and the binding's warnings. The
/// scene is built at a small size: what it provides does not depend on it.
pub fn on_scene(
    source: &str,
    scene: &str,
    sets: &[(String, Vec<f64>)],
) -> anyhow::Result<(Vec<Diagnostic>, Vec<String>)> {
    let options = mrsl::Options::for_modes(&[mrsl::Mode::Reference]);
    let program = mrsl::compile(source, &options)
        .map_err(|_| anyhow::anyhow!("the program does not compile for the reference mode"))?;
    let gpu = mrsl_lab::gpu::Gpu::new()?;
    let mut bound = crate::setup::bind_scene_quietly(&gpu, scene, Some((64, 64)))?;
    let diagnostics = channel_diagnostics(source, &program.layout, scene, &bound.channels);
    if !diagnostics.is_empty() {
        return Ok((diagnostics, vec![]));
    }
    let tile = mrsl_abi::shading_rate::DEFAULT_RATE_TILE;
    let bound = crate::setup::bind_program(&gpu, &mut bound, scene, &program, sets, tile)?;
    Ok((uniform_diagnostics(source, &bound.shader, scene), bound.warnings))
}

fn channel_diagnostics(
    source: &str,
    layout: &Layout,
    scene: &str,
    channels: &[(String, wgpu::Texture)],
) -> Vec<Diagnostic> {
    let provided: Vec<(&str, String)> =
        channels.iter().map(|(name, texture)| (name.as_str(), readable_as(texture.format()))).collect();
    let listing = provided.iter().map(|(name, ty)| format!("{name} ({ty})")).collect::<Vec<_>>().join(", ");
    let mut diagnostics = vec![];
    // Engine-format channels are decoded from what the engine stores: the runtime checks those.
    for channel in layout.channels.iter().filter(|c| c.decode.is_none()) {
        let Some(span) = mrsl::declaration_span(source, &channel.name) else { continue };
        let declared = channel.ty.to_string();
        let found = channels.iter().find(|(name, _)| *name == channel.name);
        let d = match found {
            None => {
                let mut d =
                    Diagnostic::error("E0801", format!("the scene `{scene}` has no channel `{}`", channel.name))
                        .with_label(Label::primary(span, format!("`in {declared} {}` is read here", channel.name)))
                        .with_note(format!("the scene provides: {listing}"));
                if let Some(close) = closest(&channel.name, provided.iter().map(|(n, _)| *n)) {
                    d = d.with_note(format!("help: did you mean `{close}`?"));
                }
                d
            }
            Some((_, texture)) if scalar_of(texture.format()) != Some(channel.ty.scalar()) => {
                let theirs = type_of(texture.format());
                Diagnostic::error(
                    "E0802",
                    format!("channel `{}` is {theirs} in the scene `{scene}`, declared `{declared}`", channel.name),
                )
                .with_label(Label::primary(span, format!("the scene's texture is {:?}", texture.format())))
                .with_note(format!(
                    "help: declare `in {} {};`",
                    suggested(&theirs, &declared),
                    channel.name
                ))
            }
            Some(_) => continue,
        };
        diagnostics.push(d);
    }
    diagnostics
}

fn uniform_diagnostics(source: &str, shader: &mrsl_runtime::Shader, scene: &str) -> Vec<Diagnostic> {
    let fields = shader.layout().uniforms.iter().flat_map(|block| &block.fields);
    let unset = fields.filter(|f| f.default.is_none() && shader.uniform(&f.name).is_none());
    let mut diagnostics = vec![];
    for field in unset {
        let Some(span) = mrsl::declaration_span(source, &field.name) else { continue };
        let (name, ty, count) = (&field.name, &field.ty, field.ty.components());
        let default = match ty {
            mrsl_abi::ValueType::Array(element, n) => {
                format!("or give it one: `uniform {element} {name}[{n}] = {{ ... }};` ({n} elements)")
            }
            _ => format!("or give it one: `uniform {ty} {name} = ...;`"),
        };
        diagnostics.push(
            Diagnostic::error("E0803", format!("uniform `{name}` has no value"))
                .with_label(Label::primary(span, format!("no default, and the scene `{scene}` does not set it")))
                .with_note(format!("help: pass `--set {name}=V1,V2,...` ({count} numbers for a {ty}); {default}")),
        );
    }
    diagnostics
}

/// The mrsl scalar a texture of `format` gives a kernel.
fn scalar_of(format: wgpu::TextureFormat) -> Option<Scalar> {
    match format.sample_type(None, None)? {
        wgpu::TextureSampleType::Float { .. } | wgpu::TextureSampleType::Depth => Some(Scalar::Float),
        wgpu::TextureSampleType::Uint => Some(Scalar::Uint),
        wgpu::TextureSampleType::Sint => Some(Scalar::Int),
    }
}

/// The mrsl type a texture of `format` holds (`float3` for the three of
/// four components a colour target stores are written `float4` here).
fn type_of(format: wgpu::TextureFormat) -> String {
    let scalar = scalar_of(format).map_or("?", Scalar::name);
    match format.components() {
        1 => scalar.to_string(),
        n => format!("{scalar}{n}"),
    }
}

/// What a program may declare over a texture of `format`: its type, and
/// for four components also three (a colour target stores `float3` in four).
pub(crate) fn readable_as(format: wgpu::TextureFormat) -> String {
    let ty = type_of(format);
    match ty.strip_suffix('4') {
        Some(scalar) => format!("{scalar}3 or {ty}"),
        None => ty,
    }
}

/// The declaration to write: the scene's scalar with the declared
/// components (`float3` declared over a `uint` texture: `uint`).
fn suggested(theirs: &str, declared: &str) -> String {
    let scalar = theirs.trim_end_matches(|c: char| c.is_ascii_digit());
    let components = declared.trim_start_matches(|c: char| c.is_ascii_alphabetic());
    let theirs_components = theirs.trim_start_matches(|c: char| c.is_ascii_alphabetic());
    match (components, theirs_components) {
        ("", _) | (_, "") => theirs.to_string(),
        (n, _) => format!("{scalar}{n}"),
    }
}

/// The closest of `candidates` to `name` within a third of its length in
/// edits (strsim's Levenshtein distance), ties to the first in order.
fn closest<'s>(name: &str, candidates: impl Iterator<Item = &'s str>) -> Option<&'s str> {
    let limit = (name.len() / 3).max(1);
    candidates
        .map(|c| (strsim::levenshtein(name, c), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_keep_the_declared_shape_and_the_scenes_scalar() {
        assert_eq!(suggested("uint", "float"), "uint");
        assert_eq!(suggested("float4", "uint3"), "float3");
        assert_eq!(closest("abledo", ["normal", "albedo", "depth"].into_iter()), Some("albedo"));
        assert_eq!(closest("xyz", ["normal", "albedo"].into_iter()), None);
        assert_eq!(type_of(wgpu::TextureFormat::R32Uint), "uint");
        assert_eq!(type_of(wgpu::TextureFormat::Rgba32Float), "float4");
        assert_eq!(readable_as(wgpu::TextureFormat::Rgba16Float), "float3 or float4");
    }
}
