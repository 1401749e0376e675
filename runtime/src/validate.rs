//! What an engine binds, checked against the program's layout and the
//! mode's plan before anything is recorded: every mismatch is a typed
//! [`Error`] naming the binding at fault.

use crate::error::Error;
use crate::shader::Bindings;
use crate::wgpu_format;
use mrsl_abi::geometry::MAX_SIDE;
use mrsl_abi::plan::{MAX_WORKGROUPS_PER_DIMENSION, ModePlan, TooLarge, Workgroups};
use mrsl_abi::{Layout, Plan, ResourceId, SampleType};

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
/// layout declares, of the right format and size, and the shading-rate
/// image where the mode binds one.
pub(crate) fn bindings(layout: &Layout, mode: &ModePlan, bindings: &Bindings, rate_tile: u32) -> Result<(), Error> {
    if mode.resources().contains(&ResourceId::ShadingRate) {
        shading_rate(bindings, rate_tile)?;
    }
    let (width, height) = bindings.size;
    let check_size = |what: &'static str, name: &str, t: &wgpu::Texture| {
        if (t.width(), t.height()) != (width, height) {
            return Err(Error::SizeMismatch {
                what,
                name: name.into(),
                width,
                height,
                found_width: t.width(),
                found_height: t.height(),
            });
        }
        Ok(())
    };
    for ch in &layout.channels {
        let t = bindings.channels.get(&ch.name).ok_or_else(|| Error::MissingChannel(ch.name.clone()))?;
        let need = ch.ty.components();
        let fits = matches!(
            (ch.sample_type, t.format().sample_type(None, None)),
            (SampleType::Uint, Some(wgpu::TextureSampleType::Uint))
                | (SampleType::Sint, Some(wgpu::TextureSampleType::Sint))
                | (SampleType::UnfilterableFloat, Some(wgpu::TextureSampleType::Float { .. }))
        ) && t.format().components() as u32 >= need.min(4)
            && (need != 3 || t.format().components() == 4);
        if !fits {
            return Err(Error::ChannelFormat {
                channel: ch.name.clone(),
                ty: ch.ty.to_string(),
                expected: ch.format.to_string(),
                components: need,
                found: t.format(),
            });
        }
        check_size("G-buffer channel", &ch.name, t)?;
    }
    for t in &layout.textures {
        if !bindings.textures.contains_key(&t.name) {
            return Err(Error::MissingTexture(t.name.clone()));
        }
    }
    for s in &layout.samplers {
        if !bindings.samplers.contains_key(&s.name) {
            return Err(Error::MissingSampler(s.name.clone()));
        }
    }
    for o in &layout.outputs {
        let t = bindings.outputs.get(&o.name).ok_or_else(|| Error::MissingOutput(o.name.clone()))?;
        let expected = wgpu_format(o.format);
        if t.format() != expected {
            return Err(Error::OutputFormat { name: o.name.clone(), expected, found: t.format() });
        }
        if !t.usage().contains(wgpu::TextureUsages::STORAGE_BINDING) {
            return Err(Error::OutputUsage(o.name.clone()));
        }
        check_size("output", &o.name, t)?;
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
