//! Constant evaluation: the values of `const`s, uniform defaults, array
//! lengths and loop bounds, the constant expressions of the language
//! (docs/language.md, section 3.3). WGSL's wider notion of a constant
//! expression, and the checks it makes on them when the shader is created,
//! are in `fold.rs`.

use super::{Checker, ConstId, ConstValue, Ctx, Global, err};
use crate::syntax::ast::*;
use crate::syntax::visit_expr;
use crate::types::{self, Scalar, Type};
use std::collections::HashMap;

impl Checker<'_> {
    /// The value of a constant, evaluated once (a failure, too, is reported
    /// once). The constants it reads are evaluated first, deepest first and
    /// without recursion, so that a chain of constants of any length, in any
    /// declaration order, is evaluated in constant stack space.
    pub(super) fn const_value(&mut self, id: ConstId) -> Option<ConstValue> {
        if self.evaluated_consts.contains(&id.0) || self.evaluating_consts.contains(&id.0) {
            return self.evaluate_const(id);
        }
        // Depth-first over the constants each initialiser names; a constant
        // is evaluated when those it names are. A constant met again on the
        // current path is left to `evaluate_const`, which reports the cycle.
        let mut stack = vec![(id, self.consts_named(id))];
        self.evaluating_consts.insert(id.0);
        while let Some((c, named)) = stack.last_mut() {
            match named.pop() {
                Some(next) => {
                    if !self.evaluated_consts.contains(&next.0) && self.evaluating_consts.insert(next.0) {
                        let named = self.consts_named(next);
                        stack.push((next, named));
                    }
                }
                None => {
                    let c = *c;
                    stack.pop();
                    self.evaluating_consts.remove(&c.0);
                    self.evaluate_const(c);
                }
            }
        }
        self.out.consts[id.index()].value.clone()
    }

    /// The constants the initialiser of `id` names, last first.
    fn consts_named(&self, id: ConstId) -> Vec<ConstId> {
        let mut named = vec![];
        visit_expr(&self.out.const_decl(id).value, &mut |x| {
            if let ExprKind::Name(name) = &x.kind
                && let Some((Global::Const(c), _)) = self.globals.get(name)
            {
                named.push(*c);
            }
        });
        named.reverse();
        named
    }

    /// Evaluates one constant whose named constants are evaluated already
    /// (see [`Checker::const_value`]), or returns its value if it is.
    fn evaluate_const(&mut self, id: ConstId) -> Option<ConstValue> {
        if self.evaluated_consts.contains(&id.0) {
            return self.out.consts[id.index()].value.clone();
        }
        if !self.evaluating_consts.insert(id.0) {
            let decl = self.out.const_decl(id);
            self.error(err(
                "E0301",
                format!("constant `{}` is defined in terms of itself", decl.name.name),
                decl.name.span,
                "cyclic constant",
            ));
            return None;
        }
        let program = self.out.program;
        let Item::Const(decl) = &program.items[self.out.consts[id.index()].item] else {
            unreachable!("const ids index const items")
        };
        let ty = self.out.consts[id.index()].ty.clone();
        let value = self.const_eval(&decl.value);
        // Type-check the initialiser like any other expression, too.
        let saved = std::mem::replace(&mut self.ctx, Ctx::Global);
        self.scopes.push(HashMap::new());
        let init_ty = self.expr(&decl.value);
        self.scopes.pop();
        self.ctx = saved;
        self.expect_type(&init_ty, &ty, decl.value.span, "constant initialiser");
        let value = match value {
            Some(v) => Some(ConstValue { ty: ty.clone(), values: v.values }),
            None => {
                if !init_ty.is_error() {
                    self.error(err(
                        "E0115",
                        "a constant must be initialised with a constant expression",
                        decl.value.span,
                        "not constant",
                    ));
                }
                None
            }
        };
        self.out.consts[id.index()].value = value.clone();
        self.evaluating_consts.remove(&id.0);
        self.evaluated_consts.insert(id.0);
        value
    }

    /// Evaluates literals, constants, arithmetic and constructors at compile time.
    pub(super) fn const_eval(&mut self, e: &Expr) -> Option<ConstValue> {
        let scalar = |ty: Type, v: f64| Some(ConstValue { ty, values: vec![v] });
        match &e.kind {
            ExprKind::Int(v, IntSuffix::None) => scalar(Type::AbstractInt, *v as f64),
            ExprKind::Int(v, IntSuffix::U) => scalar(types::UINT, *v as f64),
            ExprKind::Int(v, IntSuffix::I) => scalar(types::INT, *v as f64),
            ExprKind::Float(v) => scalar(Type::AbstractFloat, *v),
            ExprKind::Bool(b) => scalar(types::BOOL, if *b { 1.0 } else { 0.0 }),
            ExprKind::Name(name) => match self.globals.get(name) {
                Some((Global::Const(id), _)) => {
                    let id = *id;
                    self.const_value(id)
                }
                _ => None,
            },
            ExprKind::Unary(UnaryOp::Neg, inner) => {
                let v = self.const_eval(inner)?;
                Some(ConstValue { ty: v.ty, values: v.values.iter().map(|x| -x).collect() })
            }
            ExprKind::Binary(op @ (BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul | BinaryOp::Div), a, b) => {
                let a = self.const_eval(a)?;
                let b = self.const_eval(b)?;
                if a.values.len() != b.values.len() && a.values.len() != 1 && b.values.len() != 1 {
                    return None;
                }
                if matches!(a.ty, Type::Matrix(_)) || matches!(b.ty, Type::Matrix(_)) {
                    return None;
                }
                let ty = if a.values.len() >= b.values.len() { a.ty.clone() } else { b.ty.clone() };
                let ty = match (&a.ty, &b.ty) {
                    (Type::AbstractInt, Type::AbstractFloat) | (Type::AbstractFloat, Type::AbstractInt) => {
                        Type::AbstractFloat
                    }
                    (x, y) if x.is_abstract() && !y.is_abstract() && b.values.len() >= a.values.len() => y.clone(),
                    _ => ty,
                };
                let integer = matches!(ty.scalar(), Some(Scalar::Int | Scalar::Uint));
                let n = a.values.len().max(b.values.len());
                let mut values = Vec::with_capacity(n);
                for i in 0..n {
                    let x = a.values[if a.values.len() == 1 { 0 } else { i }];
                    let y = b.values[if b.values.len() == 1 { 0 } else { i }];
                    values.push(match op {
                        BinaryOp::Add => x + y,
                        BinaryOp::Sub => x - y,
                        BinaryOp::Mul => x * y,
                        _ if integer && y == 0.0 => return None,
                        _ if integer => (x / y).trunc(),
                        _ => x / y,
                    });
                }
                Some(ConstValue { ty, values })
            }
            ExprKind::Call { callee, args } => {
                let ty = Type::from_name(&callee.name)?;
                let mut values = vec![];
                for arg in args {
                    values.extend(self.const_eval(arg)?.values);
                }
                let n = ty.components() as usize;
                if values.len() == 1 && n > 1 && !matches!(ty, Type::Matrix(_)) {
                    values = vec![values[0]; n];
                }
                if values.len() != n {
                    return None;
                }
                if matches!(ty.scalar(), Some(Scalar::Int | Scalar::Uint)) {
                    values = values.iter().map(|v| v.trunc()).collect();
                }
                Some(ConstValue { ty, values })
            }
            _ => None,
        }
    }
}
