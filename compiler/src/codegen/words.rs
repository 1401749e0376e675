//! Values as 32-bit words: how effect values travel through the `array<u32>`
//! buffers (interface records, per-pixel records), and how bits of flag and
//! mask words are addressed.

use crate::types::{Scalar, Type};

/// Bit `k` of a run of `u32` words: the word index and the mask within it.
pub(super) fn bit(k: u32) -> (u32, u32) {
    (k / 32, 1u32 << (k % 32))
}

/// WGSL expressions for the 32-bit words of a value, in order.
pub(super) fn pack_words(value: &str, ty: &Type) -> Vec<String> {
    let scalar = |x: String, s: Scalar| match s {
        Scalar::Float | Scalar::Int => format!("bitcast<u32>({x})"),
        Scalar::Uint => x,
        Scalar::Bool => format!("select(0u, 1u, {x})"),
    };
    match ty {
        Type::Scalar(s) => vec![scalar(value.to_string(), *s)],
        Type::Vector(s, n) => (0..*n).map(|k| scalar(format!("{value}[{k}]"), *s)).collect(),
        Type::Matrix(n) => {
            (0..*n).flat_map(|col| (0..*n).map(move |row| format!("bitcast<u32>({value}[{col}][{row}])"))).collect()
        }
        _ => vec![],
    }
}

/// A WGSL expression reading a value from `buffer` at word `base`.
pub(super) fn unpack_words(ty: &Type, buffer: &str) -> String {
    unpack_with(ty, |k| format!("{buffer}[base + {k}u]"))
}

/// A WGSL expression for a value whose `k`th word is `word(k)`.
pub(super) fn unpack_with(ty: &Type, word: impl Fn(u32) -> String) -> String {
    let scalar = |k: u32, s: Scalar| match s {
        Scalar::Float => format!("bitcast<f32>({})", word(k)),
        Scalar::Int => format!("bitcast<i32>({})", word(k)),
        Scalar::Uint => word(k),
        Scalar::Bool => format!("({} != 0u)", word(k)),
    };
    match ty {
        Type::Scalar(s) => scalar(0, *s),
        Type::Vector(s, n) => {
            format!("{}({})", ty.wgsl(), (0..*n as u32).map(|k| scalar(k, *s)).collect::<Vec<_>>().join(", "))
        }
        Type::Matrix(n) => {
            let n = *n as u32;
            let cols: Vec<String> = (0..n)
                .map(|col| {
                    format!(
                        "vec{n}<f32>({})",
                        (0..n).map(|row| scalar(col * n + row, Scalar::Float)).collect::<Vec<_>>().join(", ")
                    )
                })
                .collect();
            format!("{}({})", ty.wgsl(), cols.join(", "))
        }
        _ => "0u".into(),
    }
}

/// WGSL testing bit `k` of the words `{prefix}0`, `{prefix}1`, ...
pub(super) fn test_bit(prefix: &str, k: u32) -> String {
    let (word, mask) = bit(k);
    format!("(({prefix}{word} & {mask}u) != 0u)")
}
