//! Storage-texture formats of `fine out` targets: which formats can hold an
//! output's type, and the default one.

use crate::types::{Scalar, Type};
use mrsl_abi::TextureFormat;

/// Storage-texture formats an output of type `ty` may be written to.
pub(super) fn formats_for(ty: &Type) -> Vec<TextureFormat> {
    use TextureFormat as F;
    // A format must hold every component: single-channel formats only for
    // scalars, two-channel ones for at most two components.
    let n = ty.components();
    let any = match ty {
        Type::Scalar(Scalar::Float) => vec![F::R32Float, F::Rgba16Float, F::Rgba32Float, F::Rgba8Unorm],
        Type::Vector(Scalar::Float, _) => vec![F::Rgba32Float, F::Rgba16Float, F::Rgba8Unorm, F::Rg32Float],
        Type::Scalar(Scalar::Uint) | Type::Vector(Scalar::Uint, _) => vec![F::R32Uint, F::Rgba32Uint],
        Type::Scalar(Scalar::Int) | Type::Vector(Scalar::Int, _) => vec![F::R32Sint, F::Rgba32Sint],
        _ => vec![],
    };
    any.into_iter().filter(|f| f.components() >= n.min(4) || f.components() == 4).collect()
}

/// The format called `format`, if an output of type `ty` may be written to it.
pub(super) fn output_format_fits(format: &str, ty: &Type) -> Option<TextureFormat> {
    formats_for(ty).into_iter().find(|f| f.name() == format)
}

/// The default storage format of an output: exact 32-bit storage, so that
/// outputs can be compared bit for bit with the reference.
pub(super) fn default_output_format(ty: &Type) -> TextureFormat {
    use TextureFormat as F;
    match ty {
        Type::Scalar(Scalar::Float) => F::R32Float,
        Type::Vector(Scalar::Float, _) => F::Rgba32Float,
        Type::Scalar(Scalar::Uint) => F::R32Uint,
        Type::Vector(Scalar::Uint, _) => F::Rgba32Uint,
        Type::Scalar(Scalar::Int) => F::R32Sint,
        _ => F::Rgba32Sint,
    }
}
