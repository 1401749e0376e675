//! Semantic checks: name resolution, types, rate rules, definite assignment,
//! static loop bounds. Collects every error instead of stopping at the first.
//!
//! The result, [`Checked`], keeps the AST untouched and stores what it learned
//! in side tables keyed by [`NodeId`] and by typed ids ([`EffectId`],
//! [`LocalId`], ...), which the later stages read.
//!
//! [`check`] runs the passes of one [`Checker`] in order; each pass lives in
//! its own module: `declarations` (globals), `constants`, `statements` and
//! `loops` (bodies), `expressions` (with `fold`, WGSL's constant
//! expressions in them), then `program` (whole-program checks).
//! `typing`, `builtins` and `formats` are the rules those passes apply, and
//! `names` makes the "did you mean" suggestions.

use crate::builtins::Builtin;
use crate::diagnostic::{Diagnostic, Label};
use crate::foreign;
use crate::syntax::ast::*;
use crate::types::Type;
use mrsl_abi::TextureFormat;
use std::collections::{HashMap, HashSet};

mod builtins;
mod constants;
mod declarations;
mod decode;
mod expressions;
mod fold;
mod formats;
mod loops;
mod names;
mod program;
mod statements;
mod typing;

use names::{TYPE_NAMES, suggest};

/// The block sizes `coarse(N)` may name, coarsest first: those of the
/// multi-rate mode's levels (docs/language.md, section 8.4).
pub const COARSE_BLOCKS: [u32; 2] = [mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK, mrsl_abi::geometry::DYNAMIC_INNER_BLOCK];

macro_rules! typed_id {
    ($name:ident) => {
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}
typed_id!(InputId);
typed_id!(UniformId);
typed_id!(ConstId);
typed_id!(FunctionId);
typed_id!(EffectId);
typed_id!(LocalId);

/// What a name in an expression refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Symbol {
    Input(InputId),
    Uniform(UniformId),
    Const(ConstId),
    Effect(EffectId),
    Local(LocalId),
}

/// What a call expression calls.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Callee {
    Builtin(Builtin),
    Function(FunctionId),
    /// A constructor or conversion to this type.
    Construct(Type),
}

/// How a discontinuity-key channel is compared (part of the layout contract).
pub use mrsl_abi::{Background, KeyCompare};

/// A G-buffer input (`in`).
#[derive(Debug, Clone)]
pub struct InputInfo {
    pub name: String,
    pub ty: Type,
    pub key: Option<KeyCompare>,
    /// `@background(v)` or `@foreground(v)`: which values mark background pixels.
    pub background: Option<Background>,
    /// `@depth(..)` or `@encoded(..)`: how the engine stores it.
    pub decode: Option<mrsl_abi::Decode>,
}

/// What a uniform binds to: a value in the uniform block, or a resource.
#[derive(Debug, Clone, PartialEq)]
pub enum UniformKind {
    Value { default: Option<ConstValue> },
    Texture,
    Sampler,
}

#[derive(Debug, Clone)]
pub struct UniformInfo {
    pub name: String,
    pub ty: Type,
    pub kind: UniformKind,
}

/// A `const`; `item` indexes `Program::items`, as in the other infos.
#[derive(Debug, Clone)]
pub struct ConstInfo {
    pub name: String,
    pub ty: Type,
    pub value: Option<ConstValue>,
    pub item: usize,
}

/// A user function.
#[derive(Debug, Clone)]
pub struct FunctionInfo {
    pub name: String,
    pub ret: Type,
    pub params: Vec<LocalId>,
    pub item: usize,
    /// Functions this one calls.
    pub calls: Vec<FunctionId>,
}

/// An effect or output.
#[derive(Debug, Clone)]
pub struct EffectInfo {
    pub name: String,
    pub rate: Rate,
    /// `coarse(N)`'s block size N (4 or 2); `None` for plain `coarse`, the
    /// fine rates, and a block size E0117 rejected.
    pub block: Option<u32>,
    pub ty: Type,
    pub item: usize,
    pub name_span: Span,
    /// Effects this one reads, with the first place it reads each.
    pub deps: Vec<(EffectId, Span)>,
    /// Whether the body contains a `refine;` (coarse effects only).
    pub has_refine: bool,
    /// `@nearest`: resample by the nearest corner instead of bilinearly.
    pub nearest: bool,
    /// The local variable holding the result inside a block body.
    pub result: Option<LocalId>,
    /// Output storage format (outputs only).
    pub format: Option<TextureFormat>,
}

/// A local variable, a parameter, or a block effect's result.
#[derive(Debug, Clone)]
pub struct LocalInfo {
    pub name: String,
    pub ty: Type,
    pub span: Span,
    /// Assigned anywhere after its declaration (or, for parameters, at all).
    pub reassigned: bool,
}

/// A compile-time value: a scalar, vector or matrix of numbers.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ConstValue {
    #[serde(skip)]
    pub ty: Type,
    pub values: Vec<f64>,
}

/// The checked program: the AST plus everything the checks learned about it.
#[derive(Debug, Clone)]
pub struct Checked<'a> {
    pub program: &'a Program,
    pub inputs: Vec<InputInfo>,
    pub uniforms: Vec<UniformInfo>,
    pub consts: Vec<ConstInfo>,
    pub functions: Vec<FunctionInfo>,
    pub effects: Vec<EffectInfo>,
    pub locals: Vec<LocalInfo>,
    /// The type of every expression, indexed by `NodeId`.
    pub types: Vec<Type>,
    pub symbols: HashMap<NodeId, Symbol>,
    pub callees: HashMap<NodeId, Callee>,
    /// Local declared by a `Local` statement.
    pub local_decls: HashMap<NodeId, LocalId>,
    /// Arguments that must be widened (scalar splat) to this vector type.
    pub splats: HashMap<NodeId, Type>,
    /// Derivative sites (`ddx`, `ddy`, `fwidth`, `sample` calls), in order.
    pub derivative_calls: Vec<(EffectId, NodeId)>,
    /// The static trip count of every `for` statement whose bounds the
    /// loop check evaluated (the cost model multiplies its body by it).
    pub loop_trips: HashMap<NodeId, u64>,
    /// The value of every expression WGSL evaluates when the shader is
    /// created (made of literals, constants and operations on them; see
    /// `fold.rs`), in the type the checker gives the expression.
    pub constants: HashMap<NodeId, ConstValue>,
}

impl Checked<'_> {
    pub fn ty(&self, expr: &Expr) -> &Type {
        &self.types[expr.id.0 as usize]
    }
    pub fn effect_decl(&self, id: EffectId) -> &EffectDecl {
        match &self.program.items[self.effects[id.index()].item] {
            Item::Effect(e) => e,
            _ => unreachable!("effect ids index effect items"),
        }
    }
    pub fn function_decl(&self, id: FunctionId) -> &FunctionDecl {
        match &self.program.items[self.functions[id.index()].item] {
            Item::Function(f) => f,
            _ => unreachable!("function ids index function items"),
        }
    }
    pub fn const_decl(&self, id: ConstId) -> &ConstDecl {
        match &self.program.items[self.consts[id.index()].item] {
            Item::Const(c) => c,
            _ => unreachable!("const ids index const items"),
        }
    }
}

/// Checks a parsed program. Returns the side tables and every diagnostic
/// (errors and warnings); the caller decides whether errors stop compilation.
pub fn check(program: &Program) -> (Checked<'_>, Vec<Diagnostic>) {
    let mut checker = Checker::new(program);
    checker.register_globals();
    checker.check_bodies();
    checker.check_function_recursion();
    checker.check_outputs_and_usage();
    let Checker { out, diagnostics, .. } = checker;
    (out, diagnostics)
}

/// What a top-level name is bound to.
#[derive(Clone, Copy)]
enum Global {
    Input(InputId),
    Uniform(UniformId),
    Const(ConstId),
    Function(FunctionId),
    Effect(EffectId),
}

/// Where the expression being checked is: it decides which names it may read.
#[derive(Clone, Copy, PartialEq)]
enum Ctx {
    /// Constant contexts: const initialisers, uniform defaults, array lengths.
    Global,
    Function(FunctionId),
    Effect(EffectId),
}

/// One run of the checks: the side tables being filled, the diagnostics so
/// far, and the scopes and context of the body being checked. The passes are
/// `impl` blocks in the submodules.
struct Checker<'a> {
    out: Checked<'a>,
    diagnostics: Vec<Diagnostic>,
    globals: HashMap<String, (Global, Span)>,
    scopes: Vec<HashMap<String, LocalId>>,
    ctx: Ctx,
    loop_depth: u32,
    /// Set while checking the operand of a derivative call.
    in_derivative: bool,
    evaluating_consts: HashSet<u32>,
    /// Constants evaluated, successfully or not.
    evaluated_consts: HashSet<u32>,
}

/// An error with one primary label, the shape of most check diagnostics.
fn err(code: &'static str, message: impl Into<String>, span: Span, label: impl Into<String>) -> Diagnostic {
    Diagnostic::error(code, message).with_label(Label::primary(span, label))
}

impl<'a> Checker<'a> {
    fn new(program: &'a Program) -> Self {
        Checker {
            out: Checked {
                program,
                inputs: vec![],
                uniforms: vec![],
                consts: vec![],
                functions: vec![],
                effects: vec![],
                locals: vec![],
                types: vec![Type::Error; program.node_count as usize],
                symbols: HashMap::new(),
                callees: HashMap::new(),
                local_decls: HashMap::new(),
                splats: HashMap::new(),
                derivative_calls: vec![],
                loop_trips: HashMap::new(),
                constants: HashMap::new(),
            },
            diagnostics: vec![],
            globals: HashMap::new(),
            scopes: vec![],
            ctx: Ctx::Global,
            loop_depth: 0,
            in_derivative: false,
            evaluating_consts: HashSet::new(),
            evaluated_consts: HashSet::new(),
        }
    }

    fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    fn resolve_type(&mut self, name: &Ident) -> Type {
        match Type::from_name(&name.name) {
            Some(t) => t,
            None => {
                if let Some(d) = foreign::keyword_diagnostic(&name.name, name.span) {
                    // `let x = n;` parses as a declaration of type `let`.
                    self.error(d);
                    return Type::Error;
                }
                let mut d = err("E0102", format!("unknown type `{}`", name.name), name.span, "not a type");
                if let Some(help) = foreign::help(&name.name) {
                    d = d.with_note(help);
                } else if let Some(s) = suggest(&name.name, TYPE_NAMES.iter().copied()) {
                    d = d.with_note(format!("did you mean `{s}`?"));
                }
                self.error(d);
                Type::Error
            }
        }
    }

    fn new_local(&mut self, name: &Ident, ty: Type) -> LocalId {
        let id = LocalId(self.out.locals.len() as u32);
        self.out.locals.push(LocalInfo { name: name.name.clone(), ty, span: name.span, reassigned: false });
        id
    }

    /// Declares a local in the innermost scope, reporting duplicates there.
    fn declare_local(&mut self, name: &Ident, ty: Type) -> LocalId {
        let id = self.new_local(name, ty);
        // Shadowing a global is allowed (as in C), but a builtin is reserved.
        if Builtin::from_name(&name.name).is_some() {
            self.error(err("E0103", format!("`{}` is a builtin function name", name.name), name.span, "reserved name"));
        }
        let scope = self.scopes.last_mut().expect("locals are declared inside a scope");
        if let Some(previous) = scope.insert(name.name.clone(), id) {
            let previous_span = self.out.locals[previous.index()].span;
            self.error(
                Diagnostic::error("E0101", format!("`{}` is defined twice in the same scope", name.name))
                    .with_label(Label::primary(name.span, "defined again here"))
                    .with_label(Label::secondary(previous_span, "first defined here")),
            );
        }
        id
    }

    /// Reports a type mismatch unless `found` converts to `expected`.
    fn expect_type(&mut self, found: &Type, expected: &Type, span: Span, what: &str) {
        if !found.converts_to(expected) {
            let mut d = err(
                "E0201",
                format!("mismatched types in {what}: expected `{expected}`, found `{found}`"),
                span,
                format!("this is `{found}`"),
            );
            if found.is_numeric_value() && expected.is_numeric_value() && found.components() == expected.components() {
                d = d.with_note(format!("convert explicitly: `{}(...)`", expected.name()));
            } else if found.scalar().is_some() && found.components() == 1 && expected.vector_len().is_some() {
                d = d.with_note(format!("widen explicitly: `{}(...)`", expected.name()));
            }
            self.error(d);
        }
    }
}
