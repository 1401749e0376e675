//! Expressions: name resolution against the scope stack and the globals,
//! the type of every expression, swizzles and indexing, and calls to
//! constructors, user functions and builtins.

use super::builtins::{BuiltinError, builtin_type};
use super::names::{TYPE_NAMES, suggest, well_known_uniform};
use super::typing::{binary_type, construct_check, unify};
use super::{Callee, Checker, Ctx, FunctionId, Global, LocalId, Symbol, err};
use crate::builtins::Builtin;
use crate::diagnostic::{Diagnostic, Label};
use crate::foreign;
use crate::syntax::ast::*;
use crate::types::{self, Scalar, Type};

impl Checker<'_> {
    pub(super) fn expr(&mut self, e: &Expr) -> Type {
        let t = self.expr_inner(e);
        // What WGSL would reject about constant operands (`fold.rs`).
        let t = if t.is_error() { t } else { self.fold(e, t) };
        self.out.types[e.id.0 as usize] = t.clone();
        t
    }

    fn lookup_local(&self, name: &str) -> Option<LocalId> {
        self.scopes.iter().rev().find_map(|s| s.get(name).copied())
    }

    fn expr_inner(&mut self, e: &Expr) -> Type {
        match &e.kind {
            ExprKind::Int(v, IntSuffix::None) if *v > i32::MAX as u64 => {
                self.error(
                    err("E0205", "integer literal out of range for `int`", e.span, "larger than 2147483647")
                        .with_note("write it as a `uint` (`4294967295u`) or a float (`3e9`)"),
                );
                Type::Error
            }
            ExprKind::Int(_, IntSuffix::None) => Type::AbstractInt,
            ExprKind::Int(v, IntSuffix::I) => {
                if *v > i32::MAX as u64 {
                    self.error(err("E0205", "integer literal out of range for `int`", e.span, "too large"));
                }
                types::INT
            }
            ExprKind::Int(..) => types::UINT,
            ExprKind::Float(_) => Type::AbstractFloat,
            ExprKind::Bool(_) => types::BOOL,
            ExprKind::Name(name) => self.name(e, name),
            ExprKind::Unary(op, inner) => self.unary(e, *op, inner),
            ExprKind::Binary(op, a, b) => {
                let ta = self.expr(a);
                let tb = self.expr(b);
                if ta.is_error() || tb.is_error() {
                    return Type::Error;
                }
                match binary_type(*op, &ta, &tb) {
                    Ok(t) => t,
                    Err(message) => {
                        self.error(
                            err("E0201", message, e.span, "invalid operands")
                                .with_label(Label::secondary(a.span, format!("`{ta}`")))
                                .with_label(Label::secondary(b.span, format!("`{tb}`"))),
                        );
                        Type::Error
                    }
                }
            }
            ExprKind::Ternary(c, a, b) => self.ternary(e, c, a, b),
            ExprKind::Field { base, field } => {
                let t = self.expr(base);
                self.field_type(&t, field)
            }
            ExprKind::Index { base, index } => {
                let t = self.expr(base);
                self.index_type(&t, index, e.span)
            }
            ExprKind::Call { callee, args } => self.call(e, callee, args),
        }
    }

    /// `-x`, `+x`, `!x`, `~x`: the operand types WGSL accepts.
    fn unary(&mut self, e: &Expr, op: UnaryOp, inner: &Expr) -> Type {
        let t = self.expr(inner);
        if t.is_error() {
            return Type::Error;
        }
        let ok = match op {
            // WGSL negates signed scalars and vectors only.
            UnaryOp::Neg | UnaryOp::Pos => {
                (t.is_numeric_value() || t.is_abstract())
                    && t.scalar() != Some(Scalar::Uint)
                    && !matches!(t, Type::Matrix(_))
            }
            UnaryOp::Not => matches!(t, Type::Scalar(Scalar::Bool) | Type::Vector(Scalar::Bool, _)),
            UnaryOp::BitNot => matches!(t.scalar(), Some(Scalar::Int | Scalar::Uint)) && !matches!(t, Type::Matrix(_)),
        };
        if ok {
            t
        } else {
            let sym = match op {
                UnaryOp::Neg => "-",
                UnaryOp::Pos => "+",
                UnaryOp::Not => "!",
                UnaryOp::BitNot => "~",
            };
            self.error(err("E0201", format!("cannot apply `{sym}` to `{t}`"), e.span, "invalid operand"));
            Type::Error
        }
    }

    /// `c ? a : b`: a boolean condition and branches of one type.
    fn ternary(&mut self, e: &Expr, c: &Expr, a: &Expr, b: &Expr) -> Type {
        self.condition(c, "`?:` condition");
        let ta = self.expr(a);
        let tb = self.expr(b);
        match unify(&ta, &tb) {
            // `select` is a function in WGSL: literal branches become concrete.
            Some(t) => t.concretize(),
            None => {
                self.error(
                    err(
                        "E0201",
                        format!("`?:` branches have different types: `{ta}` and `{tb}`"),
                        e.span,
                        "branches must agree",
                    )
                    .with_label(Label::secondary(a.span, format!("`{ta}`")))
                    .with_label(Label::secondary(b.span, format!("`{tb}`"))),
                );
                Type::Error
            }
        }
    }

    fn name(&mut self, e: &Expr, name: &str) -> Type {
        if let Some(local) = self.lookup_local(name) {
            self.out.symbols.insert(e.id, Symbol::Local(local));
            return self.out.locals[local.index()].ty.clone();
        }
        let Some(&(global, _)) = self.globals.get(name) else {
            let mut d = err("E0100", format!("unknown name `{name}`"), e.span, "not found in this scope");
            let candidates: Vec<String> =
                self.globals.keys().cloned().chain(self.scopes.iter().flat_map(|s| s.keys().cloned())).collect();
            if let Some(s) = suggest(name, candidates.iter().map(|s| s.as_str())) {
                d = d.with_note(format!("did you mean `{s}`?"));
            } else if let Some(ty) = well_known_uniform(name).filter(|_| self.ctx != Ctx::Global) {
                d = d.with_note(format!("help: declare it: `uniform {ty} {name};`"));
            }
            self.error(d);
            return Type::Error;
        };
        let in_function = matches!(self.ctx, Ctx::Function(_));
        let in_const = self.ctx == Ctx::Global;
        match global {
            Global::Input(id) => {
                if in_function || in_const {
                    self.error(self.context_error(e.span, name, "a G-buffer input"));
                    return Type::Error;
                }
                self.out.symbols.insert(e.id, Symbol::Input(id));
                self.out.inputs[id.index()].ty.clone()
            }
            Global::Uniform(id) => {
                if in_const {
                    self.error(err("E0115", format!("uniform `{name}` is not a constant"), e.span, "not constant"));
                    return Type::Error;
                }
                self.out.symbols.insert(e.id, Symbol::Uniform(id));
                self.out.uniforms[id.index()].ty.clone()
            }
            Global::Const(id) => {
                self.out.symbols.insert(e.id, Symbol::Const(id));
                self.out.consts[id.index()].ty.clone()
            }
            Global::Effect(id) => {
                if in_function || in_const {
                    self.error(self.context_error(e.span, name, "an effect"));
                    return Type::Error;
                }
                if let Ctx::Effect(current) = self.ctx {
                    let deps = &mut self.out.effects[current.index()].deps;
                    if !deps.iter().any(|(d, _)| *d == id) {
                        deps.push((id, e.span));
                    }
                }
                self.out.symbols.insert(e.id, Symbol::Effect(id));
                self.out.effects[id.index()].ty.clone()
            }
            Global::Function(_) => {
                self.error(err(
                    "E0206",
                    format!("`{name}` is a function, not a value"),
                    e.span,
                    "call it: `name(...)`",
                ));
                Type::Error
            }
        }
    }

    fn context_error(&self, span: Span, name: &str, what: &str) -> Diagnostic {
        match self.ctx {
            Ctx::Function(_) => {
                err("E0207", format!("functions cannot read `{name}`"), span, format!("`{name}` is {what}")).with_note(
                    "functions see only their parameters, uniforms and constants: pass the value as an argument",
                )
            }
            _ => err("E0115", format!("`{name}` is not a constant"), span, format!("`{name}` is {what}")),
        }
    }

    pub(super) fn field_type(&mut self, base: &Type, field: &Ident) -> Type {
        if base.is_error() {
            return Type::Error;
        }
        let Some(n) = base.vector_len() else {
            self.error(err(
                "E0208",
                format!("`{base}` has no components to select"),
                field.span,
                "swizzles apply to vectors",
            ));
            return Type::Error;
        };
        let set_of = |c: char| match c {
            'x' | 'y' | 'z' | 'w' => Some((0, "xyzw".find(c).unwrap_or(0))),
            'r' | 'g' | 'b' | 'a' => Some((1, "rgba".find(c).unwrap_or(0))),
            _ => None,
        };
        let mut set = None;
        for c in field.name.chars() {
            match set_of(c) {
                Some((s, i)) if i < n as usize && set.is_none_or(|x| x == s) => set = Some(s),
                Some((_, i)) if i >= n as usize => {
                    self.error(err(
                        "E0208",
                        format!("`{base}` has no component `{c}`"),
                        field.span,
                        format!("`{base}` has {n} components"),
                    ));
                    return Type::Error;
                }
                _ => {
                    self.error(
                        err("E0208", format!("invalid swizzle `.{}`", field.name), field.span, "not a swizzle")
                            .with_note("swizzles use `xyzw` or `rgba` (not mixed), one to four letters"),
                    );
                    return Type::Error;
                }
            }
        }
        let scalar = base.scalar().unwrap_or(Scalar::Float);
        match field.name.len() {
            1 => Type::Scalar(scalar),
            2..=4 => Type::Vector(scalar, field.name.len() as u8),
            _ => {
                self.error(err(
                    "E0208",
                    format!("invalid swizzle `.{}`", field.name),
                    field.span,
                    "at most four components",
                ));
                Type::Error
            }
        }
    }

    pub(super) fn index_type(&mut self, base: &Type, index: &Expr, span: Span) -> Type {
        let it = self.expr(index);
        if !matches!(it, Type::Scalar(Scalar::Int | Scalar::Uint) | Type::AbstractInt | Type::Error) {
            self.error(err(
                "E0201",
                format!("an index must be `int` or `uint`, found `{it}`"),
                index.span,
                "not an integer",
            ));
        }
        match base {
            Type::Vector(s, _) => Type::Scalar(*s),
            Type::Matrix(n) => Type::Vector(Scalar::Float, *n),
            Type::Array(t, _) => (**t).clone(),
            Type::Error => Type::Error,
            other => {
                self.error(err("E0209", format!("cannot index into `{other}`"), span, "not a vector, matrix or array"));
                Type::Error
            }
        }
    }

    fn call(&mut self, e: &Expr, callee: &Ident, args: &[Expr]) -> Type {
        let name = callee.name.as_str();
        // Builtin names are reserved, so a builtin's name always means the builtin.
        let builtin = Builtin::from_name(name);
        let derivative = builtin.is_some_and(Builtin::is_derivative);
        let was_in_derivative = self.in_derivative;
        if derivative {
            self.derivative_call(e, name, builtin);
            self.in_derivative = true;
        }
        let arg_types: Vec<Type> = args.iter().map(|a| self.expr(a)).collect();
        self.in_derivative = was_in_derivative;
        if arg_types.iter().any(|t| t.is_error()) {
            // Still resolve the callee so unknown functions are reported.
            if Type::from_name(name).is_none() && builtin.is_none() && !self.globals.contains_key(name) {
                self.unknown_function(name, callee);
            }
            return Type::Error;
        }
        if let Some(ty) = Type::from_name(name) {
            self.out.callees.insert(e.id, Callee::Construct(ty.clone()));
            return match construct_check(&ty, &arg_types) {
                Ok(()) => ty,
                Err(message) => {
                    self.error(err("E0210", message, e.span, format!("in this `{name}` constructor")));
                    Type::Error
                }
            };
        }
        if let Some(&(Global::Function(fid), _)) = self.globals.get(name) {
            return self.call_function(e, name, fid, args, &arg_types);
        }
        if let Some(builtin) = builtin {
            return self.call_builtin(e, name, builtin, args, &arg_types);
        }
        self.unknown_function(name, callee);
        Type::Error
    }

    /// A derivative (`ddx`, `fwidth`, `sample`, ...) needs a sample
    /// position, so only an effect may take one, and not of another.
    fn derivative_call(&mut self, e: &Expr, name: &str, builtin: Option<Builtin>) {
        match self.ctx {
            Ctx::Effect(id) => {
                if self.in_derivative && builtin == Some(Builtin::Sample) {
                    // `fwidth(sample(t, s, uv))` differentiates a texture lookup, whose
                    // derivative of `uv` (for the mip level) is then taken at the neighbour.
                    self.error(
                        err(
                            "E0502",
                            "`sample` inside the operand of a derivative",
                            e.span,
                            "picks its mip level from derivatives of its uv",
                        )
                        .with_note(
                            "help: differentiate `sample_level(t, s, uv, 0.0)`, which takes no derivative, or \
                                 sample in an effect of its own and differentiate that effect",
                        ),
                    );
                } else if self.in_derivative {
                    self.error(err("E0502", format!("`{name}` inside the operand of another derivative"), e.span, "nested derivative").with_note(
                        "second derivatives are not supported; compute the first derivative as an effect and differentiate that",
                    ));
                }
                self.out.derivative_calls.push((id, e.id));
            }
            _ => {
                self.error(
                    err(
                        "E0501",
                        format!("`{name}` outside an effect body"),
                        e.span,
                        "derivatives need a sample position",
                    )
                    .with_note(if builtin == Some(Builtin::Sample) {
                        "inside functions use `sample_level` or `sample_grad`, or pass the sampled value as an argument"
                    } else {
                        "compute the derivative in the effect and pass it as an argument"
                    }),
                );
            }
        }
    }

    /// A call of a function the program declares: its arguments' count and types.
    fn call_function(&mut self, e: &Expr, name: &str, fid: FunctionId, args: &[Expr], arg_types: &[Type]) -> Type {
        self.out.callees.insert(e.id, Callee::Function(fid));
        if let Ctx::Function(current) = self.ctx {
            self.out.functions[current.index()].calls.push(fid);
        }
        let params: Vec<Type> =
            self.out.functions[fid.index()].params.iter().map(|p| self.out.locals[p.index()].ty.clone()).collect();
        let ret = self.out.functions[fid.index()].ret.clone();
        let decl_span = self.out.function_decl(fid).name.span;
        // Parameters are registered when a body is checked; for a function
        // declared later, take the types from its declaration.
        let declared: Vec<Type> = self
            .out
            .function_decl(fid)
            .params
            .iter()
            .map(|p| Type::from_name(&p.ty.name).unwrap_or(Type::Error))
            .collect();
        let params = if params.len() == declared.len() { params } else { declared };
        if params.len() != args.len() {
            self.error(
                err(
                    "E0211",
                    format!(
                        "`{name}` takes {} argument{}, but {} were given",
                        params.len(),
                        plural(params.len()),
                        args.len()
                    ),
                    e.span,
                    "wrong number of arguments",
                )
                .with_label(Label::secondary(decl_span, "declared here")),
            );
            return ret;
        }
        for ((arg, at), pt) in args.iter().zip(arg_types).zip(&params) {
            self.expect_type(at, pt, arg.span, &format!("argument to `{name}`"));
            self.check_fits(arg, pt);
        }
        ret
    }

    /// A call of a builtin: its signature, and the scalar arguments it splats.
    fn call_builtin(&mut self, e: &Expr, name: &str, builtin: Builtin, args: &[Expr], arg_types: &[Type]) -> Type {
        self.out.callees.insert(e.id, Callee::Builtin(builtin));
        match builtin_type(builtin, arg_types) {
            Ok((ret, splat_to)) => {
                if let Some(target) = splat_to {
                    for (arg, at) in args.iter().zip(arg_types) {
                        if at.components() == 1 && target.vector_len().is_some() {
                            self.out.splats.insert(arg.id, target.clone());
                        }
                    }
                }
                ret
            }
            Err(BuiltinError::Arity(expected)) => {
                self.error(err(
                    "E0211",
                    format!("`{name}` takes {expected}, but {} argument{} were given", args.len(), plural(args.len())),
                    e.span,
                    "wrong number of arguments",
                ));
                Type::Error
            }
            Err(BuiltinError::Types(message)) => {
                let shown = arg_types.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ");
                self.error(err("E0212", message, e.span, format!("called with {shown}")));
                Type::Error
            }
        }
    }

    /// `name` names no function: say so, with the nearest name there is.
    fn unknown_function(&mut self, name: &str, callee: &Ident) {
        let mut d = err("E0100", format!("unknown function `{name}`"), callee.span, "not found");
        let functions: Vec<String> = self
            .globals
            .iter()
            .filter(|(_, (g, _))| matches!(g, Global::Function(_)))
            .map(|(k, _)| k.clone())
            .collect();
        if let Some(help) = foreign::help(name) {
            d = d.with_note(help);
        } else if let Some(s) = suggest(
            name,
            Builtin::ALL
                .iter()
                .map(|b| b.name())
                .chain(functions.iter().map(|s| s.as_str()))
                .chain(TYPE_NAMES.iter().copied()),
        ) {
            d = d.with_note(format!("did you mean `{s}`?"));
        }
        self.error(d);
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}
