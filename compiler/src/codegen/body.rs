//! User code as WGSL: the statements and expressions of effect bodies and
//! functions, and the renaming that keeps source names clear of WGSL's
//! keywords and of the generated `mrsl_` namespace and entry points.
//!
//! The same expression is written in its body, where names are in scope,
//! and rebuilt at another position for a derivative, where inputs are
//! loaded there and effects evaluated there, or read from that pixel's
//! complete record (the hierarchical levels' neighbours).

use super::Writer;
use super::names::{Name, POS, REFINE, UNIFORMS};
use crate::builtins::Builtin;
use crate::check::{Callee, Checked, LocalId, Symbol, UniformKind};
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};
use mrsl_abi::{KernelKind, entry};
use std::collections::HashSet;

/// The WGSL name of a user identifier: the name itself where WGSL takes it
/// and nothing generated can be called so, else an escaped form. Distinct
/// source names always get distinct WGSL names (the escapes are injective),
/// and none is a name the generator writes:
///
/// - a name WGSL reserves for itself (starting with `__`, or `_` alone) or
///   in the generated namespace (starting with `mrsl` in any case) is
///   prefixed: `mrsl_user_<name>`. Generated names start with `mrsl`,
///   `Mrsl` or `MRSL` but never with `mrsl_user_`;
/// - a WGSL keyword, reserved word or builtin, a generated entry point or a
///   name with an entry point's prefix (`hier_`, `cb_`), `u` and `pos`, and
///   any name that ends in `_` or `_l`, gets a trailing `_`. Names ending in
///   `_` are escaped too so that an escaped name cannot equal a source name
///   (`var` becomes `var_`, and `var_` becomes `var__`); names ending in
///   `_l` so that no name this function returns ends in `_l`, the suffix of
///   [`local_name`].
pub(super) fn wgsl_ident(name: &str) -> String {
    // WGSL's reserved words and builtin names, looked up in a set: the
    // generator asks for every name it writes.
    static WGSL_NAMES: std::sync::LazyLock<std::collections::HashSet<&'static str>> = std::sync::LazyLock::new(|| {
        naga::keywords::wgsl::RESERVED.iter().chain(naga::keywords::wgsl::BUILTIN_IDENTIFIERS).copied().collect()
    });
    let prefixed =
        name.starts_with("__") || name == "_" || name.get(..4).is_some_and(|p| p.eq_ignore_ascii_case("mrsl"));
    let suffixed = WGSL_NAMES.contains(name)
        || KernelKind::ALL.iter().any(|k| k.entry_points().contains(&name))
        || entry::RESERVED_PREFIXES.iter().any(|p| name.starts_with(p))
        || name.ends_with('_')
        || name.ends_with("_l")
        || matches!(name, "u" | "pos");
    match (prefixed, suffixed) {
        (true, true) => Name::User.of(format!("{name}_")),
        (true, false) => Name::User.of(name),
        (false, true) => format!("{name}_"),
        (false, false) => name.to_string(),
    }
}

/// The WGSL name of a local variable or parameter.
pub(super) fn local_name(checked: &Checked, id: LocalId) -> String {
    let info = &checked.locals[id.index()];
    // Locals may shadow module-scope user names (C allows it, WGSL would then
    // hide the function or texture), so they are suffixed when they would:
    // `_l` after the escaped name, which no name `wgsl_ident` returns ends in.
    let base = wgsl_ident(&info.name);
    let clashes = checked.functions.iter().any(|f| f.name == info.name)
        || checked.consts.iter().any(|c| c.name == info.name)
        || checked.uniforms.iter().any(|u| u.name == info.name && !matches!(u.kind, UniformKind::Value { .. }));
    if clashes { format!("{base}_l") } else { base }
}

#[derive(Clone, Copy)]
pub(super) enum Mode<'s> {
    /// Inside an effect body or function: names are in scope.
    Body,
    /// Rebuilding a derivative operand at another position.
    Neighbour(&'s crate::deriv::DerivSite<'s>),
    /// The same at a pixel whose record is complete (a hierarchical level's
    /// neighbour): effects are read from the record, not evaluated.
    Stored(&'s crate::deriv::DerivSite<'s>),
}

impl Writer<'_, '_, '_> {
    pub(super) fn function(&mut self, id: crate::check::FunctionId) {
        let c = self.checked();
        let f = c.function_decl(id);
        let info = &c.functions[id.index()];
        let params: Vec<String> = info
            .params
            .iter()
            .map(|p| {
                let l = &c.locals[p.index()];
                let name = local_name(c, *p);
                if l.reassigned { format!("{name}_in: {}", l.ty.wgsl()) } else { format!("{name}: {}", l.ty.wgsl()) }
            })
            .collect();
        // Names, not source lines: formatting a program leaves its kernels byte-identical.
        self.line(0, format!("// function `{}`", f.name.name));
        self.line(0, format!("fn {}({}) -> {} {{", wgsl_ident(&f.name.name), params.join(", "), info.ret.wgsl()));
        for p in &info.params {
            if c.locals[p.index()].reassigned {
                let name = local_name(c, *p);
                self.line(1, format!("var {name} = {name}_in;"));
            }
        }
        for s in &f.body.stmts {
            self.stmt(s, 1, None);
        }
        self.line(0, "}");
        self.line(0, "");
    }

    /// The sizes of the matrices the program selects between: with `?:`
    /// anywhere, or by resampling a `@nearest` coarse effect.
    fn matrix_select_sizes(&self) -> std::collections::BTreeSet<u8> {
        let c = self.checked();
        let mut sizes = std::collections::BTreeSet::new();
        let mut visit = |e: &Expr| {
            crate::syntax::visit_expr(e, &mut |x| {
                if let (ExprKind::Ternary(..), Type::Matrix(n)) = (&x.kind, c.ty(x)) {
                    sizes.insert(*n);
                }
            })
        };
        for item in &c.program.items {
            match item {
                Item::Function(f) => f.body.stmts.iter().for_each(|s| crate::syntax::visit_stmt_exprs(s, &mut visit)),
                Item::Effect(d) => match &d.body {
                    EffectBody::Expr(e) => visit(e),
                    EffectBody::Block(b) => b.stmts.iter().for_each(|s| crate::syntax::visit_stmt_exprs(s, &mut visit)),
                },
                _ => {}
            }
        }
        for e in &c.effects {
            if let (true, Type::Matrix(n)) = (e.nearest, &e.ty) {
                sizes.insert(*n);
            }
        }
        sizes
    }

    /// `mrsl_select_m<N>(f, t, c)`: WGSL's `select(f, t, c)` for the
    /// `matN x N` matrices the program selects between, which `select` does
    /// not take: column by column.
    pub(super) fn matrix_selects(&mut self) {
        for n in self.matrix_select_sizes() {
            let ty = crate::types::Type::Matrix(n).wgsl();
            let columns: Vec<String> = (0..n).map(|k| format!("select(f[{k}], t[{k}], c)")).collect();
            self.line(0, format!("fn {}(f: {ty}, t: {ty}, c: bool) -> {ty} {{", Name::SelectMatrix.of(n)));
            self.line(1, format!("return {ty}({});", columns.join(", ")));
            self.line(0, "}");
            self.line(0, "");
        }
    }

    /// Writes statement `s`, unless it is in `skipped` (the statements a
    /// value-only function leaves out, [`Writer::eval_function`]), and its
    /// sub-statements that are not.
    pub(super) fn stmt(&mut self, s: &Stmt, indent: usize, skipped: Option<&HashSet<NodeId>>) {
        if skipped.is_some_and(|skipped| skipped.contains(&s.id)) {
            return;
        }
        let c = self.checked();
        match &s.kind {
            StmtKind::Local { init, .. } => {
                let id = c.local_decls[&s.id];
                let info = &c.locals[id.index()];
                let name = local_name(c, id);
                match init {
                    Some(v) => {
                        // naga folds what a `let` names when it is constant and
                        // then treats every use as that constant (`x / zero`
                        // with `let zero = 0;` would be a division by a
                        // constant zero, which WGSL rejects); WGSL does not,
                        // nor does mrsl: such a local is a `var`, whose value
                        // naga reads at run time.
                        let constant = c.constants.contains_key(&v.id);
                        let keyword = if info.reassigned || constant { "var" } else { "let" };
                        let value = self.expr(v, Mode::Body);
                        self.line(indent, format!("{keyword} {name}: {} = {value};", info.ty.wgsl()));
                    }
                    None => self.line(indent, format!("var {name}: {};", info.ty.wgsl())),
                }
            }
            StmtKind::Assign { .. } | StmtKind::Step { .. } => {
                let text = self.simple_stmt(s);
                self.line(indent, format!("{text};"));
            }
            StmtKind::If { cond, then, otherwise } => {
                let cond = self.expr(cond, Mode::Body);
                self.line(indent, format!("if ({cond}) {{"));
                self.body(then, indent + 1, skipped);
                if let Some(o) = otherwise {
                    self.line(indent, "} else {");
                    self.body(o, indent + 1, skipped);
                }
                self.line(indent, "}");
            }
            StmtKind::For { init, cond, step, body } => {
                let init = init.as_ref().map(|i| self.for_init(i)).unwrap_or_default();
                let cond = cond.as_ref().map(|x| self.expr(x, Mode::Body)).unwrap_or_default();
                let step = step.as_ref().map(|st| self.simple_stmt(st)).unwrap_or_default();
                self.line(indent, format!("for ({init}; {cond}; {step}) {{"));
                self.body(body, indent + 1, skipped);
                self.line(indent, "}");
            }
            StmtKind::Block(b) => {
                self.line(indent, "{");
                for s in &b.stmts {
                    self.stmt(s, indent + 1, skipped);
                }
                self.line(indent, "}");
            }
            StmtKind::Refine => self.line(indent, format!("*{REFINE} = true; // refine")),
            StmtKind::Return(Some(v)) => {
                let v = self.expr(v, Mode::Body);
                self.line(indent, format!("return {v};"));
            }
            StmtKind::Return(None) => self.line(indent, "return;"),
            StmtKind::Break => self.line(indent, "break;"),
            StmtKind::Continue => self.line(indent, "continue;"),
        }
    }

    fn body(&mut self, s: &Stmt, indent: usize, skipped: Option<&HashSet<NodeId>>) {
        // A branch or loop body left out of a value-only function as a
        // whole: its statements are not in the skipped set themselves.
        if skipped.is_some_and(|skipped| skipped.contains(&s.id)) {
            return;
        }
        match &s.kind {
            StmtKind::Block(b) => b.stmts.iter().for_each(|s| self.stmt(s, indent, skipped)),
            _ => self.stmt(s, indent, skipped),
        }
    }

    fn for_init(&mut self, s: &Stmt) -> String {
        let c = self.checked();
        match &s.kind {
            StmtKind::Local { init, .. } => {
                let id = c.local_decls[&s.id];
                let info = &c.locals[id.index()];
                let value = init.as_ref().map(|v| format!(" = {}", self.expr(v, Mode::Body))).unwrap_or_default();
                format!("var {}: {}{value}", local_name(c, id), info.ty.wgsl())
            }
            _ => self.simple_stmt(s),
        }
    }

    fn simple_stmt(&mut self, s: &Stmt) -> String {
        match &s.kind {
            StmtKind::Assign { target, op, value } => {
                let t = self.expr(target, Mode::Body);
                let v = self.expr(value, Mode::Body);
                let op = match op {
                    AssignOp::Set => "=",
                    AssignOp::Add => "+=",
                    AssignOp::Sub => "-=",
                    AssignOp::Mul => "*=",
                    AssignOp::Div => "/=",
                };
                format!("{t} {op} {v}")
            }
            StmtKind::Step { target, increment } => {
                // `++` is integer-only in WGSL; `+= 1` works for every numeric type.
                let t = self.expr(target, Mode::Body);
                format!("{t} {} 1", if *increment { "+=" } else { "-=" })
            }
            StmtKind::Local { .. } => self.for_init(s),
            _ => String::new(),
        }
    }

    // ---- Expressions --------------------------------------------------------

    pub(super) fn expr(&self, e: &Expr, mode: Mode) -> String {
        let c = self.checked();
        match &e.kind {
            ExprKind::Int(v, IntSuffix::None) => v.to_string(),
            ExprKind::Int(v, IntSuffix::U) => format!("{v}u"),
            ExprKind::Int(v, IntSuffix::I) => format!("{v}i"),
            ExprKind::Float(v) => float_literal(*v),
            ExprKind::Bool(b) => b.to_string(),
            ExprKind::Name(name) => self.name(e, name, mode),
            ExprKind::Unary(op, inner) => {
                let x = self.expr(inner, mode);
                let sym = match op {
                    UnaryOp::Pos => "",
                    UnaryOp::Neg => "-",
                    UnaryOp::Not => "!",
                    UnaryOp::BitNot => "~",
                };
                format!("{sym}({x})")
            }
            ExprKind::Binary(op, a, b) => {
                let x = self.expr(a, mode);
                let mut y = self.expr(b, mode);
                match op {
                    BinaryOp::Shl | BinaryOp::Shr => {
                        // WGSL shifts take an unsigned amount.
                        match c.ty(b) {
                            Type::Scalar(Scalar::Int) => y = format!("u32({y})"),
                            Type::Vector(Scalar::Int, n) => y = format!("vec{n}<u32>({y})"),
                            _ => {}
                        }
                        format!("({x} {} {y})", op.symbol())
                    }
                    BinaryOp::BitXor if c.ty(a).scalar() == Some(Scalar::Bool) => {
                        format!("({x} != {y})")
                    }
                    _ => format!("({x} {} {y})", op.symbol()),
                }
            }
            ExprKind::Ternary(cond, a, b) => {
                let cond = self.expr(cond, mode);
                let x = self.expr(a, mode);
                let y = self.expr(b, mode);
                // WGSL's `select` takes scalars and vectors only; a matrix is
                // selected column by column in a helper (`matrix_selects`),
                // which, like `select`, evaluates both branches once.
                match c.ty(e) {
                    Type::Matrix(n) => format!("{}({y}, {x}, {cond})", Name::SelectMatrix.of(n)),
                    _ => format!("select({y}, {x}, {cond})"),
                }
            }
            ExprKind::Field { base, field } => format!("{}.{}", self.expr(base, mode), field.name),
            ExprKind::Index { base, index } => {
                format!("{}[{}]", self.expr(base, mode), self.expr(index, mode))
            }
            ExprKind::Call { callee, args } => self.call(e, callee, args, mode),
        }
    }

    fn name(&self, e: &Expr, name: &str, mode: Mode) -> String {
        let c = self.checked();
        match c.symbols.get(&e.id) {
            Some(Symbol::Local(l)) => match mode {
                Mode::Neighbour(site) | Mode::Stored(site) if !site.params.contains(l) => {
                    match self.i.deriv.definitions.get(l) {
                        Some(def) => format!("({})", self.expr(def, mode)),
                        None => local_name(c, *l),
                    }
                }
                _ => local_name(c, *l),
            },
            Some(Symbol::Input(i)) => match mode {
                Mode::Body => wgsl_ident(name),
                Mode::Neighbour(_) | Mode::Stored(_) => format!("{}({POS})", Name::Load.of(&c.inputs[i.index()].name)),
            },
            Some(Symbol::Uniform(u)) => {
                let info = &c.uniforms[u.index()];
                match (&info.kind, &info.ty) {
                    (UniformKind::Value { .. }, Type::Scalar(Scalar::Bool)) => {
                        format!("({UNIFORMS}.{} != 0u)", wgsl_ident(name))
                    }
                    (UniformKind::Value { .. }, Type::Vector(Scalar::Bool, n)) => {
                        format!("({UNIFORMS}.{} != vec{n}<u32>(0u))", wgsl_ident(name))
                    }
                    (UniformKind::Value { .. }, _) => format!("{UNIFORMS}.{}", wgsl_ident(name)),
                    _ => wgsl_ident(name),
                }
            }
            Some(Symbol::Const(_)) => wgsl_ident(name),
            Some(Symbol::Effect(id)) => match mode {
                Mode::Body => self.effect_name(*id),
                Mode::Neighbour(_) => format!("{}({POS})", Name::At.of(&c.effects[id.index()].name)),
                Mode::Stored(_) => format!("{}({POS})", Name::Stored.of(&c.effects[id.index()].name)),
            },
            None => wgsl_ident(name),
        }
    }

    fn call(&self, e: &Expr, callee: &Ident, args: &[Expr], mode: Mode) -> String {
        let c = self.checked();
        let arg = |k: usize| {
            let text = self.expr(&args[k], mode);
            match c.splats.get(&args[k].id) {
                Some(target) => format!("{}({text})", target.wgsl()),
                None => text,
            }
        };
        let all = || (0..args.len()).map(arg).collect::<Vec<_>>().join(", ");
        match c.callees.get(&e.id) {
            Some(Callee::Construct(ty)) => format!("{}({})", ty.wgsl(), all()),
            Some(Callee::Function(_)) => format!("{}({})", wgsl_ident(&callee.name), all()),
            Some(Callee::Builtin(builtin)) if builtin.is_derivative() => {
                let site_index = self.i.deriv.site_of[&e.id];
                let site = &self.i.deriv.sites[site_index];
                let mut call_args = vec![POS.to_string()];
                call_args.extend(site.params.iter().map(|p| local_name(c, *p)));
                // The operand here, as this code already computes it (an
                // effect's or input's local), where that is what the helpers
                // would recompute: they evaluate only the quad pair's other position.
                if self.reuses_operand_here(site_index) {
                    call_args.push(self.expr(site.operand, mode));
                }
                let call_args = call_args.join(", ");
                let dx = format!("{}({call_args})", Name::Ddx.of(site_index));
                let dy = format!("{}({call_args})", Name::Ddy.of(site_index));
                match builtin.plain_derivative() {
                    Builtin::Ddx => dx,
                    Builtin::Ddy => dy,
                    Builtin::Fwidth => format!("(abs({dx}) + abs({dy}))"),
                    _ => format!("{}({}, {}, {}, {dx}, {dy})", builtin.wgsl_name(), arg(0), arg(1), arg(2)),
                }
            }
            // WGSL's `textureLoad` takes the mip level, and `textureDimensions` returns unsigned sizes.
            Some(Callee::Builtin(Builtin::Load)) if args.len() == 2 => {
                format!("{}({}, {}, 0)", Builtin::Load.wgsl_name(), arg(0), arg(1))
            }
            Some(Callee::Builtin(Builtin::TextureSize)) => {
                format!("vec2<i32>({}({}))", Builtin::TextureSize.wgsl_name(), arg(0))
            }
            Some(Callee::Builtin(builtin)) => format!("{}({})", builtin.wgsl_name(), all()),
            None => format!("{}({})", wgsl_ident(&callee.name), all()),
        }
    }
}

pub(super) fn float_literal(v: f64) -> String {
    let text = format!("{v:?}");
    if text.contains('.') || text.contains('e') || text.contains("inf") || text.contains("NaN") {
        text
    } else {
        format!("{text}.0")
    }
}
