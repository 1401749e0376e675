//! A small deterministic hash in [0, 1), for what must be the same on every
//! run and machine: the light rig's jitter and colours, and the generated
//! scene's city. Pulling in a random-number crate for a few thousand
//! numbers is not worth a dependency.

/// `k` hashed to [0, 1) (24 bits).
pub(crate) fn hash01(k: u32) -> f32 {
    let mut x = k.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}
