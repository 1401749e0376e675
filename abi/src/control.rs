//! The control block: the uniform block the runtime writes before every
//! dispatch and every kernel reads as `mrsl_ctl`. [`Control`] is its bytes,
//! [`CONTROL_FIELDS`] its description; the generated WGSL struct, the
//! layout's `control` entry and the runtime's writes all come from here.

use crate::ValueType;
use crate::types::Scalar;

/// The control block as the runtime uploads it (`std140`-compatible: 32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Control {
    /// Width and height of the shaded image in pixels.
    pub size: [u32; 2],
    /// Nonzero: every refine predicate is true (the output must equal the reference).
    pub force_refine: u32,
    /// Dispatch counter, never 0: the dynamic mode tags its 2x2 records with it.
    pub frame: u32,
    /// Hierarchical mode: largest neighbour variance that is still interpolated.
    pub similarity: f32,
    /// Rate-image mode: pixels per side of one shading-rate tile (8 or 16).
    pub rate_tile: u32,
    /// Nonzero: the per-pixel kernels count their re-evaluations (layout
    /// `stats`) and write the refine mask. Zero leaves both out, so timed
    /// runs carry no instrumentation.
    pub statistics: u32,
    /// Padding to a multiple of 16 bytes.
    pub reserved: u32,
}

/// One field of the control block as the layout and the generated WGSL describe it.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlField {
    pub name: &'static str,
    pub ty: ValueType,
    pub wgsl_type: &'static str,
    pub offset: u32,
    pub size: u32,
    /// The value a kernel sees when the runtime has nothing to say.
    pub default: Option<f64>,
    /// A comment the generated WGSL carries after the field, if any.
    pub comment: Option<&'static str>,
}

const UINT2: ValueType = ValueType::Vector(Scalar::Uint, 2);
const UINT: ValueType = ValueType::Scalar(Scalar::Uint);
const FLOAT: ValueType = ValueType::Scalar(Scalar::Float);

/// The fields of [`Control`], in order, with their offsets.
pub static CONTROL_FIELDS: [ControlField; 6] = [
    ControlField { name: "size", ty: UINT2, wgsl_type: "vec2<u32>", offset: 0, size: 8, default: None, comment: None },
    ControlField {
        name: "force_refine",
        ty: UINT,
        wgsl_type: "u32",
        offset: 8,
        size: 4,
        default: Some(0.0),
        comment: None,
    },
    ControlField { name: "frame", ty: UINT, wgsl_type: "u32", offset: 12, size: 4, default: Some(0.0), comment: None },
    ControlField {
        name: "similarity",
        ty: FLOAT,
        wgsl_type: "f32",
        offset: 16,
        size: 4,
        default: Some(0.0),
        comment: Some("hierarchical mode: largest neighbour variance still interpolated"),
    },
    ControlField {
        name: "rate_tile",
        ty: UINT,
        wgsl_type: "u32",
        offset: 20,
        size: 4,
        default: Some(8.0),
        comment: Some("rate-image mode: pixels per side of a shading-rate tile"),
    },
    ControlField {
        name: "statistics",
        ty: UINT,
        wgsl_type: "u32",
        offset: 24,
        size: 4,
        default: Some(1.0),
        comment: Some("nonzero: count per-pixel re-evaluations and write the refine mask"),
    },
];

impl Control {
    /// Size of the block in bytes.
    pub const SIZE: u32 = std::mem::size_of::<Control>() as u32;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_match_the_struct() {
        assert_eq!(Control::SIZE, 32);
        assert_eq!(std::mem::offset_of!(Control, size) as u32, CONTROL_FIELDS[0].offset);
        assert_eq!(std::mem::offset_of!(Control, force_refine) as u32, CONTROL_FIELDS[1].offset);
        assert_eq!(std::mem::offset_of!(Control, frame) as u32, CONTROL_FIELDS[2].offset);
        assert_eq!(std::mem::offset_of!(Control, similarity) as u32, CONTROL_FIELDS[3].offset);
        assert_eq!(std::mem::offset_of!(Control, rate_tile) as u32, CONTROL_FIELDS[4].offset);
        assert_eq!(std::mem::offset_of!(Control, statistics) as u32, CONTROL_FIELDS[5].offset);
        for f in &CONTROL_FIELDS {
            assert_eq!(f.ty.components() * 4, f.size, "{}", f.name);
        }
    }
}
