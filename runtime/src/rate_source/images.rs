//! Rate images: made for the rate source to write, uploaded from an
//! engine's rates, read back, checked, and measured in shading work.

use crate::Error;
use crate::gpu::read_texture;
use mrsl_abi::shading_rate::{RATE_TILE_SIZES, ShadingRate, rate_image_size};

/// The format of the rate image the rate source writes.
pub const RATE_IMAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Checks a rate image's format and size for an image of `size` pixels.
pub(super) fn check_rate_texture(
    texture: &wgpu::Texture,
    what: &'static str,
    size: (u32, u32),
    tile: u32,
    formats: &[wgpu::TextureFormat],
    expected: &'static str,
) -> Result<(), Error> {
    if !formats.contains(&texture.format()) {
        return Err(Error::RateFormat { what, expected, found: texture.format() });
    }
    let want = rate_image_size(size, tile);
    let found = (texture.width(), texture.height());
    if found != want {
        return Err(Error::RateImageSize { what, image: size, tile, expected: want, found });
    }
    Ok(())
}

/// Creates the rate image for an image of `size` pixels and `tile`-pixel
/// tiles: [`RATE_IMAGE_FORMAT`], [`rate_image_size`] texels, usable as the
/// rate source's target (`STORAGE_BINDING`), by the `rate-image` kernels
/// (`TEXTURE_BINDING`) and by [`read_rate_image`] (`COPY_SRC`).
pub fn create_rate_image(device: &wgpu::Device, size: (u32, u32), tile: u32) -> Result<wgpu::Texture, Error> {
    if !RATE_TILE_SIZES.contains(&tile) {
        return Err(Error::BadTileSize(tile));
    }
    if size.0 == 0 || size.1 == 0 {
        return Err(Error::BadSize { width: size.0, height: size.1, reason: "an empty image has no tiles".into() });
    }
    Ok(texture(device, "mrsl rate image", rate_image_size(size, tile), RATE_IMAGE_FORMAT))
}

/// Uploads an engine-side rate image: `rates` row by row, `size` texels
/// (one per tile), as an `R8Uint` texture of D3D12/Vulkan codes usable as
/// [`ExternalRates::texture`].
pub fn upload_rate_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    size: (u32, u32),
    rates: &[ShadingRate],
) -> Result<wgpu::Texture, Error> {
    if size.0 == 0 || size.1 == 0 || rates.len() as u64 != u64::from(size.0) * u64::from(size.1) {
        return Err(Error::BadSize {
            width: size.0,
            height: size.1,
            reason: format!("{} rates were given for {} texels", rates.len(), u64::from(size.0) * u64::from(size.1)),
        });
    }
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("mrsl external rate image"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R8Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let codes: Vec<u8> = rates.iter().map(|r| r.code()).collect();
    queue.write_texture(
        texture.as_image_copy(),
        &codes,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(size.0), rows_per_image: Some(size.1) },
        texture.size(),
    );
    Ok(texture)
}

/// Reads a rate image back (waits for the GPU): one rate per texel, row by
/// row. Takes the `R32Uint` images the rate source writes and engines'
/// `R8Uint` (or `R16Uint`) ones; the texture needs `COPY_SRC`.
pub fn read_rate_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<Vec<ShadingRate>, Error> {
    use wgpu::TextureFormat as F;
    let what = "the rate image to read back";
    let bytes_per_texel: usize = match texture.format() {
        F::R8Uint => 1,
        F::R16Uint => 2,
        F::R32Uint => 4,
        found => return Err(Error::RateFormat { what, expected: "R8Uint, R16Uint or R32Uint", found }),
    };
    if !texture.usage().contains(wgpu::TextureUsages::COPY_SRC) {
        return Err(Error::RateUsage { what, missing: "COPY_SRC" });
    }
    let texels = read_texture(device, queue, texture)?;
    let width = texture.width() as usize;
    let mut rates = Vec::with_capacity(texels.len() / bytes_per_texel);
    for (y, line) in texels.chunks(width * bytes_per_texel).enumerate() {
        for (x, texel) in line.chunks_exact(bytes_per_texel).enumerate() {
            let mut word = [0u8; 4];
            word[..texel.len()].copy_from_slice(texel);
            let code = u32::from_le_bytes(word);
            let rate = u8::try_from(code).ok().and_then(ShadingRate::from_code).ok_or_else(|| {
                Error::Readback(format!("rate image texel ({x}, {y}) holds {code:#x}, which is not a rate's code"))
            })?;
            rates.push(rate);
        }
    }
    Ok(rates)
}

/// The fraction of per-pixel shading work `rates` (one per tile, row by row,
/// as [`read_rate_image`] returns them) asks for over an image of `size`
/// pixels: shading cells (cut by the image border where partial) per pixel;
/// 1 for 1x1 everywhere, 1/16 for 4x4 on a multiple of 4. `None` when the
/// count of rates does not match the image.
pub fn rate_fraction(rates: &[ShadingRate], size: (u32, u32), tile: u32) -> Option<f64> {
    let (tw, th) = rate_image_size(size, tile.max(1));
    if tile == 0 || size.0 == 0 || size.1 == 0 || rates.len() as u64 != u64::from(tw) * u64::from(th) {
        return None;
    }
    let mut cells = 0u64;
    for (i, rate) in rates.iter().enumerate() {
        let (tx, ty) = (i as u32 % tw, i as u32 / tw);
        let w = (size.0 - tx * tile).min(tile);
        let h = (size.1 - ty * tile).min(tile);
        let (a, b) = rate.size();
        cells += u64::from(w.div_ceil(a)) * u64::from(h.div_ceil(b));
    }
    Some(cells as f64 / (f64::from(size.0) * f64::from(size.1)))
}

/// A rate-source texture: sampled, written as storage, copied in and out.
pub(super) fn texture(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_fraction_counts_cells_cut_by_the_border() {
        assert_eq!(rate_fraction(&[ShadingRate::R1x1; 4], (16, 16), 8), Some(1.0));
        assert_eq!(rate_fraction(&[ShadingRate::R4x4; 4], (16, 16), 8), Some(1.0 / 16.0));
        // 10x10 pixels, tiles 8: the 2x2 tiles hold 8x8, 2x8, 8x2, 2x2 pixels;
        // at 4x4: 4 + 2 + 2 + 1 cells.
        assert_eq!(rate_fraction(&[ShadingRate::R4x4; 4], (10, 10), 8), Some(9.0 / 100.0));
        assert_eq!(rate_fraction(&[ShadingRate::R2x4; 2], (16, 8), 8), Some(16.0 / 128.0));
        assert_eq!(rate_fraction(&[ShadingRate::R1x1; 3], (16, 16), 8), None);
    }
}
