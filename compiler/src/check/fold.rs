//! WGSL's constant expressions in effect and function bodies, and the checks
//! WGSL makes on them when a shader is created.
//!
//! WGSL evaluates every expression made only of literals, constants,
//! operators, constructors and conversions, swizzles, indexing, `select`
//! (our `?:`) and most math builtins when the shader is created, and
//! rejects the shader where such an evaluation fails: an integer division
//! by zero, a result its type cannot hold, a float that is not finite, a
//! builtin outside its domain, an abstract value that does not fit the
//! concrete type it is converted to. It also rejects some operations whose
//! other operands are not constant: an integer division by a constant zero,
//! a shift by a constant amount of 32 or more, a constant index outside the
//! vector, matrix or array. naga, which validates every kernel (and which
//! wgpu runs when the engine creates the shader), checks all of these.
//!
//! The checker folds the same expressions, in the arithmetic naga uses
//! (`float` in `f32`, literals in `f64`, `int` and `uint` as integers), and
//! reports what would be rejected: E0205 for operators and conversions,
//! E0213 for builtins and E0214 for indices. Its rules are those of WGSL,
//! and, where naga is more permissive than they are (it wraps `int`
//! arithmetic, saturates `int(3e9)`, keeps literal arithmetic in 64 bits),
//! stricter: a program the checks accept never makes naga reject a kernel.
//! The builtins naga leaves to run time (`mix`, `smoothstep`, `reflect`,
//! `refract`, `faceforward`, `determinant`, `transpose`) are not folded.
//!
//! The folded values go to `Checked::constants`. Code generation still
//! writes the expressions, and naga computes their values; it reads the
//! table to know which values naga sees as constant (a local initialised
//! with one is declared `var`, since naga also folds what a `let` names,
//! which WGSL does not: `int zero = 0; x / zero` must stay a division at run
//! time).

use super::{Callee, Checker, ConstValue, Symbol, err};
use crate::builtins::Builtin;
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};

/// The arithmetic a value is computed in, as naga computes it.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    /// An integer literal or literal arithmetic (64-bit in naga, held to the
    /// `int` range here).
    AbsInt,
    /// A float literal or literal arithmetic (`f64`).
    AbsFloat,
    I32,
    U32,
    F32,
    Bool,
}

impl Kind {
    fn of(ty: &Type) -> Option<Kind> {
        Some(match ty {
            Type::AbstractInt => Kind::AbsInt,
            Type::AbstractFloat => Kind::AbsFloat,
            _ => match ty.scalar()? {
                Scalar::Int => Kind::I32,
                Scalar::Uint => Kind::U32,
                Scalar::Float => Kind::F32,
                Scalar::Bool => Kind::Bool,
            },
        })
    }

    fn is_abstract(self) -> bool {
        matches!(self, Kind::AbsInt | Kind::AbsFloat)
    }

    fn is_int(self) -> bool {
        matches!(self, Kind::AbsInt | Kind::I32 | Kind::U32)
    }

    fn is_float(self) -> bool {
        matches!(self, Kind::AbsFloat | Kind::F32)
    }

    /// The kind two operands of one operation are computed in: a concrete
    /// operand's, to which a literal converts, else the wider literal kind.
    fn common(a: Kind, b: Kind) -> Kind {
        match (a, b) {
            _ if a == b => a,
            (x, _) if !x.is_abstract() => x,
            (_, y) if !y.is_abstract() => y,
            _ => Kind::AbsFloat,
        }
    }

    /// The type named in messages.
    fn name(self) -> &'static str {
        match self {
            Kind::AbsInt | Kind::I32 => "int",
            Kind::U32 => "uint",
            Kind::AbsFloat | Kind::F32 => "float",
            Kind::Bool => "bool",
        }
    }

    /// Whether `x` is a value of this kind. Literal integers are held to the
    /// `int` range and literal floats to the `float` range wherever they are
    /// used, as docs/language.md says, which is stricter than naga.
    fn fits(self, x: f64) -> bool {
        match self {
            Kind::AbsInt | Kind::I32 => (i32::MIN as f64..=i32::MAX as f64).contains(&x),
            Kind::U32 => (0.0..=u32::MAX as f64).contains(&x),
            Kind::AbsFloat | Kind::F32 => x.is_finite() && x.abs() <= f32::MAX as f64,
            Kind::Bool => true,
        }
    }

    /// `x` as this kind holds it: `float` rounds to `f32`.
    fn round(self, x: f64) -> f64 {
        if self == Kind::F32 { x as f32 as f64 } else { x }
    }
}

/// The element type of `ty` that `values` do not fit, if any: for the
/// values of uniform defaults, which the layout carries and the runtime
/// writes into the uniform block as that type.
pub(super) fn misfit(ty: &Type, values: &[f64]) -> Option<&'static str> {
    let kind = Kind::of(ty)?;
    if values.iter().all(|x| kind.fits(*x)) { None } else { Some(kind.name()) }
}

/// Why a constant operation fails.
enum Fail {
    DivideByZero,
    /// The result does not fit its kind (with whether a float went infinite or NaN).
    Range(Kind, bool),
}

/// A float operation in `kind`'s arithmetic: `f32` for `float`, `f64` for
/// literals, as naga computes it.
fn in_kind(kind: Kind, x: f64, f32_op: impl Fn(f32) -> f32, f64_op: impl Fn(f64) -> f64) -> f64 {
    if kind == Kind::AbsFloat { f64_op(x) } else { f32_op(x as f32) as f64 }
}

/// A two-operand float operation in `kind`'s arithmetic.
fn in_kind2(kind: Kind, x: f64, y: f64, f32_op: impl Fn(f32, f32) -> f32, f64_op: impl Fn(f64, f64) -> f64) -> f64 {
    if kind == Kind::AbsFloat { f64_op(x, y) } else { f32_op(x as f32, y as f32) as f64 }
}

/// `x op y` in `kind` (`+ - * / %` and the bitwise operators).
fn arith(kind: Kind, op: BinaryOp, x: f64, y: f64) -> Result<f64, Fail> {
    use BinaryOp::*;
    let r = if kind.is_float() {
        in_kind2(
            kind,
            x,
            y,
            |a, b| match op {
                Add => a + b,
                Sub => a - b,
                Mul => a * b,
                Div => a / b,
                _ => a % b,
            },
            |a, b| match op {
                Add => a + b,
                Sub => a - b,
                Mul => a * b,
                Div => a / b,
                _ => a % b,
            },
        )
    } else {
        // Integers in range are exact in `f64`, and so are sums and
        // differences of two; a product may round, but only where it is far
        // outside the range anyway.
        let (a, b) = (x as i64, y as i64);
        match op {
            Add => x + y,
            Sub => x - y,
            Mul => x * y,
            Div | Rem if b == 0 => return Err(Fail::DivideByZero),
            // naga computes `int` with `checked_div`/`checked_rem`, which
            // fail for the most negative int divided by -1.
            Div | Rem if kind == Kind::I32 && a == i32::MIN as i64 && b == -1 => {
                return Err(Fail::Range(kind, false));
            }
            Div => (a / b) as f64,
            Rem => (a % b) as f64,
            BitAnd => bits(kind, a & b),
            BitOr => bits(kind, a | b),
            _ => bits(kind, a ^ b),
        }
    };
    if kind.fits(r) { Ok(r) } else { Err(Fail::Range(kind, kind.is_float() && !r.is_finite())) }
}

/// The value of integer bits `v` in `kind`: `uint`'s are unsigned.
fn bits(kind: Kind, v: i64) -> f64 {
    match kind {
        Kind::U32 => (v as u32) as f64,
        Kind::I32 => (v as i32) as f64,
        _ => v as f64,
    }
}

/// Component `i` of a value, a scalar standing for every component.
fn at(v: &ConstValue, i: usize) -> f64 {
    if v.values.len() == 1 { v.values[0] } else { v.values[i] }
}

/// A `bool` as a value.
fn truth(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

impl Checker<'_> {
    /// Checks expression `e`, of type `t`, against WGSL's rules for constant
    /// operands, and folds it when all its operands are constant. Returns
    /// `t`, or `Type::Error` when it reported an error.
    pub(super) fn fold(&mut self, e: &Expr, t: Type) -> Type {
        match self.fold_expr(e, &t) {
            Ok(Some(v)) => {
                self.out.constants.insert(e.id, v);
                t
            }
            Ok(None) => t,
            Err(d) => {
                self.error(d);
                Type::Error
            }
        }
    }

    /// The folded value of an operand that the checker has already seen.
    fn value(&self, e: &Expr) -> Option<ConstValue> {
        self.out.constants.get(&e.id).cloned()
    }

    fn fold_expr(&mut self, e: &Expr, t: &Type) -> Result<Option<ConstValue>, Diagnostic> {
        let scalar = |ty: Type, v: f64| Ok(Some(ConstValue { ty, values: vec![v] }));
        match &e.kind {
            ExprKind::Int(v, IntSuffix::None) => scalar(Type::AbstractInt, *v as f64),
            // `2147483648i` is reported as a literal out of range already.
            ExprKind::Int(v, IntSuffix::I) if *v > i32::MAX as u64 => Ok(None),
            ExprKind::Int(v, IntSuffix::I) => scalar(t.clone(), *v as f64),
            ExprKind::Int(v, IntSuffix::U) => scalar(t.clone(), *v as f64),
            ExprKind::Float(v) => scalar(Type::AbstractFloat, *v),
            ExprKind::Bool(b) => scalar(t.clone(), truth(*b)),
            // Every constant is evaluated before the bodies are checked, and
            // those a constant's initialiser names before it (a cycle is
            // reported there, once).
            ExprKind::Name(_) => Ok(match self.out.symbols.get(&e.id) {
                Some(Symbol::Const(id)) if self.evaluated_consts.contains(&id.0) => {
                    self.out.consts[id.index()].value.clone().map(|v| {
                        let kind = Kind::of(&v.ty).unwrap_or(Kind::F32);
                        ConstValue { values: v.values.iter().map(|x| kind.round(*x)).collect(), ty: v.ty }
                    })
                }
                _ => None,
            }),
            ExprKind::Unary(op, inner) => {
                let Some(v) = self.value(inner) else { return Ok(None) };
                let Some(kind) = Kind::of(&v.ty) else { return Ok(None) };
                let mut values = Vec::with_capacity(v.values.len());
                for &x in &v.values {
                    values.push(match op {
                        UnaryOp::Pos => x,
                        UnaryOp::Neg => -x,
                        UnaryOp::Not => truth(x == 0.0),
                        UnaryOp::BitNot => bits(kind, !(x as i64)),
                    });
                }
                if values.iter().any(|x| !kind.fits(*x)) {
                    return Err(out_of_range(e.span, kind, false));
                }
                Ok(Some(ConstValue { ty: v.ty, values }))
            }
            ExprKind::Binary(op, a, b) => self.fold_binary(e, t, *op, a, b),
            ExprKind::Ternary(c, a, b) => {
                // `select(b, a, c)`: both branches convert to the result type.
                self.fits_type(a, t)?;
                self.fits_type(b, t)?;
                let (Some(c), Some(x), Some(y)) = (self.value(c), self.value(a), self.value(b)) else {
                    return Ok(None);
                };
                let kind = Kind::of(t).unwrap_or(Kind::F32);
                let picked = if c.values[0] != 0.0 { x } else { y };
                Ok(Some(ConstValue { ty: t.clone(), values: picked.values.iter().map(|v| kind.round(*v)).collect() }))
            }
            ExprKind::Field { base, field } => {
                let Some(v) = self.value(base).filter(|v| !v.values.is_empty()) else { return Ok(None) };
                let values = field
                    .name
                    .chars()
                    .map(|c| v.values["xyzwrgba".find(c).map_or(0, |k| k % 4).min(v.values.len() - 1)])
                    .collect();
                Ok(Some(ConstValue { ty: t.clone(), values }))
            }
            ExprKind::Index { base, index } => self.fold_index(t, base, index),
            ExprKind::Call { args, .. } => match self.out.callees.get(&e.id).cloned() {
                Some(Callee::Construct(ty)) => self.fold_construct(e, &ty, args),
                Some(Callee::Builtin(builtin)) => self.fold_builtin(e, t, builtin, args),
                // A user function's arguments are checked against its
                // parameters where the call is typed.
                _ => Ok(None),
            },
        }
    }

    /// Reports a literal constant `e` (an abstract value) that does not fit
    /// `target`'s element type, to which WGSL converts it: `-1` where a
    /// `uint` is wanted. Concrete values never convert implicitly.
    pub(super) fn fits_type(&self, e: &Expr, target: &Type) -> Result<(), Diagnostic> {
        let (Some(v), Some(kind)) = (self.out.constants.get(&e.id), Kind::of(target)) else { return Ok(()) };
        if !v.ty.is_abstract() || kind.is_abstract() {
            return Ok(());
        }
        if v.values.iter().all(|x| kind.fits(*x)) { Ok(()) } else { Err(out_of_range(e.span, kind, false)) }
    }

    /// Like [`Checker::fits_type`], reporting the error.
    pub(super) fn check_fits(&mut self, e: &Expr, target: &Type) {
        if let Err(d) = self.fits_type(e, target) {
            self.error(d);
        }
    }

    fn fold_binary(
        &mut self,
        e: &Expr,
        t: &Type,
        op: BinaryOp,
        a: &Expr,
        b: &Expr,
    ) -> Result<Option<ConstValue>, Diagnostic> {
        use BinaryOp::*;
        let (ta, tb) = (self.out.types[a.id.0 as usize].clone(), self.out.types[b.id.0 as usize].clone());
        let (Some(ka), Some(kb)) = (Kind::of(&ta), Kind::of(&tb)) else { return Ok(None) };
        let (va, vb) = (self.value(a), self.value(b));
        if let Shl | Shr = op {
            return self.fold_shift(e, t, op, (a, ka, va), (b, kb, vb));
        }
        let kind = Kind::common(ka, kb);
        // A literal operand converts to the other operand's type.
        if ka.is_abstract() && !kind.is_abstract() {
            self.fits_type(a, &tb)?;
        }
        if kb.is_abstract() && !kind.is_abstract() {
            self.fits_type(b, &ta)?;
        }
        // An integer division by a constant with a zero component is
        // rejected whether or not the dividend is constant.
        if matches!(op, Div | Rem) && kind.is_int() && vb.as_ref().is_some_and(|v| v.values.contains(&0.0)) {
            return Err(division_by_zero(e.span));
        }
        let (Some(va), Some(vb)) = (va, vb) else { return Ok(None) };
        let va = ConstValue { values: va.values.iter().map(|x| kind.round(*x)).collect(), ..va };
        let vb = ConstValue { values: vb.values.iter().map(|x| kind.round(*x)).collect(), ..vb };
        let values = match op {
            Lt | Le | Gt | Ge | Eq | Ne => {
                let n = va.values.len().max(vb.values.len());
                (0..n)
                    .map(|i| {
                        let (x, y) = (at(&va, i), at(&vb, i));
                        truth(match op {
                            Lt => x < y,
                            Le => x <= y,
                            Gt => x > y,
                            Ge => x >= y,
                            Eq => x == y,
                            _ => x != y,
                        })
                    })
                    .collect()
            }
            And => vec![truth(va.values[0] != 0.0 && vb.values[0] != 0.0)],
            Or => vec![truth(va.values[0] != 0.0 || vb.values[0] != 0.0)],
            _ if kind == Kind::Bool => {
                let n = va.values.len().max(vb.values.len());
                (0..n)
                    .map(|i| {
                        let (x, y) = (at(&va, i) != 0.0, at(&vb, i) != 0.0);
                        truth(match op {
                            BitAnd => x & y,
                            BitOr => x | y,
                            _ => x ^ y,
                        })
                    })
                    .collect()
            }
            Mul if matches!(ta, Type::Matrix(_)) || matches!(tb, Type::Matrix(_)) => {
                self.matrix_product(e, kind, &ta, &tb, &va, &vb)?
            }
            _ => {
                let n = va.values.len().max(vb.values.len());
                let mut values = Vec::with_capacity(n);
                for i in 0..n {
                    match arith(kind, op, at(&va, i), at(&vb, i)) {
                        Ok(r) => values.push(r),
                        Err(Fail::DivideByZero) => return Err(division_by_zero(e.span)),
                        Err(Fail::Range(k, infinite)) => return Err(out_of_range(e.span, k, infinite)),
                    }
                }
                values
            }
        };
        Ok(Some(ConstValue { ty: t.clone(), values }))
    }

    /// `a << b` and `a >> b`: the amount in range for the left operand's
    /// width, and the result too.
    fn fold_shift(
        &mut self,
        e: &Expr,
        t: &Type,
        op: BinaryOp,
        (a, ka, va): (&Expr, Kind, Option<ConstValue>),
        (b, kb, vb): (&Expr, Kind, Option<ConstValue>),
    ) -> Result<Option<ConstValue>, Diagnostic> {
        use BinaryOp::*;
        // The amount is a `u32` (a signed one is converted); the left
        // operand is an `int` when only the amount is concrete.
        let left = if ka.is_abstract() && !kb.is_abstract() { Kind::I32 } else { ka };
        if left != ka {
            self.fits_type(a, &crate::types::INT)?;
        }
        let Some(amounts) = vb else { return Ok(None) };
        for &n in &amounts.values {
            // A literal left operand is 64 bits wide: `1 << 40` fails
            // because the result is too large, below.
            let too_far = if left == Kind::AbsInt { op == Shl && n >= 64.0 } else { n >= 32.0 };
            if n < 0.0 || too_far {
                return Err(shift_out_of_range(b.span, n, left));
            }
        }
        let Some(va) = va else { return Ok(None) };
        let mut values = vec![];
        for i in 0..va.values.len().max(amounts.values.len()) {
            let (x, n) = (at(&va, i), at(&amounts, i));
            let r = match op {
                Shl => x * 2f64.powi(n as i32),
                _ if n >= 64.0 => 0.0,
                _ => (x / 2f64.powi(n as i32)).floor(),
            };
            if !left.fits(r) {
                return Err(out_of_range(e.span, left, false));
            }
            values.push(r);
        }
        Ok(Some(ConstValue { ty: t.clone(), values }))
    }

    /// `a * b` with a matrix operand, summed in naga's order.
    fn matrix_product(
        &self,
        e: &Expr,
        kind: Kind,
        ta: &Type,
        tb: &Type,
        va: &ConstValue,
        vb: &ConstValue,
    ) -> Result<Vec<f64>, Diagnostic> {
        let fail = |f: Fail| match f {
            Fail::DivideByZero => division_by_zero(e.span),
            Fail::Range(k, infinite) => out_of_range(e.span, k, infinite),
        };
        // A sum of products, each step in `kind`'s arithmetic.
        let dot = |terms: &mut dyn Iterator<Item = (f64, f64)>| -> Result<f64, Diagnostic> {
            let mut sum: Option<f64> = None;
            for (x, y) in terms {
                let p = arith(kind, BinaryOp::Mul, x, y).map_err(fail)?;
                sum = Some(match sum {
                    None => p,
                    Some(s) => arith(kind, BinaryOp::Add, s, p).map_err(fail)?,
                });
            }
            Ok(sum.unwrap_or(0.0))
        };
        Ok(match (ta, tb) {
            (Type::Matrix(n), Type::Matrix(_)) => {
                let n = *n as usize;
                let mut out = vec![0.0; n * n];
                for j in 0..n {
                    for i in 0..n {
                        out[j * n + i] = dot(&mut (0..n).map(|k| (va.values[k * n + i], vb.values[j * n + k])))?;
                    }
                }
                out
            }
            (Type::Matrix(n), Type::Vector(..)) => {
                let n = *n as usize;
                (0..n)
                    .map(|i| dot(&mut (0..n).map(|j| (va.values[j * n + i], vb.values[j]))))
                    .collect::<Result<_, _>>()?
            }
            (Type::Vector(..), Type::Matrix(n)) => {
                let n = *n as usize;
                (0..n)
                    .map(|j| dot(&mut (0..n).map(|i| (va.values[i], vb.values[j * n + i]))))
                    .collect::<Result<_, _>>()?
            }
            // A matrix times a scalar, either way round.
            _ => {
                let n = va.values.len().max(vb.values.len());
                (0..n)
                    .map(|i| arith(kind, BinaryOp::Mul, at(va, i), at(vb, i)).map_err(fail))
                    .collect::<Result<_, _>>()?
            }
        })
    }

    fn fold_index(&mut self, t: &Type, base: &Expr, index: &Expr) -> Result<Option<ConstValue>, Diagnostic> {
        let base_ty = self.out.types[base.id.0 as usize].clone();
        let (len, what) = match &base_ty {
            Type::Vector(_, n) => (*n as usize, "components"),
            Type::Matrix(n) => (*n as usize, "columns"),
            Type::Array(_, n) => (*n as usize, "elements"),
            _ => return Ok(None),
        };
        let Some(i) = self.value(index).map(|v| v.values[0]) else { return Ok(None) };
        if i < 0.0 || i >= len as f64 {
            let label = if i < 0.0 { "a negative index".to_string() } else { format!("`{base_ty}` has {len} {what}") };
            return Err(err("E0214", format!("index {i} is out of range for `{base_ty}`"), index.span, label)
                .with_note(
                    "WGSL rejects a constant index outside the vector, matrix or array when the shader is created",
                ));
        }
        let Some(v) = self.value(base) else { return Ok(None) };
        let i = i as usize;
        let values = match base_ty {
            Type::Matrix(n) => v.values[i * n as usize..(i + 1) * n as usize].to_vec(),
            _ => vec![v.values[i]],
        };
        Ok(Some(ConstValue { ty: t.clone(), values }))
    }

    fn fold_construct(&mut self, e: &Expr, ty: &Type, args: &[Expr]) -> Result<Option<ConstValue>, Diagnostic> {
        let Some(target) = Kind::of(ty) else { return Ok(None) };
        let mut values = vec![];
        let mut kinds = vec![];
        let mut constant = true;
        for arg in args {
            match self.value(arg).and_then(|v| Some((Kind::of(&v.ty)?, v))) {
                Some((kind, v)) => {
                    kinds.extend(std::iter::repeat_n(kind, v.values.len()));
                    values.extend(v.values);
                }
                None => constant = false,
            }
        }
        // A conversion of constants to `uint` rejects any negative value,
        // typed or not; a literal component among others must fit too.
        if target == Kind::U32 && values.iter().any(|x| *x < 0.0) && constant {
            return Err(err("E0205", format!("`{}` of a negative constant", ty.name()), e.span, "out of range"));
        }
        for arg in args {
            self.fits_type(arg, &Type::Scalar(ty.scalar().unwrap_or(Scalar::Float)))?;
        }
        if !constant {
            return Ok(None);
        }
        let mut out = Vec::with_capacity(values.len());
        for (x, from) in values.into_iter().zip(kinds) {
            out.push(match target {
                Kind::Bool => truth(x != 0.0),
                Kind::F32 => x as f32 as f64,
                _ if from.is_float() => x.trunc(),
                _ => x,
            });
        }
        let n = ty.components() as usize;
        if out.len() == 1 && n > 1 {
            out = vec![out[0]; n];
        }
        if out.len() != n {
            return Ok(None);
        }
        if let Some(bad) = out.iter().find(|x| !target.fits(**x)) {
            return Err(out_of_range(e.span, target, !bad.is_finite()));
        }
        Ok(Some(ConstValue { ty: ty.clone(), values: out }))
    }

    fn fold_builtin(
        &mut self,
        e: &Expr,
        t: &Type,
        builtin: Builtin,
        args: &[Expr],
    ) -> Result<Option<ConstValue>, Diagnostic> {
        use Builtin::*;
        // Literal arguments convert to the type of the concrete ones
        // (`min(2u, -1)`: -1 must be a `uint`).
        let types: Vec<Type> = args.iter().map(|a| self.out.types[a.id.0 as usize].clone()).collect();
        if let Some(concrete) = types.iter().find(|t| !t.is_abstract() && t.is_numeric_value()) {
            let element = Type::Scalar(concrete.scalar().unwrap_or(Scalar::Float));
            if matches!(builtin.signature().rule, crate::builtins::Rule::Generic { .. }) {
                for arg in args {
                    self.fits_type(arg, &element)?;
                }
            }
        }
        if !folded(builtin) {
            return Ok(None);
        }
        let mut values = vec![];
        for arg in args {
            let Some(v) = self.value(arg) else { return Ok(None) };
            values.push(v);
        }
        let Some(kinds) = values.iter().map(|v| Kind::of(&v.ty)).collect::<Option<Vec<_>>>() else { return Ok(None) };
        // The arithmetic: the concrete arguments', else the literals' (a
        // float builtin takes an integer literal as a float literal).
        let mut kind = kinds.iter().copied().fold(kinds[0], Kind::common);
        if kind == Kind::AbsInt && !matches!(builtin, Abs | Sign | Min | Max | Clamp | Dot | Any | All) {
            kind = Kind::AbsFloat;
        }
        let values: Vec<ConstValue> = values
            .into_iter()
            .map(|v| ConstValue { values: v.values.iter().map(|x| kind.round(*x)).collect(), ..v })
            .collect();
        let n = values.iter().map(|v| v.values.len()).max().unwrap_or(1);
        let x = &values[0];
        let arg = |k: usize, i: usize| at(&values[k], i);
        let result: Vec<f64> = match builtin {
            Any => vec![truth(x.values.iter().any(|v| *v != 0.0))],
            All => vec![truth(x.values.iter().all(|v| *v != 0.0))],
            Dot => {
                let mut sum: Option<f64> = None;
                for i in 0..n {
                    let p = builtin_arith(e, builtin, kind, BinaryOp::Mul, arg(0, i), arg(1, i))?;
                    sum = Some(match sum {
                        None => p,
                        Some(s) => builtin_arith(e, builtin, kind, BinaryOp::Add, s, p)?,
                    });
                }
                vec![sum.unwrap_or(0.0)]
            }
            Cross => {
                let (a, b) = (&values[0].values, &values[1].values);
                let mul = |x: f64, y: f64| in_kind2(kind, x, y, |p, q| p * q, |p, q| p * q);
                let c =
                    |i: usize, j: usize| in_kind2(kind, mul(a[i], b[j]), mul(a[j], b[i]), |p, q| p - q, |p, q| p - q);
                vec![c(1, 2), c(2, 0), c(0, 1)]
            }
            Length | Distance | Normalize => length_like(e, builtin, kind, &values, n)?,
            _ => {
                let mut out = Vec::with_capacity(n);
                for i in 0..n {
                    let (x, y, z) =
                        (arg(0, i), args.get(1).map_or(0.0, |_| arg(1, i)), args.get(2).map_or(0.0, |_| arg(2, i)));
                    if let Some((inside, domain)) = builtin.constant_domain()
                        && !inside(x, y)
                    {
                        let at = if args.len() == 2 {
                            format!("x = {}, y = {}", shown(x), shown(y))
                        } else {
                            format!("x = {}", shown(x))
                        };
                        return Err(domain_error(e.span, builtin, at, domain));
                    }
                    if builtin == Clamp && y > z {
                        let at = format!("low = {}, high = {}", shown(y), shown(z));
                        return Err(domain_error(e.span, builtin, at, "low <= high"));
                    }
                    let Some(r) = componentwise(builtin, kind, x, y, z) else { return Ok(None) };
                    out.push(r);
                }
                out
            }
        };
        let result_kind = Kind::of(t).unwrap_or(kind);
        if let Some(bad) = result.iter().find(|v| !result_kind.fits(**v)) {
            return Err(builtin_overflow(e, builtin, result_kind, &values, !bad.is_finite()));
        }
        Ok(Some(ConstValue { ty: t.clone(), values: result.into_iter().map(|v| result_kind.round(v)).collect() }))
    }
}

/// Whether a call of `builtin` on constants is evaluated here; the others
/// (derivatives, texture reads, and the interpolation, geometry and matrix
/// builtins this folder does not implement) are left to the kernels.
fn folded(builtin: Builtin) -> bool {
    use Builtin::*;
    !matches!(
        builtin,
        Mix | Lerp
            | Smoothstep
            | Reflect
            | Refract
            | FaceForward
            | Determinant
            | Transpose
            | Ddx
            | Ddy
            | Fwidth
            | DdxSurface
            | DdySurface
            | FwidthSurface
            | Sample
            | SampleLevel
            | SampleGrad
            | Load
            | TextureSize
    )
}

/// A builtin applied to one component of its arguments (`y`, `z`: 0 where
/// it takes fewer), in the arithmetic of `kind`; none for a builtin not
/// folded here.
fn componentwise(builtin: Builtin, kind: Kind, x: f64, y: f64, z: f64) -> Option<f64> {
    use Builtin::*;
    Some(match builtin {
        Abs if kind.is_int() => x.abs(),
        Sign if kind.is_int() => x.signum() * truth(x != 0.0),
        Min if kind.is_int() => x.min(y),
        Min => in_kind2(kind, x, y, f32::min, f64::min),
        Max if kind.is_int() => x.max(y),
        Max => in_kind2(kind, x, y, f32::max, f64::max),
        Clamp => x.max(y).min(z),
        Abs => in_kind(kind, x, f32::abs, f64::abs),
        Sign if x == 0.0 => 0.0,
        Sign => x.signum(),
        Sin => in_kind(kind, x, f32::sin, f64::sin),
        Cos => in_kind(kind, x, f32::cos, f64::cos),
        Tan => in_kind(kind, x, f32::tan, f64::tan),
        Asin => in_kind(kind, x, f32::asin, f64::asin),
        Acos => in_kind(kind, x, f32::acos, f64::acos),
        Atan => in_kind(kind, x, f32::atan, f64::atan),
        Sinh => in_kind(kind, x, f32::sinh, f64::sinh),
        Cosh => in_kind(kind, x, f32::cosh, f64::cosh),
        Tanh => in_kind(kind, x, f32::tanh, f64::tanh),
        Exp => in_kind(kind, x, f32::exp, f64::exp),
        Exp2 => in_kind(kind, x, f32::exp2, f64::exp2),
        Log => in_kind(kind, x, f32::ln, f64::ln),
        Log2 => in_kind(kind, x, f32::log2, f64::log2),
        Sqrt => in_kind(kind, x, f32::sqrt, f64::sqrt),
        InverseSqrt => in_kind(kind, x, |v| 1.0 / v.sqrt(), |v| 1.0 / v.sqrt()),
        Floor => in_kind(kind, x, f32::floor, f64::floor),
        Ceil => in_kind(kind, x, f32::ceil, f64::ceil),
        Fract => in_kind(kind, x, |v| v - v.floor(), |v| v - v.floor()),
        Round => in_kind(kind, x, f32::round_ties_even, f64::round_ties_even),
        Trunc => in_kind(kind, x, f32::trunc, f64::trunc),
        Saturate => in_kind(kind, x, |v| v.clamp(0.0, 1.0), |v| v.clamp(0.0, 1.0)),
        Radians => in_kind(kind, x, f32::to_radians, f64::to_radians),
        Degrees => in_kind(kind, x, f32::to_degrees, f64::to_degrees),
        Pow => in_kind2(kind, x, y, f32::powf, f64::powf),
        Atan2 => in_kind2(kind, x, y, f32::atan2, f64::atan2),
        Step => truth(x <= y),
        _ => return None,
    })
}

/// `length(v)`, `distance(a, b)` and `normalize(v)` over `n` components,
/// summed in the order naga sums them.
fn length_like(
    e: &Expr,
    builtin: Builtin,
    kind: Kind,
    values: &[ConstValue],
    n: usize,
) -> Result<Vec<f64>, Diagnostic> {
    let arg = |k: usize, i: usize| at(&values[k], i);
    let d: Vec<f64> = (0..n)
        .map(|i| match builtin {
            Builtin::Distance => in_kind2(kind, arg(0, i), arg(1, i), |p, q| p - q, |p, q| p - q),
            _ => arg(0, i),
        })
        .collect();
    let len = if d.len() == 1 {
        d[0].abs()
    } else {
        let squares = d.iter().map(|v| in_kind2(kind, *v, *v, |p, q| p * q, |p, q| p * q));
        let sum = squares.fold(0.0, |s, v| in_kind2(kind, s, v, |p, q| p + q, |p, q| p + q));
        in_kind(kind, sum, f32::sqrt, f64::sqrt)
    };
    if builtin != Builtin::Normalize {
        return Ok(vec![len]);
    }
    if len == 0.0 {
        return Err(domain_error(e.span, builtin, "a zero vector".into(), "vectors that are not zero"));
    }
    if len.is_finite() {
        Ok(d.iter().map(|v| in_kind2(kind, *v, len, |p, q| p / q, |p, q| p / q)).collect())
    } else {
        // naga rejects a length that overflows before dividing by it:
        // reported by the caller as not finite.
        Ok(vec![len])
    }
}

/// A builtin of constant arguments whose result `result_kind` cannot hold
/// (`infinite`: not a finite number), as WGSL rejects it.
fn builtin_overflow(
    e: &Expr,
    builtin: Builtin,
    result_kind: Kind,
    values: &[ConstValue],
    infinite: bool,
) -> Diagnostic {
    let args_shown = values
        .iter()
        .map(|v| {
            let parts: Vec<String> = v.values.iter().map(|x| shown(*x)).collect();
            if parts.len() == 1 { parts[0].clone() } else { format!("({})", parts.join(", ")) }
        })
        .collect::<Vec<_>>()
        .join(", ");
    let why = if infinite {
        "is not a finite number".to_string()
    } else {
        format!("is outside the `{}` range", result_kind.name())
    };
    let name = builtin.name();
    err(
        "E0213",
        format!("`{name}` of constant arguments overflows `{}`", result_kind.name()),
        e.span,
        format!("`{name}({args_shown})` {why}"),
    )
    .with_note("WGSL evaluates calls on constants when the shader is created, and rejects this one")
}

/// One step of a builtin's arithmetic (`dot`), its failure reported as the builtin's.
fn builtin_arith(e: &Expr, builtin: Builtin, kind: Kind, op: BinaryOp, x: f64, y: f64) -> Result<f64, Diagnostic> {
    arith(kind, op, x, y).map_err(|_| {
        let name = builtin.name();
        err("E0213", format!("`{name}` of constant arguments overflows `{}`", kind.name()), e.span, "overflows")
            .with_note("WGSL evaluates calls on constants when the shader is created, and rejects this one")
    })
}

/// A number as messages show it: `1e20` rather than its twenty-one digits.
fn shown(x: f64) -> String {
    // A `float` prints as the `f32` it is, without the digits of its `f64` widening.
    let single = x as f32;
    let exact = single as f64 == x;
    match (x != 0.0 && !(1e-4..1e7).contains(&x.abs()), exact) {
        (true, true) => format!("{single:e}"),
        (true, false) => format!("{x:e}"),
        (false, true) => single.to_string(),
        (false, false) => x.to_string(),
    }
}

fn domain_error(span: Span, builtin: Builtin, shown: String, domain: &str) -> Diagnostic {
    let name = builtin.name();
    err("E0213", format!("`{name}` of constant arguments outside its domain"), span, shown)
        .with_note(format!("`{name}` is defined for {domain}"))
        .with_note("WGSL evaluates calls on constants when the shader is created, and rejects this one")
}

fn division_by_zero(span: Span) -> Diagnostic {
    err("E0205", "division by zero in a constant expression", span, "divides by zero")
}

fn out_of_range(span: Span, kind: Kind, infinite: bool) -> Diagnostic {
    let what = if infinite { "divides by zero or overflows" } else { "out of range" };
    err("E0205", format!("constant expression out of range for `{}`", kind.name()), span, what)
}

fn shift_out_of_range(span: Span, amount: f64, left: Kind) -> Diagnostic {
    let bits = if left == Kind::AbsInt { 64 } else { 32 };
    err(
        "E0205",
        format!("constant shift amount {amount} out of range for `{}`", left.name()),
        span,
        format!("a shift amount is 0 to {}", bits - 1),
    )
    .with_note(
        "WGSL rejects a constant shift amount outside the width of the value when the shader is created \
         (a shift by an amount that is not constant takes it modulo 32)",
    )
}
