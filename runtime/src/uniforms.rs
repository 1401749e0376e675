//! The user uniform block: values set by name, checked against the layout,
//! laid out as WGSL's uniform address space wants.

use crate::error::Error;
use mrsl_abi::{Scalar, UniformBlock, ValueType};
use std::collections::HashMap;

/// Uniform values set by name ([`crate::Shader::set_uniform`]).
#[derive(Default)]
pub(crate) struct UniformValues {
    values: HashMap<String, Vec<f64>>,
}

impl UniformValues {
    /// Sets `name` to `values` after checking both against the block.
    pub fn set(&mut self, block: Option<&UniformBlock>, name: &str, values: &[f64]) -> Result<(), Error> {
        let field = block
            .and_then(|u| u.fields.iter().find(|f| f.name == name))
            .ok_or_else(|| Error::UnknownUniform(name.to_string()))?;
        let expected = field.ty.components() as usize;
        if values.len() != expected {
            return Err(Error::UniformComponents {
                name: name.into(),
                ty: field.ty.to_string(),
                expected,
                found: values.len(),
            });
        }
        self.values.insert(name.to_string(), values.to_vec());
        Ok(())
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

/// Writes a uniform's components at the start of `out`, laid out as WGSL's
/// uniform address space wants (matrix columns 16-byte aligned but for
/// `mat2x2`; arrays hold 16-byte elements only, so their words are packed).
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
