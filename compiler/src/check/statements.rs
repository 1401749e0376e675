//! Function and effect bodies, statement by statement: scopes, assignment
//! targets, the `refine`/`return`/`break` context rules, and the path
//! analyses behind definite assignment (E0302) and missing returns (E0303).

use super::typing::binary_type;
use super::{Checker, Ctx, EffectId, FunctionId, Symbol, err};
use crate::diagnostic::Label;
use crate::syntax::ast::*;
use crate::types::{self, Scalar, Type};
use std::collections::HashMap;

impl Checker<'_> {
    pub(super) fn check_bodies(&mut self) {
        let program = self.out.program;
        let (mut function_i, mut effect_i) = (0u32, 0u32);
        for item in &program.items {
            match item {
                Item::Function(f) => {
                    self.check_function(FunctionId(function_i), f);
                    function_i += 1;
                }
                Item::Effect(e) => {
                    self.check_effect(EffectId(effect_i), e);
                    effect_i += 1;
                }
                _ => {}
            }
        }
    }

    fn check_function(&mut self, id: FunctionId, f: &FunctionDecl) {
        self.ctx = Ctx::Function(id);
        self.scopes.push(HashMap::new());
        let mut params = vec![];
        for p in &f.params {
            let ty = self.resolve_type(&p.ty);
            if matches!(ty, Type::Array(..)) {
                self.error(err("E0104", "functions cannot take arrays", p.ty.span, "unsupported parameter type"));
            }
            params.push(self.declare_local(&p.name, ty));
        }
        self.out.functions[id.index()].params = params;
        let ret = self.out.functions[id.index()].ret.clone();
        if !ret.is_value() && !ret.is_error() {
            self.error(err("E0104", format!("functions cannot return `{ret}`"), f.ret.span, "unsupported return type"));
        }
        self.block(&f.body);
        if !block_returns(&f.body) && !ret.is_error() {
            self.error(
                err(
                    "E0303",
                    format!("function `{}` may end without returning a value", f.name.name),
                    f.name.span,
                    "not every path returns",
                )
                .with_label(Label::secondary(closing_brace(&f.body), "can reach the end here")),
            );
        }
        self.scopes.pop();
        self.ctx = Ctx::Global;
    }

    fn check_effect(&mut self, id: EffectId, e: &EffectDecl) {
        self.ctx = Ctx::Effect(id);
        self.scopes.push(HashMap::new());
        match &e.body {
            EffectBody::Expr(expr) => {
                let ty = self.expr(expr);
                let want = self.out.effects[id.index()].ty.clone();
                self.expect_type(&ty, &want, expr.span, "effect value");
                self.check_fits(expr, &want);
            }
            EffectBody::Block(block) => {
                let ty = self.out.effects[id.index()].ty.clone();
                let result = self.declare_local(&e.name, ty);
                self.out.locals[result.index()].reassigned = true;
                self.out.effects[id.index()].result = Some(result);
                self.block(block);
                if !block_assigns(block, &e.name.name) {
                    let what = if e.rate == Rate::Out { "output" } else { "effect" };
                    self.error(
                        err(
                            "E0302",
                            format!("{what} `{}` is not assigned on every path", e.name.name),
                            e.name.span,
                            "declared here",
                        )
                        .with_label(Label::secondary(closing_brace(block), "may reach the end unassigned"))
                        .with_note(format!("assign `{} = ...;` on every path through the body", e.name.name)),
                    );
                }
            }
        }
        self.scopes.pop();
        self.ctx = Ctx::Global;
    }

    fn block(&mut self, b: &Block) {
        self.scopes.push(HashMap::new());
        for s in &b.stmts {
            self.stmt(s);
        }
        self.scopes.pop();
    }

    fn stmt(&mut self, s: &Stmt) {
        match &s.kind {
            StmtKind::Local { ty, name, init } => {
                let declared = self.resolve_type(ty);
                if !declared.is_value() && !declared.is_error() {
                    self.error(err(
                        "E0104",
                        format!("a local variable cannot have type `{declared}`"),
                        ty.span,
                        "unsupported type",
                    ));
                }
                if let Some(init) = init {
                    let t = self.expr(init);
                    self.expect_type(&t, &declared, init.span, "initialiser");
                    self.check_fits(init, &declared);
                }
                let id = self.declare_local(name, declared);
                self.out.local_decls.insert(s.id, id);
            }
            StmtKind::Assign { target, op, value } => self.assign(s, target, *op, value),
            StmtKind::Step { target, .. } => {
                let t = self.lvalue(target);
                if !matches!(t, Type::Scalar(Scalar::Int | Scalar::Uint | Scalar::Float) | Type::Error) {
                    self.error(err(
                        "E0201",
                        format!("`++`/`--` needs a numeric scalar, found `{t}`"),
                        target.span,
                        "not a number",
                    ));
                }
            }
            StmtKind::If { cond, then, otherwise } => {
                self.condition(cond, "`if` condition");
                self.scoped_stmt(then);
                if let Some(o) = otherwise {
                    self.scoped_stmt(o);
                }
            }
            StmtKind::For { init, cond, step, body } => {
                self.for_stmt(s, init.as_deref(), cond.as_ref(), step.as_deref(), body)
            }
            StmtKind::Block(b) => self.block(b),
            StmtKind::Refine => self.refine_stmt(s),
            StmtKind::Return(value) => self.return_stmt(s, value.as_ref()),
            StmtKind::Break | StmtKind::Continue => {
                if self.loop_depth == 0 {
                    let word = if matches!(s.kind, StmtKind::Break) { "break" } else { "continue" };
                    self.error(err("E0306", format!("`{word}` outside a loop"), s.span, "not inside a `for` loop"));
                }
            }
        }
    }

    /// `target op= value`: the value fits the target's type, and a compound
    /// operator keeps it.
    fn assign(&mut self, s: &Stmt, target: &Expr, op: AssignOp, value: &Expr) {
        let target_ty = self.lvalue(target);
        let value_ty = self.expr(value);
        // Whatever the operator, a literal value converts to the target's type.
        self.check_fits(value, &target_ty);
        // `x /= 0` is `x = x / 0`: an integer division by a constant zero.
        if op == AssignOp::Div
            && matches!(target_ty.scalar(), Some(Scalar::Int | Scalar::Uint))
            && self.out.constants.get(&value.id).is_some_and(|v| v.values.contains(&0.0))
        {
            self.error(err("E0205", "division by zero in a constant expression", value.span, "divides by zero"));
        }
        match op {
            AssignOp::Set => self.expect_type(&value_ty, &target_ty, value.span, "assignment"),
            // Either side already reported.
            _ if target_ty.is_error() || value_ty.is_error() => {}
            _ => {
                let bop = match op {
                    AssignOp::Add => BinaryOp::Add,
                    AssignOp::Sub => BinaryOp::Sub,
                    AssignOp::Mul => BinaryOp::Mul,
                    _ => BinaryOp::Div,
                };
                match binary_type(bop, &target_ty, &value_ty) {
                    Ok(result) if result.converts_to(&target_ty) => {}
                    Ok(result) => self.error(err(
                        "E0201",
                        format!("`{}=` would change the type from `{target_ty}` to `{result}`", bop.symbol()),
                        s.span,
                        "type changes",
                    )),
                    Err(message) => self.error(err("E0201", message, s.span, "invalid operands")),
                }
            }
        }
    }

    /// A `for` loop: its own scope for the counter, and a static bound.
    fn for_stmt(&mut self, s: &Stmt, init: Option<&Stmt>, cond: Option<&Expr>, step: Option<&Stmt>, body: &Stmt) {
        self.scopes.push(HashMap::new());
        if let Some(i) = init {
            self.stmt(i);
        }
        if let Some(c) = cond {
            self.condition(c, "loop condition");
        }
        if let Some(st) = step {
            self.stmt(st);
        }
        self.loop_depth += 1;
        self.scoped_stmt(body);
        self.loop_depth -= 1;
        self.check_static_bound(s, init, cond, step, body);
        self.scopes.pop();
    }

    /// `refine;` is only meaningful in a coarse effect.
    fn refine_stmt(&mut self, s: &Stmt) {
        match self.ctx {
            Ctx::Effect(id) if self.out.effects[id.index()].rate == Rate::Coarse => {
                self.out.effects[id.index()].has_refine = true;
            }
            Ctx::Effect(id) => {
                let e = &self.out.effects[id.index()];
                let (name, rate_span) = (e.name.clone(), self.out.effect_decl(id).rate_span);
                self.error(
                    err(
                        "E0304",
                        "`refine` outside a coarse effect",
                        s.span,
                        "refine is only meaningful at coarse rate",
                    )
                    .with_label(Label::secondary(rate_span, format!("`{name}` is computed per pixel"))),
                );
            }
            _ => self.error(
                err("E0304", "`refine` outside a coarse effect", s.span, "not inside a coarse effect")
                    .with_note("`refine;` marks the enclosing coarse effect refined for this coarse sample"),
            ),
        }
    }

    /// `return` only in functions, with a value of the function's type.
    fn return_stmt(&mut self, s: &Stmt, value: Option<&Expr>) {
        match self.ctx {
            Ctx::Function(id) => {
                let ret = self.out.functions[id.index()].ret.clone();
                match value {
                    Some(v) => {
                        let t = self.expr(v);
                        self.expect_type(&t, &ret, v.span, "return value");
                        self.check_fits(v, &ret);
                    }
                    None => self.error(err(
                        "E0201",
                        format!("this function must return a `{ret}`"),
                        s.span,
                        "missing value",
                    )),
                }
            }
            _ => {
                if let Some(v) = value {
                    self.expr(v);
                }
                self.error(
                    err("E0305", "`return` in an effect", s.span, "effects do not return")
                        .with_note("assign the effect's own name instead: `name = value;`"),
                );
            }
        }
    }

    fn scoped_stmt(&mut self, s: &Stmt) {
        self.scopes.push(HashMap::new());
        self.stmt(s);
        self.scopes.pop();
    }

    pub(super) fn condition(&mut self, cond: &Expr, what: &str) {
        let t = self.expr(cond);
        if t != types::BOOL && !t.is_error() {
            let mut d = err("E0202", format!("{what} must be `bool`, found `{t}`"), cond.span, "not a bool");
            if matches!(t, Type::Vector(Scalar::Bool, _)) {
                d = d.with_note("use `any(...)` or `all(...)` to reduce a vector of bools");
            }
            self.error(d);
        }
    }

    /// Checks an assignment target and returns its type.
    fn lvalue(&mut self, target: &Expr) -> Type {
        match &target.kind {
            ExprKind::Name(name) => {
                let t = self.expr(target);
                match self.out.symbols.get(&target.id) {
                    Some(Symbol::Local(id)) => {
                        self.out.locals[id.index()].reassigned = true;
                        t
                    }
                    Some(sym) => {
                        let what = match sym {
                            Symbol::Input(_) => "a G-buffer input",
                            Symbol::Uniform(_) => "a uniform",
                            Symbol::Const(_) => "a constant",
                            Symbol::Effect(_) => "another effect",
                            Symbol::Local(_) => unreachable!(),
                        };
                        let mut d = err(
                            "E0203",
                            format!("cannot assign to `{name}`"),
                            target.span,
                            format!("`{name}` is {what}"),
                        );
                        if let Symbol::Input(_) = sym
                            && !t.is_error()
                        {
                            // A name for the copy that is free here: the input's initial, else `NAME_copy`.
                            let free = |n: &str| {
                                !self.scopes.iter().any(|s| s.contains_key(n)) && !self.globals.contains_key(n)
                            };
                            let initial: String = name.chars().take(1).collect();
                            let copy =
                                if initial != *name && free(&initial) { initial } else { format!("{name}_copy") };
                            d = d.with_note(format!(
                                "help: copy it into a local first, and assign to the local: `{t} {copy} = {name};`"
                            ));
                        }
                        self.error(d);
                        Type::Error
                    }
                    None => Type::Error,
                }
            }
            ExprKind::Field { base, field } => {
                let base_ty = self.lvalue(base);
                if field.name.len() > 1 && base_ty.vector_len().is_some() {
                    self.error(
                        err(
                            "E0204",
                            "cannot assign to a multi-component swizzle",
                            field.span,
                            "assign one component at a time",
                        )
                        .with_note("WGSL, the target language, has no swizzle assignment"),
                    );
                    return Type::Error;
                }
                let t = self.field_type(&base_ty, field);
                self.out.types[target.id.0 as usize] = t.clone();
                t
            }
            ExprKind::Index { base, index } => {
                let base_ty = self.lvalue(base);
                let t = self.index_type(&base_ty, index, target.span);
                // A constant index must be in range here too (E0214, `fold.rs`).
                let t = if t.is_error() { t } else { self.fold(target, t) };
                self.out.types[target.id.0 as usize] = t.clone();
                t
            }
            _ => {
                self.expr(target);
                self.error(err("E0203", "cannot assign to this expression", target.span, "not a variable"));
                Type::Error
            }
        }
    }
}

/// The closing brace of a block: where a path that falls through ends.
fn closing_brace(block: &Block) -> Span {
    Span { start: block.span.end.saturating_sub(1), end: block.span.end }
}

/// Whether every path through `block` that reaches its end assigns `name`.
fn block_assigns(block: &Block, name: &str) -> bool {
    block.stmts.iter().any(|s| stmt_definitely_assigns(s, name))
}

fn stmt_definitely_assigns(s: &Stmt, name: &str) -> bool {
    match &s.kind {
        StmtKind::Assign { target, op: AssignOp::Set, .. } => matches!(&target.kind, ExprKind::Name(n) if n == name),
        StmtKind::Block(b) => block_assigns(b, name),
        StmtKind::If { then, otherwise: Some(o), .. } => {
            stmt_definitely_assigns(then, name) && stmt_definitely_assigns(o, name)
        }
        _ => false,
    }
}

fn block_returns(block: &Block) -> bool {
    block.stmts.iter().any(stmt_returns)
}

fn stmt_returns(s: &Stmt) -> bool {
    match &s.kind {
        StmtKind::Return(_) => true,
        StmtKind::Block(b) => block_returns(b),
        StmtKind::If { then, otherwise: Some(o), .. } => stmt_returns(then) && stmt_returns(o),
        _ => false,
    }
}
