//! Shading-rate images made on the CPU, for the tools and tests of the
//! rate-image mode: a fixed pattern that puts every rate next to every
//! other, a uniform image, and the upload of any list of rates as the
//! `R8Uint` texture engines use (D3D12/Vulkan codes,
//! [`mrsl_abi::ShadingRate::code`]).

use crate::gpu::Gpu;
use mrsl_abi::ShadingRate;
use mrsl_abi::shading_rate::rate_image_size;
use mrsl_runtime::rate_source::upload_rate_image;

/// A rate per tile for `tiles` tiles (row-major), scrambled so that every
/// rate soon borders every other one, horizontally and vertically (over 20 x
/// 20 tiles every ordered pair of different rates is found both ways; a
/// test checks it): tile (x, y) takes rate `hash(x, y) mod 7`.
pub fn pattern(tiles: (u32, u32)) -> Vec<ShadingRate> {
    let hash = |x: u32, y: u32| {
        let mut h = x.wrapping_mul(0x9e37_79b9) ^ y.wrapping_mul(0x85eb_ca6b);
        h ^= h >> 15;
        h = h.wrapping_mul(0x2c1b_3c6d);
        h ^ (h >> 12)
    };
    (0..tiles.1).flat_map(|y| (0..tiles.0).map(move |x| ShadingRate::ALL[(hash(x, y) % 7) as usize])).collect()
}

/// Uploads `rates` (row-major, `rate_image_size(size, tile)` of them) as an
/// `R8Uint` shading-rate image for a `size` image with `tile`-pixel tiles
/// (through the runtime's [`upload_rate_image`]).
///
/// # Panics
///
/// When `rates` does not hold one rate per tile (a bug in the caller: tests
/// and tools make the rates for the size they pass).
pub fn upload(gpu: &Gpu, size: (u32, u32), tile: u32, rates: &[ShadingRate]) -> wgpu::Texture {
    upload_rate_image(&gpu.device, &gpu.queue, rate_image_size(size, tile), rates)
        .unwrap_or_else(|e| panic!("one rate per tile: {e}"))
}

/// The [`pattern`] image for a `size` image with `tile`-pixel tiles.
pub fn upload_pattern(gpu: &Gpu, size: (u32, u32), tile: u32) -> wgpu::Texture {
    upload(gpu, size, tile, &pattern(rate_image_size(size, tile)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pattern_puts_every_rate_beside_every_other() {
        let tiles = (20, 20);
        let rates = pattern(tiles);
        let at = |x: u32, y: u32| rates[(y * tiles.0 + x) as usize];
        let mut right = std::collections::HashSet::new();
        let mut below = std::collections::HashSet::new();
        for y in 0..tiles.1 {
            for x in 0..tiles.0 {
                if x + 1 < tiles.0 && at(x, y) != at(x + 1, y) {
                    right.insert((at(x, y), at(x + 1, y)));
                }
                if y + 1 < tiles.1 && at(x, y) != at(x, y + 1) {
                    below.insert((at(x, y), at(x, y + 1)));
                }
            }
        }
        assert_eq!(right.len(), 42, "horizontal pairs: {right:?}");
        assert_eq!(below.len(), 42, "vertical pairs: {below:?}");
    }
}
