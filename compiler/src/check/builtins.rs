//! Typing of builtin calls: the result type of each builtin, and which scalar
//! arguments codegen must widen to the generic vector type.

use super::typing::{elements_unify, unify};
use crate::types::{self, Scalar, Type};

pub(super) enum BuiltinError {
    Arity(&'static str),
    Types(String),
}

/// Result type of a builtin call, and the vector type scalar arguments must
/// be widened to (WGSL builtins want all generic arguments of one type).
pub(super) fn builtin_type(name: &str, args: &[Type]) -> Result<(Type, Option<Type>), BuiltinError> {
    use BuiltinError::*;
    let float_gen = |t: &Type| {
        matches!(
            t,
            Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _) | Type::AbstractFloat | Type::AbstractInt
        )
    };
    let num_gen = |t: &Type| {
        matches!(
            t,
            Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
                | Type::AbstractFloat
                | Type::AbstractInt
        )
    };
    let fvec = |t: &Type| matches!(t, Type::Vector(Scalar::Float, _));
    let need = |n: usize, text: &'static str| {
        if args.len() == n { Ok(()) } else { Err(Arity(text)) }
    };
    // The generic type T of arguments that must agree, widening scalars.
    let generic = |positions: &[usize],
                   allow_scalar: &[usize],
                   accept: &dyn Fn(&Type) -> bool|
     -> Result<(Type, Option<Type>), BuiltinError> {
        let mut t: Option<Type> = None;
        for &p in positions {
            let a = &args[p];
            if !accept(a) {
                return Err(Types(format!("`{name}` does not accept `{a}`")));
            }
            if allow_scalar.contains(&p) && a.components() == 1 {
                continue;
            }
            t =
                match t {
                    None => Some(a.clone()),
                    Some(prev) => Some(unify(&prev, a).filter(|u| !u.is_error()).ok_or_else(|| {
                        Types(format!("`{name}` needs arguments of one type, found `{prev}` and `{a}`"))
                    })?),
                };
        }
        let t = match t {
            Some(t) => t,
            None => {
                // All arguments were scalars in widenable positions.
                let mut t = args[positions[0]].clone();
                for &p in positions {
                    t = unify(&t, &args[p]).ok_or_else(|| Types(format!("`{name}` needs arguments of one type")))?;
                }
                t
            }
        };
        for &p in allow_scalar {
            let a = &args[p];
            if a.components() == 1 && t.vector_len().is_some() && !elements_unify(a, &t) {
                return Err(Types(format!("`{name}`: `{a}` does not match `{t}`")));
            }
        }
        let splat = if t.vector_len().is_some() { Some(t.clone()) } else { None };
        let t = if t.is_abstract() { Type::Scalar(Scalar::Float) } else { t };
        Ok((t, splat))
    };

    match name {
        "sin" | "cos" | "tan" | "asin" | "acos" | "atan" | "sinh" | "cosh" | "tanh" | "exp" | "exp2" | "log"
        | "log2" | "sqrt" | "inversesqrt" | "floor" | "ceil" | "fract" | "round" | "trunc" | "saturate" | "radians"
        | "degrees" | "ddx" | "ddy" | "fwidth" => {
            need(1, "1 argument")?;
            if !float_gen(&args[0]) {
                return Err(Types(format!("`{name}` needs a float or float vector, found `{}`", args[0])));
            }
            Ok((if args[0].is_abstract() { types::FLOAT } else { args[0].clone() }, None))
        }
        "abs" | "sign" => {
            need(1, "1 argument")?;
            if !num_gen(&args[0]) || (name == "sign" && args[0].scalar() == Some(Scalar::Uint)) {
                return Err(Types(format!("`{name}` needs a number or vector, found `{}`", args[0])));
            }
            Ok((args[0].concretize(), None))
        }
        "pow" | "atan2" | "step" => {
            need(2, "2 arguments")?;
            let allow: &[usize] = if name == "step" { &[0] } else { &[] };
            generic(&[0, 1], allow, &float_gen)
        }
        "min" | "max" => {
            need(2, "2 arguments")?;
            generic(&[0, 1], &[0, 1], &num_gen)
                .map(|(t, s)| (if args.iter().all(|a| a.is_abstract()) { args[0].concretize() } else { t }, s))
                .map(|(t, s)| (concrete_num(&t, args), s))
        }
        "clamp" => {
            need(3, "3 arguments")?;
            generic(&[0, 1, 2], &[1, 2], &num_gen).map(|(t, s)| (concrete_num(&t, args), s))
        }
        "mix" | "lerp" => {
            need(3, "3 arguments")?;
            generic(&[0, 1, 2], &[2], &float_gen)
        }
        "smoothstep" => {
            need(3, "3 arguments")?;
            generic(&[0, 1, 2], &[0, 1], &float_gen)
        }
        "dot" => {
            need(2, "2 arguments")?;
            let ok = |t: &Type| matches!(t, Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _));
            if !ok(&args[0]) || args[0] != args[1] {
                return Err(Types("`dot` needs two vectors of the same type".into()));
            }
            Ok((Type::Scalar(args[0].scalar().unwrap_or(Scalar::Float)), None))
        }
        "cross" => {
            need(2, "2 arguments")?;
            if args[0] != Type::Vector(Scalar::Float, 3) || args[1] != args[0] {
                return Err(Types("`cross` needs two `float3`s".into()));
            }
            Ok((args[0].clone(), None))
        }
        "normalize" => {
            need(1, "1 argument")?;
            if !fvec(&args[0]) {
                return Err(Types(format!("`normalize` needs a float vector, found `{}`", args[0])));
            }
            Ok((args[0].clone(), None))
        }
        "length" => {
            need(1, "1 argument")?;
            if !float_gen(&args[0]) {
                return Err(Types(format!("`length` needs a float or float vector, found `{}`", args[0])));
            }
            Ok((types::FLOAT, None))
        }
        "distance" => {
            need(2, "2 arguments")?;
            generic(&[0, 1], &[], &float_gen).map(|_| (types::FLOAT, None))
        }
        "reflect" => {
            need(2, "2 arguments")?;
            if !fvec(&args[0]) || args[0] != args[1] {
                return Err(Types("`reflect` needs two float vectors of the same size".into()));
            }
            Ok((args[0].clone(), None))
        }
        "refract" => {
            need(3, "3 arguments")?;
            if !fvec(&args[0]) || args[0] != args[1] || !args[2].converts_to(&types::FLOAT) {
                return Err(Types("`refract` needs (floatN incident, floatN normal, float eta)".into()));
            }
            Ok((args[0].clone(), None))
        }
        "faceforward" => {
            need(3, "3 arguments")?;
            if !fvec(&args[0]) || args[0] != args[1] || args[0] != args[2] {
                return Err(Types("`faceforward` needs three float vectors of the same size".into()));
            }
            Ok((args[0].clone(), None))
        }
        "determinant" | "transpose" => {
            need(1, "1 argument")?;
            match args[0] {
                Type::Matrix(_) => Ok((if name == "determinant" { types::FLOAT } else { args[0].clone() }, None)),
                _ => Err(Types(format!("`{name}` needs a matrix, found `{}`", args[0]))),
            }
        }
        "any" | "all" => {
            need(1, "1 argument")?;
            match args[0] {
                Type::Scalar(Scalar::Bool) | Type::Vector(Scalar::Bool, _) => Ok((types::BOOL, None)),
                _ => Err(Types(format!("`{name}` needs a bool vector, found `{}`", args[0]))),
            }
        }
        "sample" => {
            need(3, "3 arguments (texture, sampler, float2 uv)")?;
            texture_args(name, args, &[Type::Vector(Scalar::Float, 2)])?;
            Ok((Type::Vector(Scalar::Float, 4), None))
        }
        "sample_level" => {
            need(4, "4 arguments (texture, sampler, float2 uv, float lod)")?;
            texture_args(name, args, &[Type::Vector(Scalar::Float, 2), types::FLOAT])?;
            Ok((Type::Vector(Scalar::Float, 4), None))
        }
        "sample_grad" => {
            need(5, "5 arguments (texture, sampler, float2 uv, float2 ddx, float2 ddy)")?;
            let f2 = Type::Vector(Scalar::Float, 2);
            texture_args(name, args, &[f2.clone(), f2.clone(), f2])?;
            Ok((Type::Vector(Scalar::Float, 4), None))
        }
        "load" => {
            if args.len() != 2 && args.len() != 3 {
                return Err(Arity("2 or 3 arguments (texture, int2 coord [, int level])"));
            }
            if args[0] != Type::Texture2d {
                return Err(Types(format!("`load` needs a `texture2d` first, found `{}`", args[0])));
            }
            if args[1] != Type::Vector(Scalar::Int, 2) {
                return Err(Types(format!("`load` needs `int2` texel coordinates, found `{}`", args[1])));
            }
            if args.len() == 3 && !args[2].converts_to(&types::INT) {
                return Err(Types(format!("`load` needs an `int` level, found `{}`", args[2])));
            }
            Ok((Type::Vector(Scalar::Float, 4), None))
        }
        "texture_size" => {
            need(1, "1 argument")?;
            if args[0] != Type::Texture2d {
                return Err(Types(format!("`texture_size` needs a `texture2d`, found `{}`", args[0])));
            }
            Ok((Type::Vector(Scalar::Int, 2), None))
        }
        _ => Err(Types(format!("unknown builtin `{name}`"))),
    }
}

fn concrete_num(t: &Type, args: &[Type]) -> Type {
    if args.iter().all(|a| a.is_abstract()) {
        args.iter().fold(Type::AbstractInt, |acc, a| unify(&acc, a).unwrap_or(acc)).concretize()
    } else {
        t.clone()
    }
}

fn texture_args(name: &str, args: &[Type], rest: &[Type]) -> Result<(), BuiltinError> {
    if args[0] != Type::Texture2d {
        return Err(BuiltinError::Types(format!("`{name}` needs a `texture2d` first, found `{}`", args[0])));
    }
    if args[1] != Type::Sampler {
        return Err(BuiltinError::Types(format!("`{name}` needs a `sampler` second, found `{}`", args[1])));
    }
    for (a, want) in args[2..].iter().zip(rest) {
        if !a.converts_to(want) {
            return Err(BuiltinError::Types(format!("`{name}` expected `{want}`, found `{a}`")));
        }
    }
    Ok(())
}
