//! The types of mrsl values, their WGSL spelling and host layout rules.

pub use mrsl_abi::Scalar;

/// A type. `AbstractInt`/`AbstractFloat` are the types of unsuffixed literals
/// (and constant expressions of them); they convert to a concrete type where
/// one is expected, exactly as WGSL's abstract numerics do.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Type {
    Scalar(Scalar),
    Vector(Scalar, u8),
    /// Square float matrices only (`float2x2`, `float3x3`, `float4x4`).
    Matrix(u8),
    Texture2d,
    Sampler,
    /// Uniform arrays only.
    Array(Box<Type>, u32),
    AbstractInt,
    AbstractFloat,
    /// The type of an expression that already produced an error; never reported again.
    Error,
}

pub const FLOAT: Type = Type::Scalar(Scalar::Float);
pub const INT: Type = Type::Scalar(Scalar::Int);
pub const UINT: Type = Type::Scalar(Scalar::Uint);
pub const BOOL: Type = Type::Scalar(Scalar::Bool);

/// Every type a program can name, by its name: the table [`Type::from_name`]
/// reads and the vocabulary lists (type names lex as identifiers, so no
/// lexer table holds them).
pub static NAMED_TYPES: [(&str, Type); 21] = {
    use Scalar::{Bool, Float, Int, Uint};
    [
        ("bool", Type::Scalar(Bool)),
        ("int", Type::Scalar(Int)),
        ("uint", Type::Scalar(Uint)),
        ("float", Type::Scalar(Float)),
        ("bool2", Type::Vector(Bool, 2)),
        ("bool3", Type::Vector(Bool, 3)),
        ("bool4", Type::Vector(Bool, 4)),
        ("int2", Type::Vector(Int, 2)),
        ("int3", Type::Vector(Int, 3)),
        ("int4", Type::Vector(Int, 4)),
        ("uint2", Type::Vector(Uint, 2)),
        ("uint3", Type::Vector(Uint, 3)),
        ("uint4", Type::Vector(Uint, 4)),
        ("float2", Type::Vector(Float, 2)),
        ("float3", Type::Vector(Float, 3)),
        ("float4", Type::Vector(Float, 4)),
        ("float2x2", Type::Matrix(2)),
        ("float3x3", Type::Matrix(3)),
        ("float4x4", Type::Matrix(4)),
        ("texture2d", Type::Texture2d),
        ("sampler", Type::Sampler),
    ]
};

impl Type {
    /// Parses a type name as written in mrsl (one of [`NAMED_TYPES`]).
    pub fn from_name(name: &str) -> Option<Type> {
        NAMED_TYPES.iter().find(|(n, _)| *n == name).map(|(_, ty)| ty.clone())
    }

    pub fn scalar(&self) -> Option<Scalar> {
        match self {
            Type::Scalar(s) | Type::Vector(s, _) => Some(*s),
            Type::Matrix(_) => Some(Scalar::Float),
            Type::AbstractFloat => Some(Scalar::Float),
            Type::AbstractInt => Some(Scalar::Int),
            _ => None,
        }
    }

    /// Number of 32-bit components.
    pub fn components(&self) -> u32 {
        match self {
            Type::Scalar(_) | Type::AbstractInt | Type::AbstractFloat => 1,
            Type::Vector(_, n) => *n as u32,
            Type::Matrix(n) => (*n as u32) * (*n as u32),
            Type::Array(t, n) => t.components() * n,
            _ => 0,
        }
    }

    pub fn vector_len(&self) -> Option<u8> {
        match self {
            Type::Vector(_, n) => Some(*n),
            _ => None,
        }
    }

    pub fn is_error(&self) -> bool {
        matches!(self, Type::Error)
    }
    pub fn is_abstract(&self) -> bool {
        matches!(self, Type::AbstractInt | Type::AbstractFloat)
    }
    pub fn is_numeric_value(&self) -> bool {
        matches!(self.scalar(), Some(Scalar::Int | Scalar::Uint | Scalar::Float)) && !matches!(self, Type::Array(..))
    }
    /// float, floatN, or an abstract literal that can become one.
    pub fn is_float_like(&self) -> bool {
        matches!(
            self,
            Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _) | Type::AbstractFloat | Type::AbstractInt
        )
    }
    /// A plain value that can live in a variable, the interface or an output.
    pub fn is_value(&self) -> bool {
        matches!(self, Type::Scalar(_) | Type::Vector(..) | Type::Matrix(_))
    }

    /// The concrete type an abstract one becomes with no other constraint.
    pub fn concretize(&self) -> Type {
        match self {
            Type::AbstractInt => INT,
            Type::AbstractFloat => FLOAT,
            other => other.clone(),
        }
    }

    /// Whether a value of `self` may be used where `target` is expected
    /// (equal, or an abstract literal that converts).
    pub fn converts_to(&self, target: &Type) -> bool {
        if self == target || self.is_error() || target.is_error() {
            return true;
        }
        matches!(
            (self, target),
            (Type::AbstractInt, Type::Scalar(Scalar::Int | Scalar::Uint | Scalar::Float))
                | (Type::AbstractInt, Type::AbstractFloat)
                | (Type::AbstractFloat, Type::Scalar(Scalar::Float))
        )
    }

    /// The mrsl spelling, for diagnostics.
    pub fn name(&self) -> String {
        match self {
            Type::Scalar(s) => s.name().to_string(),
            Type::Vector(s, n) => format!("{}{n}", s.name()),
            Type::Matrix(n) => format!("float{n}x{n}"),
            Type::Texture2d => "texture2d".into(),
            Type::Sampler => "sampler".into(),
            Type::Array(t, n) => format!("{}[{n}]", t.name()),
            Type::AbstractInt => "int literal".into(),
            Type::AbstractFloat => "float literal".into(),
            Type::Error => "{error}".into(),
        }
    }

    /// The WGSL spelling.
    pub fn wgsl(&self) -> String {
        match self {
            Type::Scalar(s) => s.wgsl().to_string(),
            Type::Vector(s, n) => format!("vec{n}<{}>", s.wgsl()),
            Type::Matrix(n) => format!("mat{n}x{n}<f32>"),
            Type::Texture2d => "texture_2d<f32>".into(),
            Type::Sampler => "sampler".into(),
            Type::Array(t, n) => format!("array<{}, {n}>", t.wgsl()),
            Type::AbstractInt => "i32".into(),
            Type::AbstractFloat => "f32".into(),
            Type::Error => "f32".into(),
        }
    }

    /// WGSL host-shareable (uniform address space) alignment and size in bytes.
    /// `bool` is stored as a `u32`.
    pub fn uniform_align_size(&self) -> (u32, u32) {
        match self {
            Type::Scalar(_) => (4, 4),
            Type::Vector(_, 2) => (8, 8),
            Type::Vector(_, 3) => (16, 12),
            Type::Vector(_, _) => (16, 16),
            Type::Matrix(2) => (8, 16),
            Type::Matrix(3) => (16, 48),
            Type::Matrix(_) => (16, 64),
            Type::Array(t, n) => {
                let (align, size) = t.uniform_align_size();
                let stride = round_up(size, align.max(16));
                (align.max(16), stride * n)
            }
            _ => (4, 4),
        }
    }

    /// The layout's spelling of a value type (scalars, vectors, matrices and
    /// arrays of them); `None` for textures, samplers and literal types.
    pub fn value_type(&self) -> Option<mrsl_abi::ValueType> {
        use mrsl_abi::ValueType;
        Some(match self {
            Type::Scalar(s) => ValueType::Scalar(*s),
            Type::Vector(s, n) => ValueType::Vector(*s, *n),
            Type::Matrix(n) => ValueType::Matrix(*n),
            Type::Array(t, n) => ValueType::Array(Box::new(t.value_type()?), *n),
            _ => return None,
        })
    }

    /// The type as stored in a host-shareable buffer (bool becomes u32).
    pub fn host_type(&self) -> Type {
        match self {
            Type::Scalar(Scalar::Bool) => UINT,
            Type::Vector(Scalar::Bool, n) => Type::Vector(Scalar::Uint, *n),
            Type::Array(t, n) => Type::Array(Box::new(t.host_type()), *n),
            other => other.clone(),
        }
    }
}

pub fn round_up(value: u32, align: u32) -> u32 {
    value.div_ceil(align) * align
}

impl std::fmt::Display for Type {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each named type is spelt back as it is named, so the table holds each
    /// type once and under the name diagnostics use.
    #[test]
    fn named_types_round_trip() {
        for (name, ty) in &NAMED_TYPES {
            assert_eq!(ty.name(), *name);
        }
        assert_eq!(Type::from_name("float1"), None);
        assert_eq!(Type::from_name("int2x2"), None);
    }
}
