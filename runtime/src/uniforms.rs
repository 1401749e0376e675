//! The user uniform block: values set by name, checked against the layout
//! (the name, the count, and each value against its scalar type), laid out
//! as WGSL's uniform address space wants.

use crate::error::Error;
use mrsl_abi::{Field, Scalar, UniformBlock, ValueType};
use std::collections::HashMap;

/// Uniform values set by name ([`crate::Shader::set_uniform`]).
#[derive(Default)]
pub(crate) struct UniformValues {
    values: HashMap<String, Vec<f64>>,
}

impl UniformValues {
    /// Sets `name` to `values` after checking both against the block: the
    /// name, the count, and every value against the scalar type
    /// ([`check_value`]).
    pub fn set(&mut self, block: Option<&UniformBlock>, name: &str, values: &[f64]) -> Result<(), Error> {
        let field = field(block, name)?;
        let expected = field.ty.components() as usize;
        if values.len() != expected {
            return Err(Error::UniformComponents {
                name: name.into(),
                ty: field.ty.to_string(),
                expected,
                found: values.len(),
            });
        }
        for (index, &value) in values.iter().enumerate() {
            check_value(field, index, value)?;
        }
        self.values.insert(name.to_string(), values.to_vec());
        Ok(())
    }

    /// [`UniformValues::set`] from a typed setter, whose values are of the
    /// Rust type `given` (`"u32"`): refused unless the uniform's scalar type
    /// is `scalar`.
    pub fn set_typed(
        &mut self,
        block: Option<&UniformBlock>,
        name: &str,
        (scalar, given): (Scalar, &'static str),
        values: &[f64],
    ) -> Result<(), Error> {
        let field = field(block, name)?;
        if field.ty.scalar() != scalar {
            return Err(Error::UniformType { name: name.into(), ty: field.ty.to_string(), given });
        }
        self.set(block, name, values)
    }

    /// The value set for `name`, if one was (not its default).
    pub fn get(&self, name: &str) -> Option<&[f64]> {
        self.values.get(name).map(Vec::as_slice)
    }

    /// The block's bytes, from set values and defaults.
    pub fn bytes(&self, block: &UniformBlock) -> Result<Vec<u8>, Error> {
        let mut bytes = vec![0u8; block.size as usize];
        for field in &block.fields {
            let values = self
                .values
                .get(&field.name)
                .or(field.default.as_ref())
                .ok_or_else(|| Error::MissingUniform(field.name.clone()))?;
            write_field(&mut bytes[field.offset as usize..], &field.ty, values);
        }
        Ok(bytes)
    }
}

/// The value uniform `name` of the block.
fn field<'b>(block: Option<&'b UniformBlock>, name: &str) -> Result<&'b Field, Error> {
    block.and_then(|u| u.fields.iter().find(|f| f.name == name)).ok_or_else(|| Error::UnknownUniform(name.to_string()))
}

/// Whether `value`, component `index` of `field`, is one its scalar type
/// holds exactly as given: a finite float within f32's range, an integer
/// within i32's or u32's range, a bool as 0 or 1 ([`Error::UniformValue`]
/// otherwise). [`write_field`] then converts without loss of meaning.
fn check_value(field: &Field, index: usize, value: f64) -> Result<(), Error> {
    let integral = value.is_finite() && value.fract() == 0.0;
    let reason = match field.ty.scalar() {
        Scalar::Float if !value.is_finite() => "is not a finite number",
        Scalar::Float if value.abs() > f64::from(f32::MAX) => "is beyond the range of a 32-bit float",
        Scalar::Int | Scalar::Uint if !integral => "is not an integer",
        Scalar::Int if value < f64::from(i32::MIN) || value > f64::from(i32::MAX) => {
            "is outside the range of an `int` (i32, -2147483648 to 2147483647)"
        }
        Scalar::Uint if value < 0.0 || value > f64::from(u32::MAX) => {
            "is outside the range of a `uint` (u32, 0 to 4294967295)"
        }
        Scalar::Bool if value != 0.0 && value != 1.0 => "is not 0 or 1 (a bool is set as 0 for false, 1 for true)",
        _ => return Ok(()),
    };
    Err(Error::UniformValue { name: field.name.clone(), ty: field.ty.to_string(), index, value, reason })
}

/// Writes a uniform's components at the start of `out`, laid out as WGSL's
/// uniform address space wants (matrix columns 16-byte aligned but for
/// `mat2x2`; arrays hold 16-byte elements only, so their words are packed).
/// The values were checked ([`check_value`]), so the casts are exact but
/// for float rounding.
fn write_field(out: &mut [u8], ty: &ValueType, values: &[f64]) {
    let scalar = ty.scalar();
    let mut put = |index: usize, v: f64| {
        let bytes = match scalar {
            Scalar::Float => (v as f32).to_le_bytes(),
            Scalar::Int => (v as i32).to_le_bytes(),
            Scalar::Uint | Scalar::Bool => (v as u32).to_le_bytes(),
        };
        out[index * 4..index * 4 + 4].copy_from_slice(&bytes);
    };
    if let ValueType::Matrix(n) = ty {
        let n = usize::from(*n);
        // Columns of a mat2x2 are 8 bytes apart, of mat3x3/mat4x4 16 bytes.
        let column_words = if n == 2 { 2 } else { 4 };
        for col in 0..n {
            for row in 0..n {
                put(col * column_words + row, values[col * n + row]);
            }
        }
    } else {
        for (i, v) in values.iter().enumerate() {
            put(i, *v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block of one uniform per type, with offsets as the compiler lays
    /// them out (16-byte aligned; nothing here reads across fields).
    fn block() -> UniformBlock {
        let fields: Vec<Field> = [("gain", "float"), ("light_count", "uint"), ("bias", "int"), ("on", "bool")]
            .into_iter()
            .chain([("tint", "float3"), ("lights", "uint4[2]")])
            .enumerate()
            .map(|(k, (name, ty))| Field {
                name: name.into(),
                ty: ty.parse().unwrap(),
                wgsl_type: String::new(),
                offset: 32 * k as u32,
                size: 32,
                default: None,
            })
            .collect();
        UniformBlock { group: 0, binding: 1, size: 32 * fields.len() as u32, fields }
    }

    fn set(name: &str, values: &[f64]) -> Result<(), Error> {
        UniformValues::default().set(Some(&block()), name, values)
    }

    fn refused(name: &str, values: &[f64]) -> (usize, &'static str) {
        match set(name, values) {
            Err(Error::UniformValue { name: n, index, reason, .. }) if n == name => (index, reason),
            other => panic!("{name} = {values:?}: expected a value error, got {other:?}"),
        }
    }

    #[test]
    fn integers_must_be_integral_and_in_range() {
        assert!(refused("light_count", &[16.7]).1.contains("not an integer"));
        assert!(refused("light_count", &[-1.0]).1.contains("range of a `uint`"));
        assert!(refused("light_count", &[4294967296.0]).1.contains("range of a `uint`"));
        assert!(refused("light_count", &[f64::NAN]).1.contains("not an integer"));
        assert!(refused("bias", &[0.5]).1.contains("not an integer"));
        assert!(refused("bias", &[2147483648.0]).1.contains("range of an `int`"));
        assert!(refused("bias", &[-2147483649.0]).1.contains("range of an `int`"));
        // The component at fault is named.
        assert_eq!(refused("lights", &[1.0, 2.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0]).0, 2);
        for (name, values) in [
            ("light_count", &[16.0][..]),
            ("light_count", &[4294967295.0]),
            ("light_count", &[-0.0]),
            ("bias", &[-2147483648.0]),
            ("bias", &[2147483647.0]),
            ("lights", &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]),
        ] {
            set(name, values).unwrap_or_else(|e| panic!("{name} = {values:?}: {e}"));
        }
    }

    #[test]
    fn bools_are_zero_or_one() {
        assert!(refused("on", &[0.5]).1.contains("not 0 or 1"));
        assert!(refused("on", &[2.0]).1.contains("not 0 or 1"));
        set("on", &[0.0]).unwrap();
        set("on", &[1.0]).unwrap();
    }

    #[test]
    fn floats_are_finite_and_within_f32() {
        assert!(refused("gain", &[f64::INFINITY]).1.contains("not a finite number"));
        assert!(refused("tint", &[0.0, f64::NAN, 0.0]).1.contains("not a finite number"));
        assert_eq!(refused("tint", &[0.0, 0.0, 1e39]), (2, "is beyond the range of a 32-bit float"));
        set("gain", &[16.7]).unwrap();
        set("tint", &[-3.5, 0.0, 3.4e38]).unwrap();
    }

    #[test]
    fn the_message_names_the_uniform_its_type_and_the_value() {
        let e = set("light_count", &[16.7]).unwrap_err().to_string();
        assert_eq!(e, "uniform `light_count` is `uint`, but its value 16.7 is not an integer");
        let e = set("lights", &[1.0, 2.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0]).unwrap_err().to_string();
        assert!(e.starts_with("uniform `lights` is `uint4[2]`, but component 2, 3.5,"), "{e}");
    }

    #[test]
    fn typed_setters_take_the_uniforms_scalar_type_only() {
        let mut values = UniformValues::default();
        let block = block();
        values.set_typed(Some(&block), "light_count", (Scalar::Uint, "u32"), &[16.0]).unwrap();
        match values.set_typed(Some(&block), "gain", (Scalar::Uint, "u32"), &[1.0]) {
            Err(Error::UniformType { name, ty, given: "u32" }) => {
                assert_eq!((name.as_str(), ty.as_str()), ("gain", "float"))
            }
            other => panic!("{other:?}"),
        }
        // The other checks still apply, and the values reach the block.
        assert!(matches!(
            values.set_typed(Some(&block), "tint", (Scalar::Float, "f32"), &[1.0]),
            Err(Error::UniformComponents { expected: 3, found: 1, .. })
        ));
        assert!(matches!(
            values.set_typed(Some(&block), "nope", (Scalar::Float, "f32"), &[]),
            Err(Error::UnknownUniform(_))
        ));
        assert_eq!(values.values["light_count"], [16.0]);
        assert_eq!(values.get("light_count"), Some(&[16.0][..]));
        assert_eq!(values.get("gain"), None, "never set: the default applies");
    }

    /// Valid values are written as before: ints and uints exactly, bools as 0 or 1.
    #[test]
    fn checked_values_pack_as_their_types() {
        let block = block();
        let mut values = UniformValues::default();
        for (name, v) in [("gain", vec![0.5]), ("light_count", vec![16.0]), ("bias", vec![-3.0]), ("on", vec![1.0])] {
            values.set(Some(&block), name, &v).unwrap();
        }
        values.set(Some(&block), "tint", &[1.0, 2.0, 3.0]).unwrap();
        values.set(Some(&block), "lights", &[5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0]).unwrap();
        let bytes = values.bytes(&block).unwrap();
        let word = |k: usize| &bytes[k * 4..k * 4 + 4];
        assert_eq!(word(0), 0.5f32.to_le_bytes());
        assert_eq!(word(8), 16u32.to_le_bytes());
        assert_eq!(word(16), (-3i32).to_le_bytes());
        assert_eq!(word(24), 1u32.to_le_bytes());
        assert_eq!(word(34), 3.0f32.to_le_bytes());
        assert_eq!(word(47), 12u32.to_le_bytes());
    }
}
