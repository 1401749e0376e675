//! What an engine binds, checked against the program's layout and the
//! mode's plan before anything is recorded: every mismatch is a typed
//! [`Error`] naming the binding at fault.

use crate::bindings::Bindings;
use crate::error::Error;
use crate::gpu::{layout_format, wgpu_format};
use mrsl_abi::geometry::MAX_SIDE;
use mrsl_abi::plan::{MAX_WORKGROUPS_PER_DIMENSION, ModePlan, TooLarge, Workgroups};
use mrsl_abi::{Channel, ChannelAccess, Decode, Layout, Output, Plan, ResourceId, SampleType, TextureFormat};

/// The image size: not empty, within [`MAX_SIDE`], and within the limits of
/// every resource the mode makes and every indirect dispatch it records.
pub(crate) fn size(plan: &Plan, mode: &ModePlan, size: (u32, u32)) -> Result<(), Error> {
    let (width, height) = size;
    if width == 0 || height == 0 {
        return Err(Error::BadSize { width, height, reason: "it is empty".into() });
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(Error::BadSize { width, height, reason: format!("the largest supported side is {MAX_SIDE}") });
    }
    let too_large = |TooLarge(reason)| Error::BadSize { width, height, reason };
    for desc in mode.resources().into_iter().filter_map(|id| plan.resource(id)) {
        desc.shape.check(&desc.what, size).map_err(too_large)?;
    }
    for dispatch in mode.passes().flat_map(|p| &p.dispatches) {
        if let Workgroups::Indirect { at_most: Some(extent), per_workgroup, .. } = dispatch.workgroups {
            let most = u64::from(MAX_WORKGROUPS_PER_DIMENSION);
            if extent.count(size).div_ceil(u64::from(per_workgroup)) > most {
                let reason = format!("`{}` would need more than {most} workgroups", dispatch.entry);
                return Err(Error::BadSize { width, height, reason });
            }
        }
    }
    Ok(())
}

/// The engine's resources: every channel, texture, sampler and output the
/// layout declares, of the right format, usage, shape and size, and the
/// shading-rate image where the mode binds one.
pub(crate) fn bindings(layout: &Layout, mode: &ModePlan, bindings: &Bindings, rate_tile: u32) -> Result<(), Error> {
    if mode.resources().contains(&ResourceId::ShadingRate) {
        shading_rate(bindings, rate_tile)?;
    }
    for ch in &layout.channels {
        let t = bindings.channels.get(&ch.name).ok_or_else(|| Error::MissingChannel(ch.name.clone()))?;
        channel(ch, t)?;
        texture_size("G-buffer channel", &ch.name, t, bindings.size)?;
    }
    for t in &layout.textures {
        let view = bindings.textures.get(&t.name).ok_or_else(|| Error::MissingTexture(t.name.clone()))?;
        if !view.texture().usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return Err(Error::TextureUsage(t.name.clone()));
        }
    }
    for s in &layout.samplers {
        if !bindings.samplers.contains_key(&s.name) {
            return Err(Error::MissingSampler(s.name.clone()));
        }
    }
    for o in &layout.outputs {
        let t = bindings.outputs.get(&o.name).ok_or_else(|| Error::MissingOutput(o.name.clone()))?;
        output(o, t)?;
        texture_size("output", &o.name, t, bindings.size)?;
    }
    Ok(())
}

/// A G-buffer channel's texture: a depth format exactly when the channel is
/// rebuilt from depth; else, read sampled, a format of the channel's sample
/// type with enough components (of what its encoding stores) and
/// `TEXTURE_BINDING`, or read through a storage binding, exactly the
/// layout's format and `STORAGE_BINDING`; a single-sample 2D texture of one
/// layer.
fn channel(ch: &Channel, t: &wgpu::Texture) -> Result<(), Error> {
    let (found, expected) = (t.format(), wgpu_format(ch.format));
    let from_depth = matches!(ch.decode, Some(Decode::Depth { .. }));
    if found.is_depth_stencil_format() != from_depth {
        let (channel, ty) = (ch.name.clone(), ch.ty.to_string());
        return Err(if from_depth {
            Error::ChannelNotDepth { channel, found }
        } else {
            Error::ChannelDepthFormat { channel, ty, expected, found }
        });
    }
    if from_depth {
        if !found.has_depth_aspect() {
            return Err(Error::ChannelNotDepth { channel: ch.name.clone(), found });
        }
        return usage_and_shape(ch, t);
    }
    if ch.access == ChannelAccess::Storage {
        if found != expected {
            return Err(Error::ChannelStorageFormat { channel: ch.name.clone(), expected, found });
        }
        return usage_and_shape(ch, t);
    }
    let need = match &ch.decode {
        Some(decode) => decode.stored_components(&ch.ty),
        None => ch.ty.components().min(4),
    };
    let components = u32::from(found.components());
    let fits = matches!(
        (ch.sample_type, found.sample_type(None, None)),
        (SampleType::Uint, Some(wgpu::TextureSampleType::Uint))
            | (SampleType::Sint, Some(wgpu::TextureSampleType::Sint))
            | (SampleType::UnfilterableFloat, Some(wgpu::TextureSampleType::Float { .. }))
    ) && components >= need
        && (need != 3 || components == 4);
    if !fits {
        let (channel, ty, accepted) = (ch.name.clone(), ch.ty.to_string(), accepted_formats(ch));
        return Err(Error::ChannelFormat { channel, ty, expected, accepted, found });
    }
    usage_and_shape(ch, t)
}

/// A channel's texture has the usage its binding needs (`TEXTURE_BINDING`,
/// or `STORAGE_BINDING` for a storage channel) and is a single-sample 2D
/// texture of one layer.
fn usage_and_shape(ch: &Channel, t: &wgpu::Texture) -> Result<(), Error> {
    let (usage, missing) = match ch.access {
        ChannelAccess::Sampled => (wgpu::TextureUsages::TEXTURE_BINDING, "TEXTURE_BINDING"),
        ChannelAccess::Storage => (wgpu::TextureUsages::STORAGE_BINDING, "STORAGE_BINDING"),
    };
    if !t.usage().contains(usage) {
        return Err(Error::ChannelUsage { channel: ch.name.clone(), missing });
    }
    match shape(t, false) {
        Some(found) => Err(Error::TextureShape { what: "G-buffer channel", name: ch.name.clone(), found }),
        None => Ok(()),
    }
}

/// The formats a channel accepts besides the layout's, in words: the rule of
/// docs/runtime.md, section 4 (the sample type of the channel's type, at
/// least its components, exactly 4 for a 3-component type), with examples.
pub(crate) fn accepted_formats(ch: &Channel) -> String {
    let kind = match ch.sample_type {
        SampleType::UnfilterableFloat => "colour format read as float (float, unorm or snorm)",
        SampleType::Uint => "uint colour format",
        SampleType::Sint => "sint colour format",
        SampleType::Depth => return "a depth format (Depth32Float, Depth24Plus, Depth16Unorm, ...)".into(),
    };
    let examples = |float: &str, uint: &str, sint: &str| match ch.sample_type {
        SampleType::Uint => uint.to_string(),
        SampleType::Sint => sint.to_string(),
        _ => float.to_string(),
    };
    // An encoded channel's texture holds what the engine stores (two octahedral components, say).
    let stored = ch.decode.as_ref().map_or(ch.ty.components(), |d| d.stored_components(&ch.ty));
    match stored.min(4) {
        1 => format!(
            "any other {kind} ({})",
            examples(
                "R16Float, Rg32Float, Rgba8Unorm, ...",
                "R8Uint, R16Uint, Rgba32Uint, ...",
                "R8Sint, R16Sint, ..."
            )
        ),
        2 => format!(
            "another {kind} with at least 2 components ({})",
            examples("Rg16Float, Rgba16Float, Rgba8Unorm, ...", "Rg16Uint, Rgba8Uint, ...", "Rg16Sint, Rgba8Sint, ...")
        ),
        n => format!(
            "another {kind} with exactly 4 components ({}){}",
            examples("Rgba16Float, Rgba8Unorm, Rgba8Snorm, ...", "Rgba16Uint, Rgba8Uint", "Rgba16Sint, Rgba8Sint"),
            if n == 3 { "; 3-component formats such as Rg11b10Ufloat are not accepted" } else { "" }
        ),
    }
}

/// An output's texture: the layout's format (with a hint to declare its
/// own, where the language can), `STORAGE_BINDING`, a single-sample 2D
/// texture of one layer and one mip level.
fn output(o: &Output, t: &wgpu::Texture) -> Result<(), Error> {
    let (expected, found) = (wgpu_format(o.format), t.format());
    if found != expected {
        return Err(Error::OutputFormat { name: o.name.clone(), expected, found, hint: output_format_hint(o, found) });
    }
    if !t.usage().contains(wgpu::TextureUsages::STORAGE_BINDING) {
        return Err(Error::OutputUsage(o.name.clone()));
    }
    match shape(t, true) {
        Some(found) => Err(Error::TextureShape { what: "output", name: o.name.clone(), found }),
        None => Ok(()),
    }
}

/// How to fix an output bound with a texture of format `found`: declare the
/// output with `@format` where the language can store its type in `found`,
/// else create the texture in the layout's format.
pub(crate) fn output_format_hint(o: &Output, found: wgpu::TextureFormat) -> String {
    let declarable = TextureFormat::for_output(&o.ty);
    match layout_format(found).filter(|f| declarable.contains(f)) {
        Some(f) => format!(
            "to write a {found:?} texture, declare the output `@format({f}) fine out {} {}` and compile the program again",
            o.ty, o.name
        ),
        None => format!(
            "create it as {:?} (`mrsl_runtime::wgpu_format` of the layout's format); `@format(..)` can declare a `{}` output as {}",
            wgpu_format(o.format),
            o.ty,
            declarable.iter().map(|f| f.name()).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// Why `t` is not the single-sample 2D texture of one layer that a binding
/// takes (of one mip level too for a `storage` binding), if it is not.
fn shape(t: &wgpu::Texture, storage: bool) -> Option<String> {
    if t.dimension() != wgpu::TextureDimension::D2 {
        return Some(format!("a {:?} texture", t.dimension()));
    }
    if t.depth_or_array_layers() != 1 {
        return Some(format!("a 2D texture of {} layers", t.depth_or_array_layers()));
    }
    if t.sample_count() != 1 {
        return Some(format!(
            "a multisampled texture ({} samples): resolve it into a single-sample one",
            t.sample_count()
        ));
    }
    if storage && t.mip_level_count() != 1 {
        return Some(format!(
            "a texture of {} mip levels, and a storage texture binding takes one",
            t.mip_level_count()
        ));
    }
    None
}

/// A channel's or output's texture is exactly the image size.
fn texture_size(what: &'static str, name: &str, t: &wgpu::Texture, (width, height): (u32, u32)) -> Result<(), Error> {
    if (t.width(), t.height()) != (width, height) {
        let (found_width, found_height) = (t.width(), t.height());
        return Err(Error::SizeMismatch { what, name: name.into(), width, height, found_width, found_height });
    }
    Ok(())
}

/// The shading-rate image of the rate-image mode: bound, an unsigned-integer
/// texture, one texel per tile.
fn shading_rate(bindings: &Bindings, tile: u32) -> Result<(), Error> {
    const WHAT: &str = "the shading-rate image";
    if !mrsl_abi::shading_rate::RATE_TILE_SIZES.contains(&tile) {
        return Err(Error::BadTileSize(tile));
    }
    let t = bindings.shading_rate.ok_or(Error::MissingShadingRate)?;
    if !matches!(t.format(), wgpu::TextureFormat::R8Uint | wgpu::TextureFormat::R16Uint | wgpu::TextureFormat::R32Uint)
    {
        let expected = "R8Uint (as in D3D12 and Vulkan), R16Uint or R32Uint";
        return Err(Error::RateFormat { what: WHAT, expected, found: t.format() });
    }
    if !t.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(Error::RateUsage { what: WHAT, missing: "TEXTURE_BINDING" });
    }
    let expected = mrsl_abi::shading_rate::rate_image_size(bindings.size, tile);
    if (t.width(), t.height()) != expected {
        let (image, found) = (bindings.size, (t.width(), t.height()));
        return Err(Error::RateImageSize { what: WHAT, image, tile, expected, found });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrsl_abi::ValueType;

    fn channel(ty: &str, sample_type: SampleType, format: TextureFormat) -> Channel {
        let ty: ValueType = ty.parse().unwrap();
        Channel {
            name: "c".into(),
            ty,
            group: 1,
            binding: 0,
            format,
            sample_type,
            key: None,
            background: None,
            decode: None,
            access: Default::default(),
        }
    }

    /// The rule in words: "any" for one component, "at least 2", "exactly 4"
    /// for three and four (saying that 3-component formats are refused).
    #[test]
    fn channel_formats_are_described_as_the_check_applies_them() {
        let float = |ty| accepted_formats(&channel(ty, SampleType::UnfilterableFloat, TextureFormat::Rgba32Float));
        assert!(float("float").starts_with("any other colour format read as float"), "{}", float("float"));
        assert!(float("float2").contains("at least 2 components"), "{}", float("float2"));
        let three = float("float3");
        assert!(three.contains("exactly 4 components") && three.contains("Rg11b10Ufloat are not accepted"), "{three}");
        let four = float("float4");
        assert!(four.contains("exactly 4 components") && !four.contains("Rg11b10Ufloat"), "{four}");
        let uint = accepted_formats(&channel("uint", SampleType::Uint, TextureFormat::R32Uint));
        assert!(uint.starts_with("any other uint colour format (R8Uint"), "{uint}");
        let int3 = accepted_formats(&channel("int3", SampleType::Sint, TextureFormat::Rgba32Sint));
        assert!(int3.contains("sint colour format with exactly 4 components (Rgba16Sint"), "{int3}");
        for ty in ["float", "float2", "float3", "float4"] {
            assert!(!float(ty).contains("1 components"), "{}", float(ty));
        }
    }

    #[test]
    fn output_formats_the_language_can_declare_are_hinted_as_format_attributes() {
        let output = |ty: &str| Output {
            name: "color".into(),
            ty: ty.parse().unwrap(),
            format: TextureFormat::Rgba32Float,
            group: 2,
            binding: 1,
        };
        let hint = output_format_hint(&output("float4"), wgpu::TextureFormat::Rgba16Float);
        assert!(hint.contains("`@format(rgba16float) fine out float4 color`"), "{hint}");
        assert!(output_format_hint(&output("float3"), wgpu::TextureFormat::Rgba8Unorm).contains("@format(rgba8unorm)"));
        // Not a format the language has, or not one for this type: create the layout's.
        for found in [wgpu::TextureFormat::Bgra8Unorm, wgpu::TextureFormat::Rg32Float] {
            let hint = output_format_hint(&output("float4"), found);
            assert!(hint.starts_with("create it as Rgba32Float"), "{hint}");
            assert!(hint.ends_with("as rgba32float, rgba16float, rgba8unorm"), "{hint}");
        }
    }
}
