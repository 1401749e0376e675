//! The kit's vector maths is glam's (`Vec3`, `Mat3`, `Mat4`); this module
//! holds the one operation the kit rounds differently from glam.
//!
//! glam's `normalize` multiplies by the reciprocal of the length, which
//! rounds differently from dividing by it; meshes, cameras and the light rig
//! have always divided, and their images must stay byte-identical, so
//! [`normalize`] divides.

use glam::Vec3;

/// `v` scaled to unit length (each component divided by the length), or
/// zero for a zero vector.
pub(crate) fn normalize(v: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 { v / l } else { Vec3::ZERO }
}
