//! Typed names the layout uses instead of strings: value types, texture
//! formats and sample types. Each serialises to the same string the layout
//! JSON has always carried, and parsing rejects anything else.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A scalar type of mrsl.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scalar {
    Bool,
    Int,
    Uint,
    Float,
}

impl Scalar {
    /// The mrsl spelling (`float`).
    pub fn name(self) -> &'static str {
        match self {
            Scalar::Bool => "bool",
            Scalar::Int => "int",
            Scalar::Uint => "uint",
            Scalar::Float => "float",
        }
    }

    /// The WGSL spelling (`f32`).
    pub fn wgsl(self) -> &'static str {
        match self {
            Scalar::Bool => "bool",
            Scalar::Int => "i32",
            Scalar::Uint => "u32",
            Scalar::Float => "f32",
        }
    }

    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "bool" => Scalar::Bool,
            "int" => Scalar::Int,
            "uint" => Scalar::Uint,
            "float" => Scalar::Float,
            _ => return None,
        })
    }
}

/// The type of a value the layout describes (uniform fields, channels,
/// effects, outputs), written as in mrsl: `float3`, `uint`, `float4x4`,
/// `float4[32]`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum ValueType {
    Scalar(Scalar),
    /// A vector of 2 to 4 components.
    Vector(Scalar, u8),
    /// A square float matrix of side 2 to 4.
    Matrix(u8),
    /// A fixed-size array (uniforms only).
    Array(Box<ValueType>, u32),
}

impl ValueType {
    /// Number of 32-bit components (matrix columns times rows, array elements times theirs).
    pub fn components(&self) -> u32 {
        match self {
            ValueType::Scalar(_) => 1,
            ValueType::Vector(_, n) => u32::from(*n),
            ValueType::Matrix(n) => u32::from(*n) * u32::from(*n),
            ValueType::Array(t, n) => t.components() * n,
        }
    }

    /// The scalar type of the components.
    pub fn scalar(&self) -> Scalar {
        match self {
            ValueType::Scalar(s) | ValueType::Vector(s, _) => *s,
            ValueType::Matrix(_) => Scalar::Float,
            ValueType::Array(t, _) => t.scalar(),
        }
    }

    /// The element type of an array, or `self`.
    pub fn element(&self) -> &ValueType {
        match self {
            ValueType::Array(t, _) => t.element(),
            other => other,
        }
    }
}

impl fmt::Display for ValueType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ValueType::Scalar(s) => f.write_str(s.name()),
            ValueType::Vector(s, n) => write!(f, "{}{n}", s.name()),
            ValueType::Matrix(n) => write!(f, "float{n}x{n}"),
            ValueType::Array(t, n) => write!(f, "{t}[{n}]"),
        }
    }
}

impl FromStr for ValueType {
    type Err = String;

    fn from_str(text: &str) -> Result<ValueType, String> {
        let bad = || format!("`{text}` is not an mrsl value type");
        if let Some(open) = text.strip_suffix(']') {
            let (element, count) = open.rsplit_once('[').ok_or_else(bad)?;
            let count = count.parse().map_err(|_| bad())?;
            return Ok(ValueType::Array(Box::new(element.parse()?), count));
        }
        match text {
            "float2x2" => return Ok(ValueType::Matrix(2)),
            "float3x3" => return Ok(ValueType::Matrix(3)),
            "float4x4" => return Ok(ValueType::Matrix(4)),
            _ => {}
        }
        if let Some(s) = Scalar::from_name(text) {
            return Ok(ValueType::Scalar(s));
        }
        let (base, n) = text.split_at(text.len().checked_sub(1).ok_or_else(bad)?);
        match (Scalar::from_name(base), n.parse::<u8>()) {
            (Some(s), Ok(n @ 2..=4)) => Ok(ValueType::Vector(s, n)),
            _ => Err(bad()),
        }
    }
}

impl Serialize for ValueType {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for ValueType {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<ValueType, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// A texture format of a G-buffer channel or an output, as WebGPU names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TextureFormat {
    R32Float,
    Rg32Float,
    Rgba32Float,
    Rgba16Float,
    Rgba8Unorm,
    R32Uint,
    Rg32Uint,
    Rgba32Uint,
    R32Sint,
    Rg32Sint,
    Rgba32Sint,
    /// A depth texture: the format of a channel decoded from depth
    /// (`@depth(..)`, [`crate::Decode::Depth`]); never an output.
    Depth32Float,
}

impl TextureFormat {
    /// Every format, for tables and parsing.
    pub const ALL: [TextureFormat; 12] = [
        TextureFormat::R32Float,
        TextureFormat::Rg32Float,
        TextureFormat::Rgba32Float,
        TextureFormat::Rgba16Float,
        TextureFormat::Rgba8Unorm,
        TextureFormat::R32Uint,
        TextureFormat::Rg32Uint,
        TextureFormat::Rgba32Uint,
        TextureFormat::R32Sint,
        TextureFormat::Rg32Sint,
        TextureFormat::Rgba32Sint,
        TextureFormat::Depth32Float,
    ];

    /// The WebGPU name (`rgba32float`), which is also the WGSL texel format.
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::R32Float => "r32float",
            TextureFormat::Rg32Float => "rg32float",
            TextureFormat::Rgba32Float => "rgba32float",
            TextureFormat::Rgba16Float => "rgba16float",
            TextureFormat::Rgba8Unorm => "rgba8unorm",
            TextureFormat::R32Uint => "r32uint",
            TextureFormat::Rg32Uint => "rg32uint",
            TextureFormat::Rgba32Uint => "rgba32uint",
            TextureFormat::R32Sint => "r32sint",
            TextureFormat::Rg32Sint => "rg32sint",
            TextureFormat::Rgba32Sint => "rgba32sint",
            TextureFormat::Depth32Float => "depth32float",
        }
    }

    /// Whether a shader may read it through a read-only storage binding:
    /// every colour format here is a storage format of WebGPU's core, whose
    /// storage textures may be read-only (WGSL's
    /// `readonly_and_readwrite_storage_textures`); a depth format is not.
    pub fn storage_readable(self) -> bool {
        self != TextureFormat::Depth32Float
    }

    /// Bytes per texel.
    pub fn texel_bytes(self) -> u32 {
        match self {
            TextureFormat::Rgba16Float => 8,
            TextureFormat::Rgba8Unorm => 4,
            other => 4 * other.components(),
        }
    }

    /// Number of channels.
    pub fn components(self) -> u32 {
        match self {
            TextureFormat::R32Float | TextureFormat::R32Uint | TextureFormat::R32Sint | TextureFormat::Depth32Float => {
                1
            }
            TextureFormat::Rg32Float | TextureFormat::Rg32Uint | TextureFormat::Rg32Sint => 2,
            _ => 4,
        }
    }

    /// The scalar type a shader reads or writes through this format.
    pub fn scalar(self) -> Scalar {
        match self {
            TextureFormat::R32Uint | TextureFormat::Rg32Uint | TextureFormat::Rgba32Uint => Scalar::Uint,
            TextureFormat::R32Sint | TextureFormat::Rg32Sint | TextureFormat::Rgba32Sint => Scalar::Int,
            _ => Scalar::Float,
        }
    }

    /// The storage formats a `fine out` of type `ty` may declare with
    /// `@format(..)` (docs/language.md, section 3.5), in the order the
    /// compiler lists them; empty for a type that cannot be an output. A
    /// format must hold every component: single-channel formats only for
    /// scalars, two-channel ones for at most two components.
    pub fn for_output(ty: &ValueType) -> Vec<TextureFormat> {
        use TextureFormat as F;
        let any = match ty {
            ValueType::Scalar(Scalar::Float) => vec![F::R32Float, F::Rgba16Float, F::Rgba32Float, F::Rgba8Unorm],
            ValueType::Vector(Scalar::Float, _) => vec![F::Rgba32Float, F::Rgba16Float, F::Rgba8Unorm, F::Rg32Float],
            ValueType::Scalar(Scalar::Uint) | ValueType::Vector(Scalar::Uint, _) => vec![F::R32Uint, F::Rgba32Uint],
            ValueType::Scalar(Scalar::Int) | ValueType::Vector(Scalar::Int, _) => vec![F::R32Sint, F::Rgba32Sint],
            _ => vec![],
        };
        let n = ty.components();
        any.into_iter().filter(|f| f.components() >= n.min(4) || f.components() == 4).collect()
    }
}

impl fmt::Display for TextureFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for TextureFormat {
    type Err = String;

    fn from_str(text: &str) -> Result<TextureFormat, String> {
        TextureFormat::ALL
            .into_iter()
            .find(|f| f.name() == text)
            .ok_or_else(|| format!("`{text}` is not a texture format mrsl supports"))
    }
}

/// How a G-buffer channel's texture is sampled (its binding's sample type).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SampleType {
    UnfilterableFloat,
    Uint,
    Sint,
    /// A depth texture (`texture_depth_2d`), for a channel decoded from depth.
    Depth,
}

impl SampleType {
    /// The sample type of textures holding `scalar` components.
    pub fn of(scalar: Scalar) -> SampleType {
        match scalar {
            Scalar::Uint | Scalar::Bool => SampleType::Uint,
            Scalar::Int => SampleType::Sint,
            Scalar::Float => SampleType::UnfilterableFloat,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_types_round_trip_through_their_names() {
        for name in ["float", "uint2", "int4", "bool3", "float3x3", "float4[32]", "float2x2[3]"] {
            let ty: ValueType = name.parse().unwrap();
            assert_eq!(ty.to_string(), name);
        }
        assert_eq!("float4[32]".parse::<ValueType>().unwrap().components(), 128);
        for bad in ["", "float5", "vec3", "float[x]", "texture2d", "float1"] {
            assert!(bad.parse::<ValueType>().is_err(), "{bad}");
        }
    }

    #[test]
    fn formats_round_trip_and_unknown_ones_are_rejected() {
        for f in TextureFormat::ALL {
            assert_eq!(f.name().parse::<TextureFormat>(), Ok(f));
            assert_eq!(serde_json::to_string(&f).unwrap(), format!("\"{}\"", f.name()));
        }
        assert!("bgra8unorm".parse::<TextureFormat>().is_err());
        assert!(serde_json::from_str::<TextureFormat>("\"rgba8snorm\"").is_err());
    }

    #[test]
    fn output_formats_hold_every_component() {
        let names = |ty: &str| -> Vec<&str> {
            TextureFormat::for_output(&ty.parse().unwrap()).into_iter().map(TextureFormat::name).collect()
        };
        assert_eq!(names("float"), ["r32float", "rgba16float", "rgba32float", "rgba8unorm"]);
        assert_eq!(names("float2"), ["rgba32float", "rgba16float", "rgba8unorm", "rg32float"]);
        assert_eq!(names("float3"), ["rgba32float", "rgba16float", "rgba8unorm"]);
        assert_eq!(names("uint"), ["r32uint", "rgba32uint"]);
        assert_eq!(names("int3"), ["rgba32sint"]);
        assert!(names("bool").is_empty() && names("float4x4").is_empty());
    }
}
