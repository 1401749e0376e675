//! Semantic checks: name resolution, types, rate rules, definite assignment,
//! static loop bounds. Collects every error instead of stopping at the first.
//!
//! The result, [`Checked`], keeps the AST untouched and stores what it learned
//! in side tables keyed by [`NodeId`] and by typed ids ([`EffectId`],
//! [`LocalId`], ...), which the later stages read.

use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;
use crate::syntax::visit_expr;
use crate::types::{self, Scalar, Type};
use mrsl_abi::TextureFormat;
use std::collections::{HashMap, HashSet};

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
    Builtin(&'static str),
    Function(FunctionId),
    /// A constructor or conversion to this type.
    Construct(Type),
}

/// How a discontinuity-key channel is compared (part of the layout contract).
pub use mrsl_abi::KeyCompare;

#[derive(Debug, Clone)]
pub struct InputInfo {
    pub name: String,
    pub ty: Type,
    pub key: Option<KeyCompare>,
    pub span: Span,
}

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
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct ConstInfo {
    pub name: String,
    pub ty: Type,
    pub value: Option<ConstValue>,
    pub item: usize,
}

#[derive(Debug, Clone)]
pub struct FunctionInfo {
    pub name: String,
    pub ret: Type,
    pub params: Vec<LocalId>,
    pub item: usize,
    /// Functions this one calls.
    pub calls: Vec<FunctionId>,
}

#[derive(Debug, Clone)]
pub struct EffectInfo {
    pub name: String,
    pub rate: Rate,
    pub ty: Type,
    pub item: usize,
    pub span: Span,
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

#[derive(Debug, Clone)]
pub struct LocalInfo {
    pub name: String,
    pub ty: Type,
    pub span: Span,
    /// Assigned anywhere after its declaration (or, for parameters, at all).
    pub reassigned: bool,
    pub is_param: bool,
}

/// A compile-time value: a scalar, vector or matrix of numbers.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ConstValue {
    #[serde(skip)]
    pub ty: Type,
    pub values: Vec<f64>,
}

/// The checked program: the AST plus everything the checks learned about it.
#[derive(Debug)]
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
    pub fn effect_by_name(&self, name: &str) -> Option<EffectId> {
        self.effects.iter().position(|e| e.name == name).map(|i| EffectId(i as u32))
    }
}

/// Builtin functions, by name; see docs/language.md for their signatures.
pub const BUILTINS: &[&str] = &[
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "sinh",
    "cosh",
    "tanh",
    "exp",
    "exp2",
    "log",
    "log2",
    "sqrt",
    "inversesqrt",
    "floor",
    "ceil",
    "fract",
    "round",
    "trunc",
    "saturate",
    "radians",
    "degrees",
    "abs",
    "sign",
    "pow",
    "atan2",
    "step",
    "min",
    "max",
    "clamp",
    "mix",
    "lerp",
    "smoothstep",
    "dot",
    "cross",
    "normalize",
    "length",
    "distance",
    "reflect",
    "refract",
    "faceforward",
    "determinant",
    "transpose",
    "any",
    "all",
    "ddx",
    "ddy",
    "fwidth",
    "sample",
    "sample_level",
    "sample_grad",
    "load",
    "texture_size",
];

/// Derivative builtins: they need the operand at the neighbouring sample.
pub fn is_derivative(name: &str) -> bool {
    matches!(name, "ddx" | "ddy" | "fwidth" | "sample")
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

#[derive(Clone, Copy)]
enum Global {
    Input(InputId),
    Uniform(UniformId),
    Const(ConstId),
    Function(FunctionId),
    Effect(EffectId),
}

#[derive(Clone, Copy, PartialEq)]
enum Ctx {
    /// Constant contexts: const initialisers, uniform defaults, array lengths.
    Global,
    Function(FunctionId),
    Effect(EffectId),
}

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
}

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
            },
            diagnostics: vec![],
            globals: HashMap::new(),
            scopes: vec![],
            ctx: Ctx::Global,
            loop_depth: 0,
            in_derivative: false,
            evaluating_consts: HashSet::new(),
        }
    }

    fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    fn resolve_type(&mut self, name: &Ident) -> Type {
        match Type::from_name(&name.name) {
            Some(t) => t,
            None => {
                let mut d = err("E0102", format!("unknown type `{}`", name.name), name.span, "not a type");
                if let Some(s) = suggest(&name.name, TYPE_NAMES.iter().copied()) {
                    d = d.with_note(format!("did you mean `{s}`?"));
                }
                self.error(d);
                Type::Error
            }
        }
    }

    fn new_local(&mut self, name: &Ident, ty: Type, is_param: bool) -> LocalId {
        let id = LocalId(self.out.locals.len() as u32);
        self.out.locals.push(LocalInfo { name: name.name.clone(), ty, span: name.span, reassigned: false, is_param });
        id
    }

    /// Declares a local in the innermost scope, reporting duplicates there.
    fn declare_local(&mut self, name: &Ident, ty: Type, is_param: bool) -> LocalId {
        let id = self.new_local(name, ty, is_param);
        if self.globals.contains_key(&name.name) || BUILTINS.contains(&name.name.as_str()) {
            // Shadowing a global is allowed (as in C), but a builtin is reserved.
            if BUILTINS.contains(&name.name.as_str()) {
                self.error(err(
                    "E0103",
                    format!("`{}` is a builtin function name", name.name),
                    name.span,
                    "reserved name",
                ));
            }
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

    // ---- Globals ----------------------------------------------------------

    fn register_globals(&mut self) {
        let program = self.out.program;
        // Pass 1: names, so that items may refer to each other in any order.
        for (index, item) in program.items.iter().enumerate() {
            let name = item.name();
            // A reserved name is reported but still registered (unbound), so
            // that ids stay aligned with the items they index.
            let reserved = BUILTINS.contains(&name.name.as_str()) || Type::from_name(&name.name).is_some();
            if reserved {
                self.error(err(
                    "E0103",
                    format!("`{}` is a reserved name", name.name),
                    name.span,
                    "reserved: a builtin function or type",
                ));
            }
            let global = match item {
                Item::Input(_) => Global::Input(InputId(self.out.inputs.len() as u32)),
                Item::Uniform(_) => Global::Uniform(UniformId(self.out.uniforms.len() as u32)),
                Item::Const(_) => Global::Const(ConstId(self.out.consts.len() as u32)),
                Item::Function(_) => Global::Function(FunctionId(self.out.functions.len() as u32)),
                Item::Effect(_) => Global::Effect(EffectId(self.out.effects.len() as u32)),
            };
            if reserved {
            } else if let Some((_, first)) = self.globals.get(&name.name) {
                self.error(
                    Diagnostic::error("E0101", format!("`{}` is defined twice", name.name))
                        .with_label(Label::primary(name.span, "defined again here"))
                        .with_label(Label::secondary(*first, "first defined here")),
                );
            } else {
                self.globals.insert(name.name.clone(), (global, name.span));
            }
            match item {
                Item::Input(d) => {
                    let ty = self.resolve_type(&d.ty);
                    self.out.inputs.push(InputInfo { name: d.name.name.clone(), ty, key: None, span: d.span });
                }
                Item::Uniform(d) => {
                    let ty = self.resolve_type(&d.ty);
                    let kind = match ty {
                        Type::Texture2d => UniformKind::Texture,
                        Type::Sampler => UniformKind::Sampler,
                        _ => UniformKind::Value { default: None },
                    };
                    self.out.uniforms.push(UniformInfo { name: d.name.name.clone(), ty, kind, span: d.span });
                }
                Item::Const(d) => {
                    let ty = self.resolve_type(&d.ty);
                    self.out.consts.push(ConstInfo { name: d.name.name.clone(), ty, value: None, item: index });
                }
                Item::Function(d) => {
                    let ret = self.resolve_type(&d.ret);
                    self.out.functions.push(FunctionInfo {
                        name: d.name.name.clone(),
                        ret,
                        params: vec![],
                        item: index,
                        calls: vec![],
                    });
                }
                Item::Effect(d) => {
                    let ty = self.resolve_type(&d.ty);
                    self.out.effects.push(EffectInfo {
                        name: d.name.name.clone(),
                        rate: d.rate,
                        ty,
                        item: index,
                        span: d.span,
                        name_span: d.name.span,
                        deps: vec![],
                        has_refine: false,
                        nearest: false,
                        result: None,
                        format: None,
                    });
                }
            }
        }
        // Pass 2: declarations' own details (types allowed, attributes, defaults).
        let (mut input_i, mut uniform_i, mut const_i, mut effect_i) = (0, 0, 0, 0);
        for item in &program.items {
            match item {
                Item::Input(d) => {
                    self.check_input(InputId(input_i), d);
                    input_i += 1;
                }
                Item::Uniform(d) => {
                    self.check_uniform(UniformId(uniform_i), d);
                    uniform_i += 1;
                }
                Item::Const(_) => {
                    self.const_value(ConstId(const_i));
                    const_i += 1;
                }
                Item::Effect(d) => {
                    self.check_effect_decl(EffectId(effect_i), d);
                    effect_i += 1;
                }
                Item::Function(_) => {}
            }
        }
    }

    fn check_input(&mut self, id: InputId, d: &InputDecl) {
        let ty = self.out.inputs[id.index()].ty.clone();
        let allowed = matches!(
            ty,
            Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
        );
        if !allowed && !ty.is_error() {
            self.error(
                err("E0104", format!("a G-buffer channel cannot have type `{ty}`"), d.ty.span, "not a channel type")
                    .with_note("channels are scalars or vectors of float, int or uint"),
            );
        }
        for attr in &d.attrs {
            match attr.name.name.as_str() {
                "key" => {
                    let key = match attr.args.as_slice() {
                        [] => Some(KeyCompare::Exact),
                        [arg] => match self.const_eval(arg) {
                            Some(v) if v.values.len() == 1 && v.values[0] >= 0.0 => {
                                Some(KeyCompare::Threshold { threshold: v.values[0] })
                            }
                            _ => {
                                self.error(err(
                                    "E0111",
                                    "`@key` threshold must be a non-negative number",
                                    arg.span,
                                    "expected a number",
                                ));
                                None
                            }
                        },
                        _ => {
                            self.error(err(
                                "E0111",
                                "`@key` takes at most one argument",
                                attr.span,
                                "too many arguments",
                            ));
                            None
                        }
                    };
                    if matches!(key, Some(KeyCompare::Threshold { .. }))
                        && ty.scalar() != Some(Scalar::Float)
                        && !ty.is_error()
                    {
                        self.error(err(
                            "E0111",
                            "a threshold key must be a float channel",
                            attr.span,
                            "use `@key` for exact comparison",
                        ));
                    }
                    self.out.inputs[id.index()].key = key;
                }
                other => self.unknown_attribute(attr, other, &["key"]),
            }
        }
    }

    fn unknown_attribute(&mut self, attr: &Attribute, name: &str, known: &[&str]) {
        let list = known.iter().map(|k| format!("`@{k}`")).collect::<Vec<_>>().join(", ");
        self.error(
            err("E0110", format!("unknown attribute `@{name}` here"), attr.span, "not allowed on this declaration")
                .with_note(if known.is_empty() {
                    "this declaration takes no attributes".to_string()
                } else {
                    format!("allowed here: {list}")
                }),
        );
    }

    fn check_uniform(&mut self, id: UniformId, d: &UniformDecl) {
        for attr in &d.attrs {
            self.unknown_attribute(attr, &attr.name.name.clone(), &[]);
        }
        let mut ty = self.out.uniforms[id.index()].ty.clone();
        if matches!(ty, Type::AbstractFloat | Type::AbstractInt) {
            ty = Type::Error;
        }
        if let Some(len) = &d.array_len {
            let n = match self.const_eval(len) {
                Some(v)
                    if v.values.len() == 1
                        && v.values[0] >= 1.0
                        && v.values[0].fract() == 0.0
                        && v.values[0] <= 65536.0 =>
                {
                    v.values[0] as u32
                }
                _ => {
                    self.error(err(
                        "E0112",
                        "array length must be a positive integer constant",
                        len.span,
                        "not a constant length",
                    ));
                    1
                }
            };
            let sixteen = matches!(ty, Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, 4) | Type::Matrix(4));
            if !sixteen && !ty.is_error() {
                self.error(
                    err("E0113", format!("uniform arrays of `{ty}` are not supported"), d.ty.span, "element type")
                        .with_note("uniform array elements must be 16 bytes wide: use float4, int4, uint4 or float4x4"),
                );
            }
            ty = Type::Array(Box::new(ty), n);
            self.out.uniforms[id.index()].ty = ty.clone();
        }
        if let Some(default) = &d.default {
            match &self.out.uniforms[id.index()].kind {
                UniformKind::Texture | UniformKind::Sampler => {
                    self.error(err(
                        "E0114",
                        "textures and samplers cannot have a default",
                        default.span,
                        "remove this",
                    ));
                }
                UniformKind::Value { .. } => {
                    let value = self.const_eval(default);
                    match value {
                        Some(v) if v.ty.converts_to(&ty) || v.ty == ty => {
                            self.out.uniforms[id.index()].kind =
                                UniformKind::Value { default: Some(ConstValue { ty: ty.clone(), values: v.values }) };
                        }
                        Some(v) => self.error(err(
                            "E0201",
                            format!("default value has type `{}`, but the uniform is `{ty}`", v.ty),
                            default.span,
                            "wrong type",
                        )),
                        None => self.error(err(
                            "E0115",
                            "a uniform default must be a constant expression",
                            default.span,
                            "not constant",
                        )),
                    }
                }
            }
        }
    }

    fn check_effect_decl(&mut self, id: EffectId, d: &EffectDecl) {
        let ty = self.out.effects[id.index()].ty.clone();
        let ok = match d.rate {
            Rate::Out => matches!(
                ty,
                Type::Scalar(Scalar::Float | Scalar::Int | Scalar::Uint)
                    | Type::Vector(Scalar::Float | Scalar::Int | Scalar::Uint, _)
            ),
            _ => ty.is_value(),
        };
        if !ok && !ty.is_error() {
            let what = if d.rate == Rate::Out { "an output" } else { "an effect" };
            self.error(
                err("E0104", format!("{what} cannot have type `{ty}`"), d.ty.span, "unsupported type").with_note(
                    if d.rate == Rate::Out {
                        "outputs are scalars or vectors of float, int or uint"
                    } else {
                        "effects are scalars, vectors or matrices"
                    },
                ),
            );
        }
        for attr in &d.attrs {
            match (attr.name.name.as_str(), d.rate) {
                ("nearest", Rate::Coarse) if !attr.args.is_empty() => {
                    self.error(err("E0110", "`@nearest` takes no arguments", attr.span, "remove the arguments"))
                }
                ("nearest", Rate::Coarse) => self.out.effects[id.index()].nearest = true,
                ("format", Rate::Out) => {
                    let format = match attr.args.as_slice() {
                        [Expr { kind: ExprKind::Name(n), .. }] => Some(n.clone()),
                        _ => None,
                    };
                    match format {
                        Some(f) if let Some(fits) = output_format_fits(&f, &ty) => {
                            self.out.effects[id.index()].format = Some(fits)
                        }
                        Some(f) => self.error(
                            err(
                                "E0116",
                                format!("format `{f}` cannot store a `{ty}` output"),
                                attr.span,
                                "unsupported format",
                            )
                            .with_note(format!(
                                "formats for `{ty}`: {}",
                                formats_for(&ty).iter().map(|f| f.name()).collect::<Vec<_>>().join(", ")
                            )),
                        ),
                        None => self.error(err(
                            "E0116",
                            "`@format` takes one format name, e.g. `@format(rgba8unorm)`",
                            attr.span,
                            "expected a format name",
                        )),
                    }
                }
                (other, Rate::Coarse) => self.unknown_attribute(attr, other, &["nearest"]),
                (other, Rate::Out) => self.unknown_attribute(attr, other, &["format"]),
                (other, Rate::Fine) => self.unknown_attribute(attr, other, &[]),
            }
        }
        if d.rate == Rate::Out && self.out.effects[id.index()].format.is_none() && ok {
            self.out.effects[id.index()].format = Some(default_output_format(&ty));
        }
    }

    // ---- Constant evaluation ------------------------------------------------

    fn const_value(&mut self, id: ConstId) -> Option<ConstValue> {
        if let Some(v) = &self.out.consts[id.index()].value {
            return Some(v.clone());
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
        value
    }

    /// Evaluates literals, constants, arithmetic and constructors at compile time.
    fn const_eval(&mut self, e: &Expr) -> Option<ConstValue> {
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

    /// Whether an expression is made only of literals and constants (WGSL
    /// evaluates such expressions when the shader is created).
    fn is_constant(&self, e: &Expr) -> bool {
        let mut constant = true;
        visit_expr(e, &mut |x| match &x.kind {
            ExprKind::Name(n) => constant &= matches!(self.globals.get(n), Some((Global::Const(_), _))),
            ExprKind::Call { callee, .. } => constant &= Type::from_name(&callee.name).is_some(),
            ExprKind::Index { .. } | ExprKind::Field { .. } | ExprKind::Ternary(..) => constant = false,
            _ => {}
        });
        constant
    }

    /// Reports a constant expression whose value does not fit its type (as
    /// WGSL would at shader creation); returns whether it fits.
    fn constant_in_range(&mut self, e: &Expr, ty: &Type) -> bool {
        let Some(value) = self.const_eval(e) else { return true };
        let fits = |x: f64| match ty.scalar() {
            _ if *ty == Type::AbstractInt => (i32::MIN as f64..=i32::MAX as f64).contains(&x),
            Some(Scalar::Int) => (i32::MIN as f64..=i32::MAX as f64).contains(&x),
            Some(Scalar::Uint) => (0.0..=u32::MAX as f64).contains(&x),
            Some(Scalar::Float) => x.is_finite() && x.abs() <= f32::MAX as f64,
            _ => true,
        };
        if value.values.iter().all(|x| fits(*x)) {
            return true;
        }
        let what = if value.values.iter().any(|x| x.is_infinite() || x.is_nan()) {
            "divides by zero or overflows"
        } else {
            "out of range"
        };
        self.error(err("E0205", format!("constant expression out of range for `{}`", ty.concretize()), e.span, what));
        false
    }

    // ---- Bodies -------------------------------------------------------------

    fn check_bodies(&mut self) {
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
            params.push(self.declare_local(&p.name, ty, true));
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
                .with_label(Label::secondary(
                    Span { start: f.body.span.end.saturating_sub(1), end: f.body.span.end },
                    "can reach the end here",
                )),
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
            }
            EffectBody::Block(block) => {
                let ty = self.out.effects[id.index()].ty.clone();
                let result = self.declare_local(&e.name, ty, false);
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
                        .with_label(Label::secondary(
                            Span { start: block.span.end.saturating_sub(1), end: block.span.end },
                            "may reach the end unassigned",
                        ))
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
                }
                let id = self.declare_local(name, declared, false);
                self.out.local_decls.insert(s.id, id);
            }
            StmtKind::Assign { target, op, value } => {
                let target_ty = self.lvalue(target);
                let value_ty = self.expr(value);
                match op {
                    AssignOp::Set => self.expect_type(&value_ty, &target_ty, value.span, "assignment"),
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
                self.check_static_bound(s, init.as_deref(), cond.as_ref(), step.as_deref(), body);
                self.scopes.pop();
            }
            StmtKind::Block(b) => self.block(b),
            StmtKind::Refine => match self.ctx {
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
            },
            StmtKind::Return(value) => match self.ctx {
                Ctx::Function(id) => {
                    let ret = self.out.functions[id.index()].ret.clone();
                    match value {
                        Some(v) => {
                            let t = self.expr(v);
                            self.expect_type(&t, &ret, v.span, "return value");
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
            },
            StmtKind::Break | StmtKind::Continue => {
                if self.loop_depth == 0 {
                    let word = if matches!(s.kind, StmtKind::Break) { "break" } else { "continue" };
                    self.error(err("E0306", format!("`{word}` outside a loop"), s.span, "not inside a `for` loop"));
                }
            }
        }
    }

    fn scoped_stmt(&mut self, s: &Stmt) {
        self.scopes.push(HashMap::new());
        self.stmt(s);
        self.scopes.pop();
    }

    fn condition(&mut self, cond: &Expr, what: &str) {
        let t = self.expr(cond);
        if t != types::BOOL && !t.is_error() {
            let mut d = err("E0202", format!("{what} must be `bool`, found `{t}`"), cond.span, "not a bool");
            if matches!(t, Type::Vector(Scalar::Bool, _)) {
                d = d.with_note("use `any(...)` or `all(...)` to reduce a vector of bools");
            }
            self.error(d);
        }
    }

    /// Loops must have the form `for (T i = c0; i OP c1; i++ | i-- | i += c | i -= c)`
    /// with constant `c`s, and must not assign `i` in the body, so that the
    /// compiler (and the GPU's watchdog) can rely on a bounded trip count.
    fn check_static_bound(
        &mut self,
        s: &Stmt,
        init: Option<&Stmt>,
        cond: Option<&Expr>,
        step: Option<&Stmt>,
        body: &Stmt,
    ) {
        let var = match init.map(|i| &i.kind) {
            Some(StmtKind::Local { name, init: Some(v), ty }) => {
                if self.const_eval(v).is_none() {
                    self.error(err("E0401", "loop has no static bound", v.span, "the start value must be a constant"));
                    return;
                }
                if !matches!(Type::from_name(&ty.name), Some(Type::Scalar(Scalar::Int | Scalar::Uint))) {
                    self.error(err(
                        "E0401",
                        "loop has no static bound",
                        ty.span,
                        "the loop variable must be an `int` or `uint`",
                    ));
                    return;
                }
                name.name.clone()
            }
            _ => {
                self.error(
                    err("E0401", "loop has no static bound", s.span, "expected `for (int i = START; i < END; i++)`")
                        .with_note("the loop must declare its counter with a constant start value"),
                );
                return;
            }
        };
        let is_var = |e: &Expr| matches!(&e.kind, ExprKind::Name(n) if *n == var);
        let bound = match cond.map(|c| &c.kind) {
            Some(ExprKind::Binary(BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge | BinaryOp::Ne, a, b))
                if is_var(a) =>
            {
                Some(b.as_ref())
            }
            Some(ExprKind::Binary(BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge | BinaryOp::Ne, a, b))
                if is_var(b) =>
            {
                Some(a.as_ref())
            }
            _ => None,
        };
        match bound {
            Some(b) if self.const_eval(b).is_some() => {}
            Some(b) => {
                self.error(
                    err("E0401", "loop has no static bound", b.span, "not a constant")
                        .with_note("use a constant bound and test the dynamic limit inside: `for (int i = 0; i < 16; i++) { if (i >= count) break; ... }`"),
                );
                return;
            }
            None => {
                let span = cond.map(|c| c.span).unwrap_or(s.span);
                self.error(err(
                    "E0401",
                    "loop has no static bound",
                    span,
                    format!("expected `{var} < CONSTANT` (or <=, >, >=, !=)"),
                ));
                return;
            }
        }
        let step_ok = match step.map(|st| &st.kind) {
            Some(StmtKind::Step { target, .. }) => is_var(target),
            Some(StmtKind::Assign { target, op: AssignOp::Add | AssignOp::Sub, value }) => {
                is_var(target) && self.const_eval(value).is_some()
            }
            _ => false,
        };
        if !step_ok {
            let span = step.map(|st| st.span).unwrap_or(s.span);
            self.error(err(
                "E0401",
                "loop has no static bound",
                span,
                format!("expected `{var}++`, `{var}--` or `{var} += CONSTANT`"),
            ));
            return;
        }
        // The shape is right; now the trip count must be finite and modest.
        let start = match init.map(|i| &i.kind) {
            Some(StmtKind::Local { init: Some(v), .. }) => self.const_eval(v).map(|c| c.values[0]),
            _ => None,
        };
        let (op, var_left, limit) = match cond.map(|c| &c.kind) {
            Some(ExprKind::Binary(op, a, b)) => {
                (*op, is_var(a), self.const_eval(if is_var(a) { b } else { a }).map(|c| c.values[0]))
            }
            _ => (BinaryOp::Lt, true, None),
        };
        let delta = match step.map(|st| &st.kind) {
            Some(StmtKind::Step { increment, .. }) => Some(if *increment { 1.0 } else { -1.0 }),
            Some(StmtKind::Assign { op: AssignOp::Add, value, .. }) => self.const_eval(value).map(|c| c.values[0]),
            Some(StmtKind::Assign { op: AssignOp::Sub, value, .. }) => self.const_eval(value).map(|c| -c.values[0]),
            _ => None,
        };
        if let (Some(mut i), Some(limit), Some(delta)) = (start, limit, delta) {
            let holds = |i: f64| {
                let (x, y) = if var_left { (i, limit) } else { (limit, i) };
                match op {
                    BinaryOp::Lt => x < y,
                    BinaryOp::Le => x <= y,
                    BinaryOp::Gt => x > y,
                    BinaryOp::Ge => x >= y,
                    _ => x != y,
                }
            };
            let mut trips = 0u64;
            while holds(i) && trips <= MAX_LOOP_TRIPS {
                i += delta;
                trips += 1;
            }
            if trips > MAX_LOOP_TRIPS {
                self.error(
                    err(
                        "E0402",
                        "loop does not terminate within the iteration limit",
                        s.span,
                        format!("runs more than {MAX_LOOP_TRIPS} times"),
                    )
                    .with_note("check the direction of the step against the condition"),
                );
                return;
            }
        }
        if let Some(span) = stmt_assigns_name(body, &var) {
            self.error(
                err(
                    "E0401",
                    "loop has no static bound",
                    span,
                    format!("the loop variable `{var}` is assigned in the body"),
                )
                .with_label(Label::secondary(init.map(|i| i.span).unwrap_or(s.span), "declared here")),
            );
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
                        self.error(err(
                            "E0203",
                            format!("cannot assign to `{name}`"),
                            target.span,
                            format!("`{name}` is {what}"),
                        ));
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

    // ---- Expressions --------------------------------------------------------

    fn expr(&mut self, e: &Expr) -> Type {
        let t = self.expr_inner(e);
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
            ExprKind::Unary(op, inner) => {
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
                    UnaryOp::BitNot => {
                        matches!(t.scalar(), Some(Scalar::Int | Scalar::Uint)) && !matches!(t, Type::Matrix(_))
                    }
                };
                if ok && matches!(op, UnaryOp::Neg) && self.is_constant(inner) && !self.constant_in_range(e, &t) {
                    Type::Error
                } else if ok {
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
            ExprKind::Binary(op, a, b) => {
                let ta = self.expr(a);
                let tb = self.expr(b);
                if ta.is_error() || tb.is_error() {
                    return Type::Error;
                }
                match binary_type(*op, &ta, &tb) {
                    // WGSL folds literal-only arithmetic at shader creation;
                    // what it would reject must be reported here.
                    // WGSL folds constant arithmetic (literals, typed or not) at
                    // shader creation; what it would reject is reported here.
                    Ok(t) if self.is_constant(a) && self.is_constant(b) => {
                        let integer = matches!(t.scalar(), Some(Scalar::Int | Scalar::Uint)) && !t.is_abstract()
                            || t == Type::AbstractInt;
                        if matches!(op, BinaryOp::Div | BinaryOp::Rem)
                            && integer
                            && self.const_eval(b).is_some_and(|v| v.values.iter().any(|x| *x == 0.0))
                        {
                            self.error(err(
                                "E0205",
                                "division by zero in a constant expression",
                                e.span,
                                "divides by zero",
                            ));
                            return Type::Error;
                        }
                        if !self.constant_in_range(e, &t) {
                            return Type::Error;
                        }
                        t
                    }
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
            ExprKind::Ternary(c, a, b) => {
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

    fn field_type(&mut self, base: &Type, field: &Ident) -> Type {
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

    fn index_type(&mut self, base: &Type, index: &Expr, span: Span) -> Type {
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
        if is_derivative(name) {
            match self.ctx {
                Ctx::Effect(id) => {
                    if self.in_derivative {
                        self.error(err("E0502", format!("`{name}` inside the operand of another derivative"), e.span, "nested derivative").with_note(
                            "second derivatives are not supported; compute the first derivative as an effect and differentiate that",
                        ));
                    }
                    self.out.derivative_calls.push((id, e.id));
                }
                _ => {
                    self.error(
                        err("E0501", format!("`{name}` outside an effect body"), e.span, "derivatives need a sample position")
                            .with_note(if name == "sample" {
                                "inside functions use `sample_level` or `sample_grad`, or pass the sampled value as an argument"
                            } else {
                                "compute the derivative in the effect and pass it as an argument"
                            }),
                    );
                }
            }
        }
        let was_in_derivative = self.in_derivative;
        if is_derivative(name) {
            self.in_derivative = true;
        }
        let arg_types: Vec<Type> = args.iter().map(|a| self.expr(a)).collect();
        self.in_derivative = was_in_derivative;
        if arg_types.iter().any(|t| t.is_error()) {
            // Still resolve the callee so unknown functions are reported.
            if Type::from_name(name).is_none() && !BUILTINS.contains(&name) && !self.globals.contains_key(name) {
                self.error(err("E0100", format!("unknown function `{name}`"), callee.span, "not found"));
            }
            return Type::Error;
        }
        if let Some(ty) = Type::from_name(name) {
            self.out.callees.insert(e.id, Callee::Construct(ty.clone()));
            return match construct_check(&ty, &arg_types) {
                Ok(()) if args.iter().all(|a| self.is_constant(a)) => {
                    // `uint(-1)` and friends: WGSL rejects them when creating the shader.
                    let negative_to_uint = ty.scalar() == Some(Scalar::Uint)
                        && args.iter().any(|a| self.const_eval(a).is_some_and(|v| v.values.iter().any(|x| *x < 0.0)));
                    if negative_to_uint {
                        self.error(err("E0205", format!("`{name}` of a negative constant"), e.span, "out of range"));
                        return Type::Error;
                    }
                    if self.constant_in_range(e, &ty) { ty } else { Type::Error }
                }
                Ok(()) => ty,
                Err(message) => {
                    self.error(err("E0210", message, e.span, format!("in this `{name}` constructor")));
                    Type::Error
                }
            };
        }
        if let Some(&(Global::Function(fid), _)) = self.globals.get(name) {
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
            for ((arg, at), pt) in args.iter().zip(&arg_types).zip(&params) {
                self.expect_type(at, pt, arg.span, &format!("argument to `{name}`"));
            }
            return ret;
        }
        if let Some(builtin) = BUILTINS.iter().find(|b| **b == name) {
            self.out.callees.insert(e.id, Callee::Builtin(builtin));
            return match builtin_type(builtin, &arg_types) {
                Ok((ret, splat_to)) => {
                    if let Some(target) = splat_to {
                        for (arg, at) in args.iter().zip(&arg_types) {
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
                        format!(
                            "`{name}` takes {expected}, but {} argument{} were given",
                            args.len(),
                            plural(args.len())
                        ),
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
            };
        }
        let mut d = err("E0100", format!("unknown function `{name}`"), callee.span, "not found");
        let functions: Vec<String> = self
            .globals
            .iter()
            .filter(|(_, (g, _))| matches!(g, Global::Function(_)))
            .map(|(k, _)| k.clone())
            .collect();
        if let Some(s) = suggest(
            name,
            BUILTINS.iter().copied().chain(functions.iter().map(|s| s.as_str())).chain(TYPE_NAMES.iter().copied()),
        ) {
            d = d.with_note(format!("did you mean `{s}`?"));
        }
        self.error(d);
        Type::Error
    }

    // ---- Whole-program checks ----------------------------------------------

    fn check_function_recursion(&mut self) {
        // WGSL forbids recursion; report each function that can reach itself.
        let n = self.out.functions.len();
        for start in 0..n {
            let mut stack = vec![start];
            let mut seen = vec![false; n];
            while let Some(f) = stack.pop() {
                for callee in &self.out.functions[f].calls {
                    if callee.index() == start {
                        let decl = self.out.function_decl(FunctionId(start as u32));
                        let d = err(
                            "E0307",
                            format!("function `{}` is recursive", decl.name.name),
                            decl.name.span,
                            "calls itself, directly or indirectly",
                        )
                        .with_note("recursion is not available on GPUs (WGSL forbids it)");
                        self.diagnostics.push(d);
                        stack.clear();
                        break;
                    }
                    if !seen[callee.index()] {
                        seen[callee.index()] = true;
                        stack.push(callee.index());
                    }
                }
            }
        }
    }

    fn check_outputs_and_usage(&mut self) {
        let effects = &self.out.effects;
        if !effects.iter().any(|e| e.rate == Rate::Out) {
            let span = self.out.program.items.last().map(|i| i.name().span).unwrap_or_default();
            self.diagnostics.push(
                err("E0601", "the program has no output", span, "no `fine out` declared")
                    .with_note("declare at least one target, e.g. `fine out float4 color = ...;`"),
            );
        }
        // Unused-effect warnings only on programs without errors: after an
        // error (a duplicate, a bad name) they are mostly noise.
        if self.diagnostics.iter().any(|d| d.is_error()) {
            return;
        }
        // An effect is used when an output needs it, directly or through other effects.
        let mut live = vec![false; effects.len()];
        let mut stack: Vec<usize> = (0..effects.len()).filter(|&i| effects[i].rate == Rate::Out).collect();
        while let Some(i) = stack.pop() {
            if !std::mem::replace(&mut live[i], true) {
                stack.extend(effects[i].deps.iter().map(|(d, _)| d.index()));
            }
        }
        for (i, e) in effects.iter().enumerate() {
            if !live[i] {
                let read = effects.iter().any(|u| u.deps.iter().any(|(d, _)| d.index() == i));
                self.diagnostics.push(
                    Diagnostic::warning("W0001", format!("effect `{}` is never used", e.name))
                        .with_label(Label::primary(
                            e.name_span,
                            if read {
                                "read only by effects that no output needs"
                            } else {
                                "not read by any effect or output"
                            },
                        ))
                        .with_note("it will not be computed"),
                );
            }
        }
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

const TYPE_NAMES: &[&str] = &[
    "bool",
    "int",
    "uint",
    "float",
    "float2",
    "float3",
    "float4",
    "int2",
    "int3",
    "int4",
    "uint2",
    "uint3",
    "uint4",
    "bool2",
    "bool3",
    "bool4",
    "float2x2",
    "float3x3",
    "float4x4",
    "texture2d",
    "sampler",
];

/// The closest candidate within a small edit distance, for "did you mean".
fn suggest<'s>(name: &str, candidates: impl Iterator<Item = &'s str>) -> Option<&'s str> {
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let d = edit_distance(name, c);
        // Ties go to the alphabetically first name, so output is deterministic.
        if d <= (name.len() / 3).max(1) && best.is_none_or(|(bd, bc)| (d, c) < (bd, bc)) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

// Hand-written: a dozen lines of Levenshtein do not justify a dependency.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Loops may run at most this many times (a GPU watchdog would stop longer ones).
pub const MAX_LOOP_TRIPS: u64 = 1 << 16;

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

/// The span of a statement in `s` that assigns `name` (its root variable), if any.
fn stmt_assigns_name(s: &Stmt, name: &str) -> Option<Span> {
    fn root(e: &Expr) -> Option<&str> {
        match &e.kind {
            ExprKind::Name(n) => Some(n),
            ExprKind::Field { base, .. } | ExprKind::Index { base, .. } => root(base),
            _ => None,
        }
    }
    match &s.kind {
        StmtKind::Assign { target, .. } | StmtKind::Step { target, .. } if root(target) == Some(name) => Some(s.span),
        StmtKind::Local { name: n, .. } if n.name == name => None,
        StmtKind::Block(b) => {
            for s in &b.stmts {
                // A declaration of the same name shadows the loop variable from here on.
                if matches!(&s.kind, StmtKind::Local { name: n, .. } if n.name == name) {
                    return None;
                }
                if let Some(span) = stmt_assigns_name(s, name) {
                    return Some(span);
                }
            }
            None
        }
        StmtKind::If { then, otherwise, .. } => {
            stmt_assigns_name(then, name).or_else(|| otherwise.as_ref().and_then(|o| stmt_assigns_name(o, name)))
        }
        StmtKind::For { init, step, body, .. } => init
            .as_ref()
            .and_then(|i| stmt_assigns_name(i, name))
            .or_else(|| step.as_ref().and_then(|i| stmt_assigns_name(i, name)))
            .or_else(|| stmt_assigns_name(body, name)),
        _ => None,
    }
}

// ---- Operator and builtin typing ---------------------------------------------

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

/// The common type of two values of the same shape (for `?:`).
fn unify(a: &Type, b: &Type) -> Option<Type> {
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

fn binary_type(op: BinaryOp, a: &Type, b: &Type) -> Result<Type, String> {
    use BinaryOp::*;
    let mismatch = || format!("cannot apply `{}` to `{a}` and `{b}`", op.symbol());
    let (ea, sa) = parts(a).ok_or_else(mismatch)?;
    let (eb, sb) = parts(b).ok_or_else(mismatch)?;
    let elem = unify_elem(ea, eb).ok_or_else(|| {
        format!(
            "cannot apply `{}` to `{a}` and `{b}`: the element types differ (convert one side explicitly)",
            op.symbol()
        )
    })?;
    let is_num = |e: Elem| e != Elem::Bool;
    let is_int = |e: Elem| matches!(e, Elem::Int | Elem::Uint | Elem::AbsInt);
    match op {
        Add | Sub | Mul | Div | Rem => {
            if !is_num(elem) {
                return Err(mismatch());
            }
            let shape = match (sa, sb) {
                (x, y) if x == y => {
                    if let Shape::Mat(_) = x {
                        if matches!(op, Div | Rem) {
                            return Err(mismatch());
                        }
                    }
                    x
                }
                (Shape::Scalar, Shape::Vec(n)) | (Shape::Vec(n), Shape::Scalar) => Shape::Vec(n),
                (Shape::Scalar, Shape::Mat(n)) | (Shape::Mat(n), Shape::Scalar) if op == Mul => Shape::Mat(n),
                (Shape::Mat(n), Shape::Vec(m)) | (Shape::Vec(m), Shape::Mat(n)) if op == Mul && n == m => Shape::Vec(n),
                _ => return Err(mismatch()),
            };
            if let Shape::Mat(_) = shape {
                if !matches!(elem, Elem::Float | Elem::AbsFloat | Elem::AbsInt) {
                    return Err(mismatch());
                }
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
        Shl | Shr => {
            // The shift amount may be int or uint; WGSL wants u32, codegen converts.
            if is_int(ea) && is_int(eb) && sa == sb && !matches!(sa, Shape::Mat(_)) {
                // A literal shifted by a concrete amount concretizes to `int`, as in WGSL.
                let elem = match (ea, eb) {
                    (Elem::AbsInt, Elem::AbsInt) => Elem::AbsInt,
                    (Elem::AbsInt, _) => Elem::Int,
                    _ => ea,
                };
                Ok(build(elem, sa))
            } else {
                Err(mismatch())
            }
        }
    }
}

fn construct_check(ty: &Type, args: &[Type]) -> Result<(), String> {
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

enum BuiltinError {
    Arity(&'static str),
    Types(String),
}

/// Result type of a builtin call, and the vector type scalar arguments must
/// be widened to (WGSL builtins want all generic arguments of one type).
fn builtin_type(name: &str, args: &[Type]) -> Result<(Type, Option<Type>), BuiltinError> {
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
            if a.components() == 1
                && t.vector_len().is_some()
                && unify_elem(parts(a).map(|x| x.0).unwrap_or(Elem::Bool), parts(&t).map(|x| x.0).unwrap_or(Elem::Bool))
                    .is_none()
            {
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

/// Storage-texture formats an output of type `ty` may be written to.
pub fn formats_for(ty: &Type) -> Vec<TextureFormat> {
    use TextureFormat as F;
    // A format must hold every component: single-channel formats only for
    // scalars, two-channel ones for at most two components.
    let n = ty.components();
    let any = match ty {
        Type::Scalar(Scalar::Float) => vec![F::R32Float, F::Rgba16Float, F::Rgba32Float, F::Rgba8Unorm],
        Type::Vector(Scalar::Float, _) => vec![F::Rgba32Float, F::Rgba16Float, F::Rgba8Unorm, F::Rg32Float],
        Type::Scalar(Scalar::Uint) | Type::Vector(Scalar::Uint, _) => vec![F::R32Uint, F::Rgba32Uint],
        Type::Scalar(Scalar::Int) | Type::Vector(Scalar::Int, _) => vec![F::R32Sint, F::Rgba32Sint],
        _ => vec![],
    };
    any.into_iter().filter(|f| f.components() >= n.min(4) || f.components() == 4).collect()
}

/// The format called `format`, if an output of type `ty` may be written to it.
fn output_format_fits(format: &str, ty: &Type) -> Option<TextureFormat> {
    formats_for(ty).into_iter().find(|f| f.name() == format)
}

/// The default storage format of an output: exact 32-bit storage, so that
/// outputs can be compared bit for bit with the reference.
pub fn default_output_format(ty: &Type) -> TextureFormat {
    use TextureFormat as F;
    match ty {
        Type::Scalar(Scalar::Float) => F::R32Float,
        Type::Vector(Scalar::Float, _) => F::Rgba32Float,
        Type::Scalar(Scalar::Uint) => F::R32Uint,
        Type::Vector(Scalar::Uint, _) => F::Rgba32Uint,
        Type::Scalar(Scalar::Int) => F::R32Sint,
        _ => F::Rgba32Sint,
    }
}
