//! Typing of builtin calls: applies a builtin's [`Signature`] (the table in
//! `crate::builtins`) to the argument types of one call. It gives the result
//! type, and the vector type scalar arguments must be widened to, because
//! WGSL builtins want every generic argument of the same type.

use super::typing::{elements_unify, unify};
use crate::builtins::{Accept, Builtin, Returns, Rule, Signature};
use crate::types::{self, Scalar, Type};

/// Why a builtin call does not type.
pub(super) enum BuiltinError {
    /// The wrong number of arguments; holds how many it takes, as the error says it.
    Arity(String),
    Types(String),
}

/// The result type of a call to `builtin` with arguments of types `args`,
/// and the type of the splat that scalar arguments need, if any.
pub(super) fn builtin_type(builtin: Builtin, args: &[Type]) -> Result<(Type, Option<Type>), BuiltinError> {
    use BuiltinError::*;
    let name = builtin.name();
    let Signature { arity, rule, returns } = builtin.signature();
    if !arity.accepts(args.len()) {
        return Err(Arity(arity.to_string()));
    }
    // The argument type T, its splat, and whether a literal T keeps its kind.
    let (t, splat, keeps_literal_kind) = match rule {
        Rule::Unary { accept } => {
            if !accept.accepts(&args[0]) {
                return Err(Types(format!("`{name}` needs {accept}, found `{}`", args[0])));
            }
            (args[0].clone(), None, accept.keeps_literal_kind())
        }
        Rule::Generic { accept, widen } => {
            let (t, splat) = generic(name, args, widen, &accept)?;
            (t, splat, accept.keeps_literal_kind())
        }
        Rule::Vectors { accept, same, then, what } => {
            let first = &args[0];
            if !accept.accepts(first)
                || args[1..same].iter().any(|a| a != first)
                || then.is_some_and(|then| !args[same].converts_to(&then))
            {
                return Err(Types(format!("`{name}` needs {what}")));
            }
            (first.clone(), None, accept.keeps_literal_kind())
        }
        Rule::Sample { coords } => {
            texture_args(name, args, coords)?;
            (args[0].clone(), None, false)
        }
        Rule::Load => {
            load_args(args)?;
            (args[0].clone(), None, false)
        }
    };
    Ok(match returns {
        Returns::Arg => (concrete(t, args, keeps_literal_kind), splat),
        Returns::Element => (Type::Scalar(t.scalar().unwrap_or(Scalar::Float)), None),
        Returns::Fixed(ty) => (ty, None),
    })
}

/// The generic type T of arguments that must agree, and the splat of the
/// scalars in `widen` positions when T is a vector. A literal T is `float`.
fn generic(name: &str, args: &[Type], widen: &[usize], accept: &Accept) -> Result<(Type, Option<Type>), BuiltinError> {
    use BuiltinError::*;
    let mut t: Option<Type> = None;
    for (p, a) in args.iter().enumerate() {
        if !accept.accepts(a) {
            return Err(Types(format!("`{name}` does not accept `{a}`")));
        }
        if widen.contains(&p) && a.components() == 1 {
            continue;
        }
        t = match t {
            None => Some(a.clone()),
            Some(prev) => Some(
                unify(&prev, a)
                    .filter(|u| !u.is_error())
                    .ok_or_else(|| Types(format!("`{name}` needs arguments of one type, found `{prev}` and `{a}`")))?,
            ),
        };
    }
    let t = match t {
        Some(t) => t,
        None => {
            // All arguments were scalars in widenable positions.
            let mut t = args[0].clone();
            for a in args {
                t = unify(&t, a).ok_or_else(|| Types(format!("`{name}` needs arguments of one type")))?;
            }
            t
        }
    };
    for &p in widen {
        let a = &args[p];
        // A scalar in a widened position must still be of T's element type
        // (WGSL converts literals, never `int` to `float`).
        if a.components() == 1 && !elements_unify(a, &t) {
            return Err(Types(format!("`{name}`: `{a}` does not match `{t}`")));
        }
    }
    let splat = if t.vector_len().is_some() { Some(t.clone()) } else { None };
    let t = if t.is_abstract() { types::FLOAT } else { t };
    Ok((t, splat))
}

/// What a `T` that is still a literal type becomes: `float`, or, for the
/// builtins that keep a literal's kind, the literals' common type made
/// concrete when every argument is one (`min(1, 2)` is an `int`).
fn concrete(t: Type, args: &[Type], keeps_literal_kind: bool) -> Type {
    if keeps_literal_kind && args.iter().all(|a| a.is_abstract()) {
        return args.iter().fold(Type::AbstractInt, |acc, a| unify(&acc, a).unwrap_or(acc)).concretize();
    }
    if t.is_abstract() { types::FLOAT } else { t }
}

/// `load`'s arguments; its messages name each one, since its coordinates
/// are texels, not uv.
fn load_args(args: &[Type]) -> Result<(), BuiltinError> {
    use BuiltinError::Types;
    if args[0] != Type::Texture2d {
        return Err(Types(format!("`load` needs a `texture2d` first, found `{}`", args[0])));
    }
    if args[1] != Type::Vector(Scalar::Int, 2) {
        return Err(Types(format!("`load` needs `int2` texel coordinates, found `{}`", args[1])));
    }
    if args.len() == 3 && !args[2].converts_to(&types::INT) {
        return Err(Types(format!("`load` needs an `int` level, found `{}`", args[2])));
    }
    Ok(())
}

/// A sampling call's arguments: a texture, a sampler, then coordinates that
/// convert to `coords`.
fn texture_args(name: &str, args: &[Type], coords: &[Type]) -> Result<(), BuiltinError> {
    if args[0] != Type::Texture2d {
        return Err(BuiltinError::Types(format!("`{name}` needs a `texture2d` first, found `{}`", args[0])));
    }
    if args[1] != Type::Sampler {
        return Err(BuiltinError::Types(format!("`{name}` needs a `sampler` second, found `{}`", args[1])));
    }
    for (a, want) in args[2..].iter().zip(coords) {
        if !a.converts_to(want) {
            return Err(BuiltinError::Types(format!("`{name}` expected `{want}`, found `{a}`")));
        }
    }
    Ok(())
}
