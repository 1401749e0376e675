//! Shading rates and the shading-rate image of the `rate-image` mode: one
//! rate per screen tile, as hardware variable-rate shading (D3D12 VRS
//! Tier 2, Vulkan `VK_KHR_fragment_shading_rate`) stores it. The encoding is
//! theirs, so an engine's existing rate images (foveation masks, importance
//! maps) can be uploaded unchanged: an `R8Uint` texel holds
//! `(log2(width) << 2) | log2(height)`, where width and height are the
//! shading-cell size in pixels along x and y.
//!
//! The compiler writes [`ShadingRate::decode_wgsl`]'s rule into the
//! `rate-image` kernels, and the runtime's rate sources write the same codes.

/// Tile sizes (pixels per side of one shading-rate texel) the `rate-image`
/// mode supports. 8 is the finest hardware VRS offers on most GPUs; 16 is
/// the other common one.
pub const RATE_TILE_SIZES: [u32; 2] = [8, 16];

/// The default tile size of the `rate-image` mode.
pub const DEFAULT_RATE_TILE: u32 = 8;

/// One shading rate: the size of a shading cell, width x height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShadingRate {
    R1x1,
    R1x2,
    R2x1,
    R2x2,
    R2x4,
    R4x2,
    R4x4,
}

impl ShadingRate {
    /// The seven rates, finest first.
    pub const ALL: [ShadingRate; 7] = [
        ShadingRate::R1x1,
        ShadingRate::R1x2,
        ShadingRate::R2x1,
        ShadingRate::R2x2,
        ShadingRate::R2x4,
        ShadingRate::R4x2,
        ShadingRate::R4x4,
    ];

    /// Cell width and height in pixels.
    pub fn size(self) -> (u32, u32) {
        match self {
            ShadingRate::R1x1 => (1, 1),
            ShadingRate::R1x2 => (1, 2),
            ShadingRate::R2x1 => (2, 1),
            ShadingRate::R2x2 => (2, 2),
            ShadingRate::R2x4 => (2, 4),
            ShadingRate::R4x2 => (4, 2),
            ShadingRate::R4x4 => (4, 4),
        }
    }

    /// The rate of a `width` x `height` cell, if it is one of the seven
    /// (1x4 and 4x1 are not: hardware VRS has no such rates).
    pub fn from_size(width: u32, height: u32) -> Option<ShadingRate> {
        ShadingRate::ALL.into_iter().find(|r| r.size() == (width, height))
    }

    /// The texel value: `(log2(width) << 2) | log2(height)` (D3D12's
    /// `D3D12_SHADING_RATE` and Vulkan's fragment-size encoding).
    pub fn code(self) -> u8 {
        let (w, h) = self.size();
        ((w.trailing_zeros() << 2) | h.trailing_zeros()) as u8
    }

    /// The rate a texel value encodes, if any.
    pub fn from_code(code: u8) -> Option<ShadingRate> {
        ShadingRate::ALL.into_iter().find(|r| r.code() == code)
    }

    /// The name used by the CLI, the docs and D3D12: `"2x4"`.
    pub fn name(self) -> &'static str {
        match self {
            ShadingRate::R1x1 => "1x1",
            ShadingRate::R1x2 => "1x2",
            ShadingRate::R2x1 => "2x1",
            ShadingRate::R2x2 => "2x2",
            ShadingRate::R2x4 => "2x4",
            ShadingRate::R4x2 => "4x2",
            ShadingRate::R4x4 => "4x4",
        }
    }

    /// Pixels per shading cell.
    pub fn pixels(self) -> u32 {
        let (w, h) = self.size();
        w * h
    }

    /// The finer rate along each axis of `self` and `other` (the `min`
    /// combiner: the cell is no wider and no taller than either).
    pub fn finer(self, other: ShadingRate) -> ShadingRate {
        let ((a, b), (c, d)) = (self.size(), other.size());
        ShadingRate::clamp_size(a.min(c), b.min(d))
    }

    /// The coarser rate along each axis (the `max` combiner). Neither
    /// combiner can produce 4x1 or 1x4 from two of the seven rates.
    pub fn coarser(self, other: ShadingRate) -> ShadingRate {
        let ((a, b), (c, d)) = (self.size(), other.size());
        ShadingRate::clamp_size(a.max(c), b.max(d))
    }

    /// The nearest of the seven rates to a `w` x `h` cell whose sides are
    /// 1, 2 or 4: 4x1 and 1x4 (which hardware VRS does not have) become
    /// 2x1 and 1x2 (the finer choice: never coarser than asked on either axis).
    pub fn clamp_size(w: u32, h: u32) -> ShadingRate {
        let (w, h) = (w.clamp(1, 4).next_power_of_two().min(4), h.clamp(1, 4).next_power_of_two().min(4));
        let (w, h) = match (w, h) {
            (4, 1) => (2, 1),
            (1, 4) => (1, 2),
            other => other,
        };
        ShadingRate::from_size(w, h).expect("every clamped size is a rate")
    }

    /// The WGSL expression that decodes a texel value `code` into the cell
    /// size as `vec2<i32>` (what the `rate-image` kernels use).
    pub fn decode_wgsl(code: &str) -> String {
        format!("vec2<i32>(1 << (({code} >> 2u) & 3u), 1 << ({code} & 3u))")
    }
}

impl std::fmt::Display for ShadingRate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The size of the shading-rate image for an image of `size` pixels and
/// tiles of `tile` pixels per side: one texel per tile, partial tiles at
/// the right and bottom edges included.
pub fn rate_image_size(size: (u32, u32), tile: u32) -> (u32, u32) {
    (size.0.div_ceil(tile), size.1.div_ceil(tile))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_those_of_d3d12_and_vulkan() {
        // D3D12_SHADING_RATE_1X1 = 0x0, 1X2 = 0x1, 2X1 = 0x4, 2X2 = 0x5, 2X4 = 0x6, 4X2 = 0x9, 4X4 = 0xa.
        let codes: Vec<u8> = ShadingRate::ALL.iter().map(|r| r.code()).collect();
        assert_eq!(codes, [0x0, 0x1, 0x4, 0x5, 0x6, 0x9, 0xa]);
        for r in ShadingRate::ALL {
            assert_eq!(ShadingRate::from_code(r.code()), Some(r));
            let (w, h) = r.size();
            assert_eq!(ShadingRate::from_size(w, h), Some(r));
            assert_eq!(r.to_string(), format!("{w}x{h}"));
        }
        for code in [0x2, 0x3, 0x8, 0xb, 0xf, 0xff] {
            assert_eq!(ShadingRate::from_code(code), None);
        }
    }

    #[test]
    fn combiners_work_per_axis() {
        use ShadingRate::*;
        assert_eq!(R4x2.finer(R2x4), R2x2);
        assert_eq!(R4x2.coarser(R2x4), R4x4);
        assert_eq!(R1x2.coarser(R4x2), R4x2);
        assert_eq!(R4x4.finer(R1x1), R1x1);
        assert_eq!(R2x1.coarser(R1x2), R2x2);
        for a in ShadingRate::ALL {
            for b in ShadingRate::ALL {
                assert_eq!(a.finer(b).size(), (a.size().0.min(b.size().0), a.size().1.min(b.size().1)));
                assert_eq!(a.coarser(b).size(), (a.size().0.max(b.size().0), a.size().1.max(b.size().1)));
            }
        }
        assert_eq!(ShadingRate::clamp_size(4, 1), R2x1);
        assert_eq!(ShadingRate::clamp_size(1, 4), R1x2);
        assert_eq!(rate_image_size((1920, 1080), 8), (240, 135));
        assert_eq!(rate_image_size((13, 9), 8), (2, 2));
    }
}
