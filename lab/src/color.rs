//! The sRGB transfer function (IEC 61966-2-1), once for the whole kit: the
//! PNGs the tools write, the mipmaps of sRGB textures and the 8-bit images
//! FLIP compares all encode and decode with these two functions, so that
//! "what a display shows" means the same bytes everywhere.

/// An sRGB-encoded byte to linear light in [0, 1] (the exact curve).
pub fn srgb_to_linear(byte: u8) -> f32 {
    let s = f32::from(byte) / 255.0;
    if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }
}

/// The sRGB encoding curve and the rounding to a byte, written once for
/// both precisions the kit encodes in (see [`linear_to_srgb8`] and
/// [`linear_to_srgb8_f64`]); the literals take the type of `$v`.
macro_rules! encode {
    ($v:expr) => {{
        let v = $v;
        let s = if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
        // In [0, 255.5) for v in [0, 1]; `as` truncates, so this rounds half up.
        (s * 255.0 + 0.5) as u8
    }};
}

/// Linear light to the nearest sRGB-encoded byte, in `f32`: clamped to
/// [0, 1], encoded, rounded half up. A non-finite value (a NaN or an
/// infinity from a broken shader) becomes 0, black, rather than a bright
/// pixel that looks right. The PNGs the tools write and the mipmaps of sRGB
/// textures are encoded with it.
pub fn linear_to_srgb8(v: f32) -> u8 {
    encode!(if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 })
}

/// [`linear_to_srgb8`] evaluated in `f64`, as the FLIP metric has always
/// encoded its inputs ([`crate::metrics`]). The two differ for 219 of the
/// `f32` values in [0, 1], each within rounding of a half step, and
/// rendered images do hit some of them, so moving either to the other's
/// precision would change every published image or FLIP figure.
pub fn linear_to_srgb8_f64(v: f32) -> u8 {
    encode!(f64::from(if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_round_trips() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_to_linear(b)), b);
        }
        assert!((srgb_to_linear(188) - 0.5029).abs() < 1e-3);
    }

    #[test]
    fn both_precisions_agree_but_on_half_steps() {
        for b in 0..=255u8 {
            assert_eq!(linear_to_srgb8_f64(srgb_to_linear(b)), b);
        }
        // One of the 219 values: f32 rounds it up, f64 down.
        assert_eq!((linear_to_srgb8(0.000_151_763_48), linear_to_srgb8_f64(0.000_151_763_48)), (1, 0));
    }

    #[test]
    fn out_of_range_and_non_finite_values_are_clamped_or_black() {
        assert_eq!(linear_to_srgb8(-3.0), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(f32::INFINITY), 0);
        assert_eq!(linear_to_srgb8_f64(f32::NAN), 0);
    }
}
