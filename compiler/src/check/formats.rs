//! Storage-texture formats of `fine out` targets: which formats can hold an
//! output's type, and the default one.

use crate::types::{Scalar, Type};
use mrsl_abi::TextureFormat;

/// Storage-texture formats an output of type `ty` may be written to (the
/// contract's table, [`TextureFormat::for_output`]).
pub(super) fn formats_for(ty: &Type) -> Vec<TextureFormat> {
    ty.value_type().map(|v| TextureFormat::for_output(&v)).unwrap_or_default()
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
