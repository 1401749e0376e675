//! Typing rules of operators, constructors and `?:`, on the element type and
//! shape of their operands. They follow WGSL, the target language, including
//! how abstract (literal) types adapt to concrete ones.

use crate::syntax::ast::BinaryOp;
use crate::types::{self, Scalar, Type};

/// Whether the element types of `a` and `b` have a common type, as a scalar
/// widened to a vector must with the vector's elements.
pub(super) fn elements_unify(a: &Type, b: &Type) -> bool {
    let elem = |t: &Type| parts(t).map(|(e, _)| e).unwrap_or(Elem::Bool);
    unify_elem(elem(a), elem(b)).is_some()
}

/// The common type of two values of the same shape (for `?:`).
pub(super) fn unify(a: &Type, b: &Type) -> Option<Type> {
    if a.is_error() || b.is_error() {
        return Some(Type::Error);
    }
    let (ea, sa) = parts(a)?;
    let (eb, sb) = parts(b)?;
    if sa != sb {
        return None;
    }
    Some(build(unify_elem(ea, eb)?, sa))
}

pub(super) fn binary_type(op: BinaryOp, a: &Type, b: &Type) -> Result<Type, String> {
    use BinaryOp::*;
    let mismatch = || format!("cannot apply `{}` to `{a}` and `{b}`", op.symbol());
    let (ea, sa) = parts(a).ok_or_else(mismatch)?;
    let (eb, sb) = parts(b).ok_or_else(mismatch)?;
    let is_int = |e: Elem| matches!(e, Elem::Int | Elem::Uint | Elem::AbsInt);
    if let Shl | Shr = op {
        // The shift amount may be int or uint, whatever the left operand's
        // element type: WGSL wants u32, codegen converts.
        return if is_int(ea) && is_int(eb) && sa == sb && !matches!(sa, Shape::Mat(_)) {
            // A literal shifted by a concrete amount concretizes to `int`, as in WGSL.
            let elem = match (ea, eb) {
                (Elem::AbsInt, Elem::AbsInt) => Elem::AbsInt,
                (Elem::AbsInt, _) => Elem::Int,
                _ => ea,
            };
            Ok(build(elem, sa))
        } else {
            Err(mismatch())
        };
    }
    let elem = unify_elem(ea, eb).ok_or_else(|| {
        format!(
            "cannot apply `{}` to `{a}` and `{b}`: the element types differ (convert one side explicitly)",
            op.symbol()
        )
    })?;
    let is_num = |e: Elem| e != Elem::Bool;
    match op {
        Add | Sub | Mul | Div | Rem => {
            if !is_num(elem) {
                return Err(mismatch());
            }
            let shape = match (sa, sb) {
                (x, y) if x == y => {
                    if let Shape::Mat(_) = x
                        && matches!(op, Div | Rem)
                    {
                        return Err(mismatch());
                    }
                    x
                }
                (Shape::Scalar, Shape::Vec(n)) | (Shape::Vec(n), Shape::Scalar) => Shape::Vec(n),
                (Shape::Scalar, Shape::Mat(n)) | (Shape::Mat(n), Shape::Scalar) if op == Mul => Shape::Mat(n),
                (Shape::Mat(n), Shape::Vec(m)) | (Shape::Vec(m), Shape::Mat(n)) if op == Mul && n == m => Shape::Vec(n),
                _ => return Err(mismatch()),
            };
            if let Shape::Mat(_) = shape
                && !matches!(elem, Elem::Float | Elem::AbsFloat | Elem::AbsInt)
            {
                return Err(mismatch());
            }
            Ok(build(elem, shape))
        }
        Lt | Gt | Le | Ge | Eq | Ne => {
            if sa != sb || matches!(sa, Shape::Mat(_)) || (!is_num(elem) && matches!(op, Lt | Gt | Le | Ge)) {
                return Err(mismatch());
            }
            Ok(build(Elem::Bool, sa))
        }
        And | Or => {
            if elem == Elem::Bool && sa == Shape::Scalar && sb == Shape::Scalar {
                Ok(types::BOOL)
            } else {
                Err(format!("`{}` needs two `bool`s, found `{a}` and `{b}`", op.symbol()))
            }
        }
        BitAnd | BitOr | BitXor => {
            if (is_int(elem) || elem == Elem::Bool) && sa == sb && !matches!(sa, Shape::Mat(_)) {
                Ok(build(elem, sa))
            } else {
                Err(mismatch())
            }
        }
        Shl | Shr => unreachable!("shifts are typed above"),
    }
}

pub(super) fn construct_check(ty: &Type, args: &[Type]) -> Result<(), String> {
    let name = ty.name();
    match ty {
        Type::Texture2d | Type::Sampler | Type::Array(..) | Type::AbstractFloat | Type::AbstractInt | Type::Error => {
            Err(format!("`{name}` cannot be constructed"))
        }
        Type::Scalar(_) => match args {
            [a] if (a.is_value() || a.is_abstract()) && a.components() == 1 => Ok(()),
            [a] => Err(format!("cannot convert `{a}` to `{name}`")),
            _ => Err(format!("`{name}(...)` takes exactly one argument, {} given", args.len())),
        },
        Type::Vector(_, n) | Type::Matrix(n) => {
            if args.iter().any(|a| !a.is_value() && !a.is_abstract()) {
                return Err(format!("`{name}` is built from numbers, vectors or matrices"));
            }
            let is_matrix = matches!(ty, Type::Matrix(_));
            let target = ty.scalar().unwrap_or(Scalar::Float);
            // Components must already have the target's element type (or be
            // literals that adapt), as in WGSL; only a whole-vector
            // conversion `float3(int3)` changes element types.
            let component_fits = |a: &Type| match a {
                Type::AbstractInt => target != Scalar::Bool,
                Type::AbstractFloat => target == Scalar::Float,
                other => other.scalar() == Some(target),
            };
            if let [single] = args {
                if single == ty {
                    return Ok(());
                }
                if !is_matrix && single.vector_len() == ty.vector_len() && single.vector_len().is_some() {
                    return Ok(());
                }
                if !is_matrix && single.components() == 1 {
                    return if component_fits(single) {
                        Ok(())
                    } else {
                        Err(format!(
                            "cannot splat `{single}` into `{name}`: convert it first, e.g. `{}(x)`",
                            target.name()
                        ))
                    };
                }
            }
            if let Some(bad) = args.iter().find(|a| !component_fits(a)) {
                return Err(format!(
                    "`{name}` is built from `{}` components, but one argument is `{bad}` (convert it explicitly)",
                    target.name()
                ));
            }
            if is_matrix && args.iter().any(|a| a.scalar() != Some(Scalar::Float) && !a.is_abstract()) {
                return Err(format!("`{name}` is built from floats"));
            }
            let total: u32 = args.iter().map(|a| a.components()).sum();
            let want = ty.components();
            let columns_ok = !is_matrix
                || args.iter().all(|a| a.components() == 1)
                || args.iter().all(|a| a.vector_len() == Some(*n));
            if total == want && columns_ok {
                Ok(())
            } else if is_matrix && !columns_ok {
                Err(format!("`{name}` is built from {n} columns (`float{n}`) or {want} floats"))
            } else {
                Err(format!("`{name}` needs {want} components, but the arguments have {total}"))
            }
        }
    }
}

/// The element type of a value, literals included: typing rules work on
/// element and shape separately, as WGSL's overload tables do.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Elem {
    Bool,
    Int,
    Uint,
    Float,
    AbsInt,
    AbsFloat,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Shape {
    Scalar,
    Vec(u8),
    Mat(u8),
}

/// A value type as element and shape; `None` for textures, samplers and arrays.
fn parts(t: &Type) -> Option<(Elem, Shape)> {
    let elem = |s: Scalar| match s {
        Scalar::Bool => Elem::Bool,
        Scalar::Int => Elem::Int,
        Scalar::Uint => Elem::Uint,
        Scalar::Float => Elem::Float,
    };
    match t {
        Type::Scalar(s) => Some((elem(*s), Shape::Scalar)),
        Type::Vector(s, n) => Some((elem(*s), Shape::Vec(*n))),
        Type::Matrix(n) => Some((Elem::Float, Shape::Mat(*n))),
        Type::AbstractInt => Some((Elem::AbsInt, Shape::Scalar)),
        Type::AbstractFloat => Some((Elem::AbsFloat, Shape::Scalar)),
        _ => None,
    }
}

/// The type of `elem` and `shape`. A literal element stays abstract only as a scalar.
fn build(elem: Elem, shape: Shape) -> Type {
    let scalar = match elem {
        Elem::Bool => Scalar::Bool,
        Elem::Int => Scalar::Int,
        Elem::Uint => Scalar::Uint,
        Elem::Float => Scalar::Float,
        Elem::AbsInt if shape == Shape::Scalar => return Type::AbstractInt,
        Elem::AbsFloat if shape == Shape::Scalar => return Type::AbstractFloat,
        Elem::AbsInt => Scalar::Int,
        Elem::AbsFloat => Scalar::Float,
    };
    match shape {
        Shape::Scalar => Type::Scalar(scalar),
        Shape::Vec(n) => Type::Vector(scalar, n),
        Shape::Mat(n) => Type::Matrix(n),
    }
}

/// The common element type, if literals can adapt to make one.
fn unify_elem(a: Elem, b: Elem) -> Option<Elem> {
    use Elem::*;
    match (a, b) {
        _ if a == b => Some(a),
        (AbsInt, Int | Uint | Float | AbsFloat) => Some(b),
        (Int | Uint | Float | AbsFloat, AbsInt) => Some(a),
        (AbsFloat, Float) | (Float, AbsFloat) => Some(Float),
        _ => None,
    }
}
