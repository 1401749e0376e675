//! A generator of well-typed mrsl programs, valid by construction: every
//! program it writes must pass `mrsl::check` with no diagnostic at all, and
//! `mrsl::compile` must turn it into kernels that naga accepts.
//!
//! It tracks the type of every name and expression while it writes, and
//! covers inputs (with `@key`, `@key(t)`, `@surface_key` and background
//! rules, `@background` and `@foreground`), value uniforms, uniform arrays,
//! textures and samplers, constants, functions (with texture and sampler
//! parameters, early returns and calls to earlier functions), coarse effects
//! (plain, `coarse(4)` reading only `coarse(4)` ones, and `coarse(2)`)
//! with `refine` predicates over derivatives, fine effects and outputs (with
//! `@nearest` and `@format`), locals, compound assignments, component
//! assignments, `++`/`--`, `if`/`else`, `for` loops with static bounds and
//! `break`/`continue`, derivatives (`ddx`, `ddy`, `fwidth`, `sample`, also
//! through single-definition locals), texture reads, every operator, swizzles,
//! indexing, constructors, conversions and the builtins.
//!
//! It also writes what the fuzzing found the compiler mishandling before
//! (docs/eval/fuzzing-campaigns.md, findings): `?:` on matrices and `@nearest` matrix
//! effects, names WGSL reserves or that collide with escaped names, locals
//! that shadow constants and functions, operations whose operands are all
//! constant (builtins, `%`, shifts, indexing, within the ranges WGSL
//! allows), and locals holding constants used as divisors (zero included),
//! shift amounts and indices (out of range included), which are run-time
//! values. It leaves out what the checks reject (E0205, E0213, E0214: a
//! constant division by zero, a constant index out of range, ...) and
//! nesting past the limits (E0602-E0604).
//!
//! The module has no dependencies: it draws its decisions from a [`Choices`].
//! The `wellformed` cargo-fuzz target (compiler/fuzz) implements it over
//! `arbitrary::Unstructured`, and the proptest smoke in `fuzz.rs` over a
//! seeded [`SplitMix`].

#![allow(dead_code)]

use std::collections::BTreeSet;
use std::fmt::Write;

/// The warnings a generated program may draw: W0002 (a key no coarse
/// effect reads), W0003 (a surface derivative that is its plain form),
/// W0004 (a coarse value built on derivatives) and W0005 (a derivative of
/// uniforms and constants), since the generator draws `@key` attributes,
/// derivatives and their operands independently of what its effects read
/// and of their rates. The
/// `wellformed` fuzz target and the proptest smoke both take this list.
pub const ALLOWED_WARNINGS: &[&str] = &["W0002", "W0003", "W0004", "W0005"];

/// The warnings the generator avoids by construction: W0001 (an effect no
/// output needs: every effect it writes is read). With [`ALLOWED_WARNINGS`]
/// these are every warning the compiler has (a test in `fuzz.rs` holds the
/// compiler's source to it), so a new warning must be placed in one list
/// before the fuzzing can run into it.
pub const AVOIDED_WARNINGS: &[&str] = &["W0001"];

/// Where the generator's decisions come from.
pub trait Choices {
    /// A number in `0..n` (`n >= 1`). Out of input, return 0: the generator
    /// then takes the first, simplest choice everywhere and terminates.
    fn below(&mut self, n: usize) -> usize;
}

/// A small seeded generator (SplitMix64), for the proptest smoke.
pub struct SplitMix(pub u64);

impl Choices for SplitMix {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z % n.max(1) as u64) as usize
    }
}

/// A generated program and the language features it uses (for coverage
/// figures: see `features_of_many`).
pub struct Generated {
    pub source: String,
    pub features: BTreeSet<&'static str>,
}

/// Writes one well-typed program.
pub fn program(choices: &mut dyn Choices) -> Generated {
    let mut g = Gen::new(choices);
    g.program();
    Generated { source: g.out, features: g.features }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum S {
    F,
    I,
    U,
    B,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Ty {
    S(S),
    V(S, u8),
    M(u8),
    Tex,
    Smp,
}

use Ty::{M, V};

const FLOAT: Ty = Ty::S(S::F);
const INT: Ty = Ty::S(S::I);
const UINT: Ty = Ty::S(S::U);
const BOOL: Ty = Ty::S(S::B);

impl Ty {
    fn name(self) -> String {
        let s = |s: S| match s {
            S::F => "float",
            S::I => "int",
            S::U => "uint",
            S::B => "bool",
        };
        match self {
            Ty::S(x) => s(x).into(),
            V(x, n) => format!("{}{n}", s(x)),
            M(n) => format!("float{n}x{n}"),
            Ty::Tex => "texture2d".into(),
            Ty::Smp => "sampler".into(),
        }
    }
    fn scalar(self) -> Option<S> {
        match self {
            Ty::S(s) | V(s, _) => Some(s),
            M(_) => Some(S::F),
            _ => None,
        }
    }
    fn width(self) -> u8 {
        match self {
            V(_, n) => n,
            _ => 1,
        }
    }
    fn with_width(s: S, n: u8) -> Ty {
        if n == 1 { Ty::S(s) } else { V(s, n) }
    }
    fn is_value(self) -> bool {
        !matches!(self, Ty::Tex | Ty::Smp)
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Rate {
    Coarse,
    Fine,
    Out,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Input,
    Uniform,
    Const,
    Effect(Rate),
    /// A local: whether it may be assigned, and whether a derivative may read it.
    Local {
        mutable: bool,
        deriv_ok: bool,
        konst: bool,
    },
    Param,
    Counter {
        deriv_ok: bool,
    },
    /// The block-form effect's own name.
    Own {
        mutable: bool,
        deriv_ok: bool,
    },
}

#[derive(Clone, Debug)]
struct Var {
    name: String,
    ty: Ty,
    kind: Kind,
}

struct Func {
    name: String,
    ret: Ty,
    params: Vec<Ty>,
}

/// A uniform array: name, element type, length.
struct Array {
    name: String,
    ty: Ty,
    len: u32,
}

/// An expression: its text, whether WGSL would see a constant expression
/// (naga also folds `let`-bound constants), and whether a derivative may
/// re-evaluate it at the neighbouring sample.
#[derive(Clone, Debug)]
struct E {
    text: String,
    konst: bool,
    dsafe: bool,
    literal: bool,
}

impl E {
    fn lit(text: impl Into<String>) -> E {
        E { text: text.into(), konst: true, dsafe: true, literal: true }
    }
    fn new(text: String, parts: &[&E]) -> E {
        E { text, konst: parts.iter().all(|p| p.konst), dsafe: parts.iter().all(|p| p.dsafe), literal: false }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Body {
    Function,
    Effect(Rate),
}

/// Where an expression or statement is being written.
struct Ctx {
    body: Body,
    scopes: Vec<Vec<Var>>,
    /// Inside a derivative operand: only `dsafe` leaves, no derivatives.
    deriv: bool,
    /// Inside a loop (for `break`/`continue`), and whether it may exit early.
    loops: Vec<bool>,
    /// Inside an `if` or a loop that may exit early: what is assigned here varies.
    varying: bool,
    /// The effect being written (it cannot read itself by name in expression form).
    effect: Option<String>,
    stmt_depth: u32,
}

const MAX_EXPR_DEPTH: u32 = 4;
const MAX_STMT_DEPTH: u32 = 3;

/// Name stems: some collide with WGSL keywords, generated names or entry
/// points, which the compiler must rename (a numeric suffix is added unless
/// the bare word is free).
const STEMS: &[&str] = &[
    "a",
    "b",
    "c",
    "light",
    "shade",
    "tint",
    "x",
    "y",
    "t",
    "var",
    "loop",
    "fn",
    "let",
    "struct",
    "override",
    "u",
    "pos",
    "k",
    "li",
    "qx",
    "qy",
    "wg",
    "coarse_main",
    "fine_main",
    "hier_t",
    "cb_t",
    "mrsl_t",
    "MrslT",
    "vec3",
    "f32",
    "select",
    "array",
    "ptr",
    "bitcast",
    "workgroup",
    // WGSL reserves names starting with `__`, and `_` alone; names ending in
    // `_` or `_l` are what escaped names look like; `mrsl_eval_x` is a
    // generated function's name.
    "__t",
    "_",
    "x_",
    "var_",
    "k_l",
    "mrsl_eval_x",
];

struct Gen<'c> {
    c: &'c mut dyn Choices,
    out: String,
    features: BTreeSet<&'static str>,
    globals: Vec<Var>,
    arrays: Vec<Array>,
    textures: Vec<String>,
    samplers: Vec<String>,
    functions: Vec<Func>,
    /// Effects written so far, each with where its declaration ends in `out`.
    effects: Vec<(Var, usize)>,
    /// Effects whose evaluation takes a derivative, directly or through the
    /// effects they read: a derivative may not read them, since each link
    /// of such a chain evaluates the next at more neighbours and a chain
    /// grows past the size budget E0701 (which `tests/it/limits.rs` covers).
    differentiating: BTreeSet<String>,
    /// The `coarse(4)` effects: only they may read one another (E0312).
    outer: BTreeSet<String>,
    used: BTreeSet<String>,
    /// Nodes left: bounds the program's size.
    budget: i64,
}

impl<'c> Gen<'c> {
    fn new(c: &'c mut dyn Choices) -> Self {
        Gen {
            c,
            out: String::new(),
            features: BTreeSet::new(),
            globals: vec![],
            arrays: vec![],
            textures: vec![],
            samplers: vec![],
            functions: vec![],
            effects: vec![],
            differentiating: BTreeSet::new(),
            outer: BTreeSet::new(),
            used: BTreeSet::new(),
            budget: 0,
        }
    }

    fn below(&mut self, n: usize) -> usize {
        if n <= 1 { 0 } else { self.c.below(n).min(n - 1) }
    }
    fn chance(&mut self, num: usize, den: usize) -> bool {
        self.below(den) < num
    }
    fn pick<T: Clone>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())].clone()
    }
    fn feat(&mut self, f: &'static str) {
        self.features.insert(f);
    }

    /// A fresh name, unique in the whole program (locals included, so no
    /// shadowing happens by accident).
    fn fresh(&mut self) -> String {
        let stem = self.pick(STEMS);
        let name = if !self.used.contains(stem) && self.chance(1, 3) {
            stem.to_string()
        } else {
            let mut i = self.used.len();
            loop {
                let n = format!("{stem}{i}");
                if !self.used.contains(&n) {
                    break n;
                }
                i += 1;
            }
        };
        if name.starts_with('_') || name.ends_with('_') || name.ends_with("_l") || name.starts_with("mrsl") {
            self.feat("name WGSL reserves or escapes");
        }
        self.used.insert(name.clone());
        name
    }

    // ----- types and literals -------------------------------------------------

    fn scalar_kind(&mut self) -> S {
        match self.below(8) {
            0..=3 => S::F,
            4 | 5 => S::I,
            6 => S::U,
            _ => S::B,
        }
    }

    fn value_type(&mut self) -> Ty {
        match self.below(10) {
            0..=3 => {
                let s = self.scalar_kind();
                Ty::S(s)
            }
            4..=8 => {
                let s = self.scalar_kind();
                V(s, 2 + self.below(3) as u8)
            }
            _ => M(2 + self.below(3) as u8),
        }
    }

    fn numeric_type(&mut self) -> Ty {
        let s = match self.below(4) {
            0 | 1 => S::F,
            2 => S::I,
            _ => S::U,
        };
        if self.chance(1, 2) { Ty::S(s) } else { V(s, 2 + self.below(3) as u8) }
    }

    fn scalar_literal(&mut self, s: S) -> String {
        match s {
            S::F => self.pick(&["0.0", "1.0", "0.5", "2.5", "0.25f", ".5", "3.", "1e-3", "1.5e1", "0.75F"]).into(),
            S::I => self.pick(&["0", "1", "2", "3", "7", "3i", "0x1F", "16"]).into(),
            S::U => self.pick(&["0u", "1u", "2u", "5u", "0xFFu", "4294967295u", "7U"]).into(),
            S::B => self.pick(&["true", "false"]).into(),
        }
    }

    /// A positive literal of kind `s` (safe to convert to any other kind).
    fn positive_literal(&mut self, s: S) -> String {
        match s {
            S::F => self.pick(&["1.0", "0.5", "2.5"]).into(),
            S::I => self.pick(&["1", "2", "5i"]).into(),
            S::U => self.pick(&["1u", "3u"]).into(),
            S::B => "true".into(),
        }
    }

    /// A constant expression of type `ty`: literals and constructors of them.
    fn literal(&mut self, ty: Ty) -> E {
        match ty {
            Ty::S(s) => E::lit(self.scalar_literal(s)),
            V(s, n) => {
                if self.chance(1, 2) {
                    let x = self.scalar_literal(s);
                    E::lit(format!("{}({x})", ty.name()))
                } else {
                    let xs: Vec<String> = (0..n).map(|_| self.scalar_literal(s)).collect();
                    E::lit(format!("{}({})", ty.name(), xs.join(", ")))
                }
            }
            M(n) => {
                let cols: Vec<String> = (0..n).map(|_| self.literal(V(S::F, n)).text).collect();
                E::lit(format!("{}({})", ty.name(), cols.join(", ")))
            }
            _ => unreachable!("no literal of {ty:?}"),
        }
    }

    // ----- the program ----------------------------------------------------------

    fn program(&mut self) {
        self.budget = 150 + self.below(400) as i64;
        // Always present: a non-constant float for every context.
        self.used.insert("uv".into());
        self.used.insert("gain".into());
        self.globals.push(Var { name: "uv".into(), ty: V(S::F, 2), kind: Kind::Input });
        self.globals.push(Var { name: "gain".into(), ty: FLOAT, kind: Kind::Uniform });
        let _ = writeln!(self.out, "in float2 uv;");
        let _ = writeln!(self.out, "uniform float gain = 0.5;");

        let inputs = self.below(4);
        for _ in 0..inputs {
            self.input();
        }
        let uniforms = self.below(5);
        for _ in 0..uniforms {
            self.uniform();
        }
        let consts = self.below(4);
        for _ in 0..consts {
            self.constant();
        }
        let functions = self.below(4);
        for _ in 0..functions {
            self.function();
        }
        let effects = 1 + self.below(6);
        for _ in 0..effects {
            if self.budget <= 0 {
                break;
            }
            self.effect();
        }
        self.final_output();
    }

    fn input(&mut self) {
        let s = match self.below(4) {
            0 | 1 => S::F,
            2 => S::I,
            _ => S::U,
        };
        let ty = if self.chance(1, 3) { Ty::S(s) } else { V(s, 2 + self.below(3) as u8) };
        let name = self.fresh();
        let mut attr = match self.below(6) {
            0 => {
                self.feat("@key");
                "@key ".to_string()
            }
            1 if s == S::F => {
                self.feat("@key(threshold)");
                format!("@key({}) ", self.pick(&["0.05", "0.0", "1", "0.5"]))
            }
            2 if ty == V(S::F, 3) => self.surface_key(),
            _ => String::new(),
        };
        // A background rule, alone or beside a key (a channel may be both).
        if matches!(ty, Ty::S(_)) && self.chance(1, 3) {
            attr.push_str(&self.background_rule(s));
        }
        self.feat("input");
        let _ = writeln!(self.out, "{attr}in {} {name};", ty.name());
        self.globals.push(Var { name, ty, kind: Kind::Input });
    }

    /// `@surface_key(n, t)` naming an earlier `float3` input as the normal,
    /// declaring one first where there is none.
    fn surface_key(&mut self) -> String {
        let mut normals: Vec<String> = self
            .globals
            .iter()
            .filter(|v| matches!(v.kind, Kind::Input) && v.ty == V(S::F, 3))
            .map(|v| v.name.clone())
            .collect();
        if normals.is_empty() {
            let name = self.fresh();
            let _ = writeln!(self.out, "in float3 {name};");
            self.globals.push(Var { name: name.clone(), ty: V(S::F, 3), kind: Kind::Input });
            normals.push(name);
        }
        self.feat("@surface_key");
        let normal = self.pick(&normals);
        format!("@surface_key({normal}, {}) ", self.pick(&["0.25", "0.0", "1", "0.05"]))
    }

    /// `@background(v)` or `@foreground(v)` with a value of the channel's
    /// scalar type `s` (for a float channel also zero, whose two bit patterns
    /// compare equal, and a large one).
    fn background_rule(&mut self, s: S) -> String {
        let value = match s {
            S::U => self.pick(&["0", "255", "7"]),
            S::I => self.pick(&["0", "-1", "3"]),
            _ => self.pick(&["0.0", "1.0", "-0.5", "1000000.0"]),
        };
        if self.chance(1, 4) {
            self.feat("@foreground");
            format!("@foreground({value}) ")
        } else {
            self.feat("@background");
            format!("@background({value}) ")
        }
    }

    fn uniform(&mut self) {
        let name = self.fresh();
        match self.below(8) {
            0 => {
                self.feat("texture2d");
                let _ = writeln!(self.out, "uniform texture2d {name};");
                self.textures.push(name);
            }
            1 => {
                self.feat("sampler");
                let _ = writeln!(self.out, "uniform sampler {name};");
                self.samplers.push(name);
            }
            2 => {
                self.feat("uniform array");
                let ty = self.pick(&[V(S::F, 4), V(S::I, 4), V(S::U, 4), M(4)]);
                let len = 1 + self.below(16) as u32;
                if self.chance(1, 3) {
                    self.feat("uniform array default");
                    let elements: Vec<String> = (0..len).map(|_| self.const_expr(ty).text).collect();
                    let _ = writeln!(self.out, "uniform {} {name}[{len}] = {{ {} }};", ty.name(), elements.join(", "));
                } else {
                    let _ = writeln!(self.out, "uniform {} {name}[{len}];", ty.name());
                }
                self.arrays.push(Array { name, ty, len });
            }
            _ => {
                self.feat("uniform");
                let ty = self.value_type();
                if self.chance(1, 2) {
                    self.feat("uniform default");
                    let value = self.const_expr(ty);
                    let _ = writeln!(self.out, "uniform {} {name} = {};", ty.name(), value.text);
                } else {
                    let _ = writeln!(self.out, "uniform {} {name};", ty.name());
                }
                self.globals.push(Var { name, ty, kind: Kind::Uniform });
            }
        }
    }

    /// A constant expression: a literal, an earlier constant, or a constructor
    /// of them; a few safe operators on small values.
    fn const_expr(&mut self, ty: Ty) -> E {
        let consts: Vec<String> =
            self.globals.iter().filter(|v| v.kind == Kind::Const && v.ty == ty).map(|v| v.name.clone()).collect();
        match self.below(5) {
            0 if !consts.is_empty() => {
                let c = self.pick(&consts);
                match ty.scalar() {
                    Some(S::F) if !matches!(ty, M(_)) => {
                        self.feat("constant arithmetic");
                        E::lit(format!("{c} * {} + {}", self.pick(&["0.5", "2.0"]), self.pick(&["1.0", "0.25"])))
                    }
                    Some(S::I) => E::lit(format!("-{c} + {}", self.pick(&["1", "2"]))),
                    _ => E::lit(c),
                }
            }
            1 if matches!(ty, Ty::S(S::F) | Ty::S(S::I)) => {
                E::lit(format!("-{}", self.positive_literal(ty.scalar().unwrap())))
            }
            _ => self.literal(ty),
        }
    }

    fn constant(&mut self) {
        let s = self.scalar_kind();
        let ty = if self.chance(1, 2) { Ty::S(s) } else { V(s, 2 + self.below(3) as u8) };
        let name = self.fresh();
        let value = self.const_expr(ty);
        self.feat("const");
        let _ = writeln!(self.out, "const {} {name} = {};", ty.name(), value.text);
        self.globals.push(Var { name, ty, kind: Kind::Const });
    }

    fn function(&mut self) {
        let name = self.fresh();
        let ret = self.value_type();
        let nparams = self.below(4);
        let mut params = vec![];
        let mut ctx = Ctx {
            body: Body::Function,
            scopes: vec![vec![]],
            deriv: false,
            loops: vec![],
            varying: false,
            effect: None,
            stmt_depth: 0,
        };
        let mut text = vec![];
        for _ in 0..nparams {
            let ty = match self.below(8) {
                0 if !self.textures.is_empty() => Ty::Tex,
                1 if !self.samplers.is_empty() => Ty::Smp,
                _ => self.value_type(),
            };
            let p = self.fresh();
            text.push(format!("{} {p}", ty.name()));
            params.push(ty);
            ctx.scopes[0].push(Var { name: p, ty, kind: Kind::Param });
        }
        self.feat("function");
        if params.iter().any(|t| matches!(t, Ty::Tex | Ty::Smp)) {
            self.feat("texture parameter");
        }
        let mut body = String::new();
        let n = self.below(4);
        for _ in 0..n {
            self.stmt(&mut ctx, &mut body, 1, Some(ret));
        }
        let value = self.expr(&ctx, ret, 0, false);
        let _ = writeln!(body, "    return {};", value.text);
        let _ = writeln!(self.out, "{} {name}({}) {{\n{body}}}", ret.name(), text.join(", "));
        self.functions.push(Func { name, ret, params });
    }

    fn effect(&mut self) {
        let rate = match self.below(6) {
            0..=2 => Rate::Coarse,
            3 | 4 => Rate::Fine,
            _ => Rate::Out,
        };
        let ty = if rate == Rate::Out {
            let s = self.pick(&[S::F, S::F, S::I, S::U]);
            if self.chance(1, 3) { Ty::S(s) } else { V(s, 2 + self.below(3) as u8) }
        } else {
            self.value_type()
        };
        let name = self.fresh();
        let mut attr = String::new();
        if rate == Rate::Coarse && self.chance(1, 4) {
            self.feat(if matches!(ty, M(_)) { "@nearest matrix" } else { "@nearest" });
            attr = "@nearest ".into();
        }
        if rate == Rate::Out && self.chance(1, 3) {
            self.feat("@format");
            let formats: &[&str] = match ty {
                Ty::S(S::F) => &["r32float", "rgba16float", "rgba32float", "rgba8unorm"],
                V(S::F, 2) => &["rgba32float", "rgba16float", "rgba8unorm", "rg32float"],
                V(S::F, _) => &["rgba32float", "rgba16float", "rgba8unorm"],
                Ty::S(S::U) => &["r32uint", "rgba32uint"],
                V(S::U, _) => &["rgba32uint"],
                Ty::S(S::I) => &["r32sint", "rgba32sint"],
                _ => &["rgba32sint"],
            };
            attr = format!("@format({}) ", self.pick(formats));
        }
        // A coarse effect's own rate: plain (the mode's), or one of the
        // multi-rate mode's levels; a coarse(4) one reads only coarse(4) ones.
        let level = if rate == Rate::Coarse { self.pick(&["", "", "(4)", "(2)"]) } else { "" };
        if level == "(4)" {
            self.outer.insert(name.clone());
        }
        let rate_text = match rate {
            Rate::Coarse => format!("coarse{level} effect"),
            Rate::Fine => "fine effect".into(),
            Rate::Out => "fine out".into(),
        };
        self.feat(match (rate, level) {
            (Rate::Coarse, "(4)") => "coarse(4) effect",
            (Rate::Coarse, "(2)") => "coarse(2) effect",
            (Rate::Coarse, _) => "coarse effect",
            (Rate::Fine, _) => "fine effect",
            (Rate::Out, _) => "fine out",
        });
        let mut ctx = Ctx {
            body: Body::Effect(rate),
            scopes: vec![vec![]],
            deriv: false,
            loops: vec![],
            varying: false,
            effect: Some(name.clone()),
            stmt_depth: 0,
        };
        let header = format!("{attr}{rate_text} {} {name}", ty.name());
        let start = self.out.len();
        if self.chance(1, 3) {
            self.feat("expression-form effect");
            let value = self.expr(&ctx, ty, 0, false);
            let _ = writeln!(self.out, "{header} = {};", value.text);
        } else {
            self.feat("block-form effect");
            // Single-assignment mode: the own name is assigned once, at the
            // top level, so derivatives (a refine predicate) may read it after.
            let single = self.chance(1, 2);
            ctx.scopes[0].push(Var { name: name.clone(), ty, kind: Kind::Own { mutable: !single, deriv_ok: false } });
            let mut body = String::new();
            let before = self.below(4);
            for _ in 0..before {
                self.stmt(&mut ctx, &mut body, 1, None);
            }
            let value = self.expr(&ctx, ty, 0, false);
            let _ = writeln!(body, "    {name} = {};", value.text);
            if single && value.dsafe {
                for v in ctx.scopes[0].iter_mut() {
                    if v.name == name {
                        v.kind = Kind::Own { mutable: false, deriv_ok: true };
                    }
                }
            }
            if rate == Rate::Coarse && self.chance(2, 3) {
                self.refine_predicate(&mut ctx, &mut body, &name, ty);
            }
            let after = self.below(3);
            for _ in 0..after {
                self.stmt(&mut ctx, &mut body, 1, None);
            }
            let _ = writeln!(self.out, "{header} {{\n{body}}}");
        }
        let text = &self.out[start..];
        let reads = names_in(text);
        if ["ddx(", "ddy(", "fwidth(", "ddx_surface(", "ddy_surface(", "fwidth_surface("]
            .iter()
            .any(|d| text.contains(d))
            || reads.iter().any(|r| self.differentiating.contains(*r))
        {
            self.differentiating.insert(name.clone());
        }
        self.effects.push((Var { name, ty, kind: Kind::Effect(rate) }, self.out.len()));
    }

    /// `if (fwidth(...) > t) refine;` and its relatives.
    fn refine_predicate(&mut self, ctx: &mut Ctx, body: &mut String, own: &str, ty: Ty) {
        let own_ok =
            ctx.scopes[0].iter().any(|v| v.name == own && v.kind == Kind::Own { mutable: false, deriv_ok: true });
        let threshold = if self.chance(1, 2) { "gain".to_string() } else { self.pick(&["0.05", "0.1", "0.01"]).into() };
        let f = self.pick(&["fwidth", "ddx", "ddy", "fwidth_surface"]);
        self.feat("refine");
        match self.below(4) {
            0 if own_ok && ty.scalar() == Some(S::F) && !matches!(ty, M(_)) => {
                self.feat("refine on derivative of own value");
                if ty.width() == 1 {
                    let _ = writeln!(body, "    if (abs({f}({own})) > {threshold})\n        refine;");
                } else {
                    let _ =
                        writeln!(body, "    if (any(abs({f}({own})) > {}({threshold})))\n        refine;", ty.name());
                }
            }
            1 => {
                self.feat("refine (unconditional)");
                let _ = writeln!(body, "    refine;");
            }
            2 => {
                let c = self.expr(ctx, BOOL, 1, false);
                let _ = writeln!(body, "    if ({})\n        refine;", c.text);
            }
            _ => {
                self.feat("refine on derivative");
                ctx.deriv = true;
                let operand = self.expr(ctx, FLOAT, 1, true);
                ctx.deriv = false;
                let _ = writeln!(body, "    if (abs({f}({})) > {threshold}) {{\n        refine;\n    }}", operand.text);
            }
        }
    }

    /// The last output: reads every effect nothing has read yet, so that
    /// every effect is live (no W0001). An effect is read when its name
    /// stands in a later declaration: it is found in the text rather than
    /// recorded when an expression reads it, since the generator sometimes
    /// writes an expression and throws it away.
    fn final_output(&mut self) {
        let mut terms = vec![];
        let unread: Vec<Var> = self
            .effects
            .iter()
            .filter(|(v, end)| !names_in(&self.out[*end..]).contains(v.name.as_str()))
            .map(|(v, _)| v.clone())
            .collect();
        for v in unread {
            if v.kind == Kind::Effect(Rate::Out) {
                continue;
            }
            terms.push(to_float(&v.name, v.ty));
        }
        let has_output = self.effects.iter().any(|(v, _)| v.kind == Kind::Effect(Rate::Out));
        if terms.is_empty() && has_output {
            return;
        }
        terms.push("uv.x".into());
        let name = self.fresh();
        self.feat("fine out");
        let _ = writeln!(self.out, "fine out float4 {name} = float4({}, gain, 0.0, 1.0);", terms.join(" + "));
    }

    // ----- statements -------------------------------------------------------

    fn visible(&self, ctx: &Ctx) -> Vec<Var> {
        let mut out: Vec<Var> = vec![];
        let mut seen = BTreeSet::new();
        for scope in ctx.scopes.iter().rev() {
            for v in scope.iter().rev() {
                if seen.insert(v.name.clone()) {
                    out.push(v.clone());
                }
            }
        }
        for v in &self.globals {
            if seen.contains(&v.name) {
                continue;
            }
            let ok = !(ctx.body == Body::Function && v.kind == Kind::Input);
            if ok {
                out.push(v.clone());
            }
        }
        if let Body::Effect(rate) = ctx.body {
            for (v, _) in &self.effects {
                if seen.contains(&v.name) || ctx.effect.as_deref() == Some(v.name.as_str()) {
                    continue;
                }
                let outer = ctx.effect.as_ref().is_some_and(|e| self.outer.contains(e));
                let ok = (rate != Rate::Coarse || v.kind == Kind::Effect(Rate::Coarse))
                    && (!outer || self.outer.contains(&v.name));
                if ok {
                    out.push(v.clone());
                }
            }
        }
        out
    }

    fn indent(depth: usize) -> String {
        "    ".repeat(depth)
    }

    /// One statement (maybe compound) at `depth`. `ret` is the function's return type.
    fn stmt(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize, ret: Option<Ty>) {
        self.budget -= 3;
        let pad = Self::indent(depth);
        let nested_ok = ctx.stmt_depth < MAX_STMT_DEPTH && self.budget > 0;
        match self.below(14) {
            0..=3 => self.local(ctx, out, depth),
            4..=6 => self.assign(ctx, out, depth),
            7 => self.step(ctx, out, depth),
            8 | 9 if nested_ok => self.if_stmt(ctx, out, depth, ret),
            10 | 11 if nested_ok => self.for_stmt(ctx, out, depth, ret),
            12 if nested_ok => {
                self.feat("block statement");
                let _ = writeln!(out, "{pad}{{");
                ctx.scopes.push(vec![]);
                ctx.stmt_depth += 1;
                let n = 1 + self.below(2);
                for _ in 0..n {
                    self.stmt(ctx, out, depth + 1, ret);
                }
                ctx.stmt_depth -= 1;
                ctx.scopes.pop();
                let _ = writeln!(out, "{pad}}}");
            }
            13 => self.jump(ctx, out, depth, ret),
            _ => self.local(ctx, out, depth),
        }
    }

    fn jump(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize, ret: Option<Ty>) {
        let pad = Self::indent(depth);
        // Only in a loop that may exit early, and only under an `if`.
        if ctx.loops.last() == Some(&true) {
            let c = self.expr(ctx, BOOL, 1, false);
            let what = self.pick(&["break", "continue"]);
            self.feat(if what == "break" { "break" } else { "continue" });
            let _ = writeln!(out, "{pad}if ({}) {what};", c.text);
        } else if let (Some(ret), Body::Function) = (ret, ctx.body) {
            self.feat("early return");
            let c = self.expr(ctx, BOOL, 1, false);
            let v = self.expr(ctx, ret, 1, false);
            let _ = writeln!(out, "{pad}if ({})\n{pad}    return {};", c.text, v.text);
        } else if ctx.body == Body::Effect(Rate::Coarse) {
            self.feat("refine");
            let c = self.expr(ctx, BOOL, 1, false);
            let _ = writeln!(out, "{pad}if ({}) refine;", c.text);
        } else {
            self.local(ctx, out, depth);
        }
    }

    fn local(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize) {
        let pad = Self::indent(depth);
        let ty = self.value_type();
        // Now and then a local shadows a constant or a function, which WGSL
        // would then hide: the compiler renames the local (`_l`). Not one a
        // local of this body already has (that would be E0101 in one scope).
        let mut shadowed: Vec<String> = self
            .globals
            .iter()
            .filter(|v| v.kind == Kind::Const)
            .map(|v| v.name.clone())
            .chain(self.functions.iter().map(|f| f.name.clone()))
            .filter(|n| !ctx.scopes.iter().flatten().any(|v| &v.name == n))
            .collect();
        shadowed.sort();
        let name = if !shadowed.is_empty() && self.chance(1, 8) {
            self.feat("local shadowing a constant or function");
            self.pick(&shadowed)
        } else {
            self.fresh()
        };
        self.feat("local");
        if self.chance(1, 5) {
            self.feat("local without initialiser");
            let _ = writeln!(out, "{pad}{} {name};", ty.name());
            ctx.scopes.last_mut().unwrap().push(Var {
                name,
                ty,
                kind: Kind::Local { mutable: true, deriv_ok: false, konst: false },
            });
            return;
        }
        let mutable = self.chance(1, 2);
        // Often a plain constant: such locals serve as run-time divisors,
        // shift amounts and indices (`konst_local`).
        let value = if self.chance(1, 4) { self.literal(ty) } else { self.expr(ctx, ty, 0, false) };
        let deriv_ok = !mutable && value.dsafe && matches!(ctx.body, Body::Effect(_));
        let _ = writeln!(out, "{pad}{} {name} = {};", ty.name(), value.text);
        ctx.scopes.last_mut().unwrap().push(Var {
            name,
            ty,
            kind: Kind::Local { mutable, deriv_ok, konst: value.konst },
        });
    }

    /// Assignable variables: mutable locals, parameters, the effect's own name.
    fn targets(&self, ctx: &Ctx) -> Vec<Var> {
        self.visible(ctx)
            .into_iter()
            .filter(|v| {
                matches!(v.kind, Kind::Local { mutable: true, .. } | Kind::Param | Kind::Own { mutable: true, .. })
                    && v.ty.is_value()
            })
            .collect()
    }

    fn assign(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize) {
        let pad = Self::indent(depth);
        let targets = self.targets(ctx);
        if targets.is_empty() {
            return self.local(ctx, out, depth);
        }
        let t = self.pick(&targets);
        if matches!(t.kind, Kind::Param) {
            self.feat("parameter assignment");
        }
        // The target: whole, one component, one column, or one element of a column.
        let (target, ty) = match (t.ty, self.below(3)) {
            (V(s, n), 0) => {
                self.feat("component assignment");
                let c = self.component(n);
                (format!("{}.{c}", t.name), Ty::S(s))
            }
            (V(s, n), 1) => {
                self.feat("indexed assignment");
                let i = self.index(ctx, n);
                (format!("{}[{}]", t.name, i.text), Ty::S(s))
            }
            (M(n), 0) => {
                self.feat("column assignment");
                let i = self.index(ctx, n);
                (format!("{}[{}]", t.name, i.text), V(S::F, n))
            }
            (M(n), 1) => {
                let i = self.index(ctx, n);
                let c = self.component(n);
                (format!("{}[{}].{c}", t.name, i.text), FLOAT)
            }
            (ty, _) => (t.name.clone(), ty),
        };
        let numeric = ty.scalar().is_some_and(|s| s != S::B);
        let op = if numeric && self.chance(1, 2) {
            match ty {
                M(_) => self.pick(&["+=", "-=", "*="]),
                _ if ty.scalar() == Some(S::F) => self.pick(&["+=", "-=", "*=", "/="]),
                _ => self.pick(&["+=", "-=", "*="]),
            }
        } else {
            "="
        };
        if op != "=" {
            self.feat("compound assignment");
        }
        let value = if op == "*=" && matches!(ty, M(_)) {
            let t = if self.chance(1, 2) { ty } else { FLOAT };
            self.expr(ctx, t, 0, false)
        } else if op != "=" && matches!(ty, V(..)) && self.chance(1, 3) {
            self.feat("compound assignment with scalar");
            self.expr(ctx, Ty::S(ty.scalar().unwrap()), 0, false)
        } else {
            self.expr(ctx, ty, 0, false)
        };
        let _ = writeln!(out, "{pad}{target} {op} {};", value.text);
    }

    fn step(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize) {
        let pad = Self::indent(depth);
        let targets: Vec<Var> =
            self.targets(ctx).into_iter().filter(|v| matches!(v.ty, Ty::S(S::F | S::I | S::U))).collect();
        if targets.is_empty() {
            return self.assign(ctx, out, depth);
        }
        let t = self.pick(&targets);
        self.feat("++/--");
        let s = self.pick(&["{}++", "{}--", "++{}", "--{}"]).replace("{}", &t.name);
        let _ = writeln!(out, "{pad}{s};");
    }

    fn if_stmt(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize, ret: Option<Ty>) {
        let pad = Self::indent(depth);
        let c = self.expr(ctx, BOOL, 0, false);
        self.feat("if");
        let _ = writeln!(out, "{pad}if ({}) {{", c.text);
        let varying = ctx.varying;
        ctx.varying = true;
        ctx.stmt_depth += 1;
        ctx.scopes.push(vec![]);
        let n = 1 + self.below(2);
        for _ in 0..n {
            self.stmt(ctx, out, depth + 1, ret);
        }
        ctx.scopes.pop();
        if self.chance(1, 2) {
            self.feat("else");
            let _ = writeln!(out, "{pad}}} else {{");
            ctx.scopes.push(vec![]);
            let n = 1 + self.below(2);
            for _ in 0..n {
                self.stmt(ctx, out, depth + 1, ret);
            }
            ctx.scopes.pop();
        }
        ctx.stmt_depth -= 1;
        ctx.varying = varying;
        let _ = writeln!(out, "{pad}}}");
    }

    fn for_stmt(&mut self, ctx: &mut Ctx, out: &mut String, depth: usize, ret: Option<Ty>) {
        let pad = Self::indent(depth);
        let counter = self.fresh();
        let may_exit = self.chance(1, 2);
        let (ty, header) = match self.below(6) {
            0 => {
                let (a, b) = (self.below(3), 1 + self.below(4));
                (INT, format!("int {counter} = {a}; {counter} < {}; {counter}++", a + b))
            }
            1 => {
                let (a, b) = (self.below(3), self.below(4));
                (INT, format!("int {counter} = {}; {counter} >= {a}; --{counter}", a + b))
            }
            2 => {
                let b = 1 + self.below(4);
                (UINT, format!("uint {counter} = 0u; {counter} < {b}u; {counter} += 1u"))
            }
            3 => {
                let b = 2 * (1 + self.below(3));
                (INT, format!("int {counter} = 0; {counter} != {b}; {counter} += 2"))
            }
            4 => {
                let b = 1 + self.below(4);
                (UINT, format!("uint {counter} = {b}u; {counter} > 0u; {counter}--"))
            }
            _ => {
                let b = 1 + self.below(5);
                (INT, format!("int {counter} = -2; {b} > {counter}; {counter} += 1"))
            }
        };
        self.feat("for");
        let _ = writeln!(out, "{pad}for ({header}) {{");
        let deriv_ok = !ctx.varying && !may_exit && !ctx.loops.contains(&true);
        let varying = ctx.varying;
        ctx.varying = ctx.varying || may_exit;
        ctx.loops.push(may_exit);
        ctx.stmt_depth += 1;
        ctx.scopes.push(vec![Var { name: counter, ty, kind: Kind::Counter { deriv_ok } }]);
        let n = 1 + self.below(3);
        for _ in 0..n {
            self.stmt(ctx, out, depth + 1, ret);
        }
        if may_exit {
            self.jump(ctx, out, depth + 1, ret);
        }
        ctx.scopes.pop();
        ctx.stmt_depth -= 1;
        ctx.loops.pop();
        ctx.varying = varying;
        let _ = writeln!(out, "{pad}}}");
    }

    // ----- expressions --------------------------------------------------------

    fn component(&mut self, n: u8) -> char {
        let sets = ["xyzw", "rgba"];
        let set = sets[self.below(2)];
        set.as_bytes()[self.below(n as usize)] as char
    }

    /// A swizzle of `len` letters drawn from the first `n` components.
    fn swizzle(&mut self, n: u8, len: u8) -> String {
        let set = if self.chance(1, 2) { "xyzw" } else { "rgba" };
        (0..len).map(|_| set.as_bytes()[self.below(n as usize)] as char).collect()
    }

    /// An index below `n`: a constant in range (a literal or an operation on
    /// literals), or a non-constant `int`/`uint`, which may be a local
    /// holding a constant of any value (a run-time index, out of range or not).
    fn index(&mut self, ctx: &Ctx, n: u8) -> E {
        match self.below(6) {
            0 | 1 => E::lit(format!("{}", self.below(n as usize))),
            2 => E::lit(format!("{}u", self.below(n as usize))),
            3 => {
                self.feat("constant index expression");
                let k = self.below(10);
                E { text: format!("({k} % {n})"), konst: true, dsafe: true, literal: false }
            }
            4 if !ctx.deriv => match self.konst_local(ctx, &[INT, UINT]) {
                Some(e) => {
                    self.feat("local holding a constant as index");
                    e
                }
                None => E::lit(format!("{}", self.below(n as usize))),
            },
            _ => {
                self.feat("dynamic index");
                let ty = if self.chance(1, 2) { INT } else { UINT };
                self.nonconst(ctx, ty, MAX_EXPR_DEPTH)
            }
        }
    }

    /// Variables usable as a leaf here.
    fn leaves(&self, ctx: &Ctx) -> Vec<Var> {
        self.visible(ctx)
            .into_iter()
            .filter(|v| !ctx.deriv || (dsafe(v) && !self.differentiating.contains(&v.name)))
            .collect()
    }

    fn var_expr(&mut self, v: &Var) -> E {
        if let Kind::Effect(_) = v.kind {
            self.feat("effect read");
        }
        let konst = match v.kind {
            Kind::Const => true,
            Kind::Local { konst, .. } => konst,
            _ => false,
        };
        E { text: v.name.clone(), konst, dsafe: dsafe(v), literal: false }
    }

    /// A non-constant expression of type `ty`: always possible, from `uv`
    /// (effects) or `gain` (everywhere).
    fn nonconst(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> E {
        let leaves = self.leaves(ctx);
        let direct: Vec<Var> = leaves
            .iter()
            .filter(|v| v.ty == ty && !matches!(v.kind, Kind::Const | Kind::Local { konst: true, .. }))
            .cloned()
            .collect();
        if !direct.is_empty() && self.chance(2, 3) {
            let v = self.pick(&direct);
            return self.var_expr(&v);
        }
        if depth < MAX_EXPR_DEPTH && self.chance(1, 2) {
            let e = self.expr(ctx, ty, depth + 1, true);
            if !e.konst {
                return e;
            }
        }
        // From `gain` (a uniform float), visible everywhere unless shadowed, which never happens.
        let f = if matches!(ctx.body, Body::Effect(_)) && self.chance(1, 2) { "uv.y" } else { "gain" };
        let f = E { text: f.into(), konst: false, dsafe: true, literal: false };
        let text = match ty {
            Ty::S(S::F) => f.text.clone(),
            Ty::S(S::I) => format!("int({})", f.text),
            Ty::S(S::U) => format!("uint({})", f.text),
            Ty::S(S::B) => format!("({} > 0.5)", f.text),
            V(S::F, n) => format!("float{n}({})", f.text),
            V(S::B, n) => format!("bool{n}({} < 0.5)", f.text),
            V(s, n) => format!("{}({}({}))", V(s, n).name(), Ty::S(s).name(), f.text),
            M(n) => {
                let mut xs = vec![f.text.clone()];
                xs.extend((1..n * n).map(|i| format!("{}.0", i % 3)));
                format!("float{n}x{n}({})", xs.join(", "))
            }
            _ => unreachable!(),
        };
        E { text, konst: false, dsafe: true, literal: false }
    }

    /// An expression of type `ty`. `nc`: it must not be constant.
    fn expr(&mut self, ctx: &Ctx, ty: Ty, depth: u32, nc: bool) -> E {
        self.budget -= 1;
        if depth >= MAX_EXPR_DEPTH || self.budget <= 0 || self.chance(1, 3 + (MAX_EXPR_DEPTH - depth) as usize) {
            return self.leaf(ctx, ty, nc);
        }
        let e = match ty {
            Ty::S(S::F) => self.float_expr(ctx, depth),
            Ty::S(S::I) | Ty::S(S::U) => self.int_expr(ctx, ty, depth),
            Ty::S(S::B) => self.bool_expr(ctx, depth),
            V(S::F, n) => self.fvec_expr(ctx, n, depth),
            V(S::I | S::U, _) => self.int_expr(ctx, ty, depth),
            V(S::B, n) => self.bvec_expr(ctx, n, depth),
            M(n) => self.mat_expr(ctx, n, depth),
            _ => unreachable!(),
        };
        let e = match e {
            Some(e) => e,
            None => self.leaf(ctx, ty, nc),
        };
        if nc && e.konst { self.nonconst(ctx, ty, depth) } else { e }
    }

    fn leaf(&mut self, ctx: &Ctx, ty: Ty, nc: bool) -> E {
        let leaves = self.leaves(ctx);
        let exact: Vec<Var> = leaves.iter().filter(|v| v.ty == ty).cloned().collect();
        match self.below(5) {
            0 | 1 if !exact.is_empty() => {
                let v = self.pick(&exact);
                let e = self.var_expr(&v);
                if nc && e.konst { self.nonconst(ctx, ty, MAX_EXPR_DEPTH) } else { e }
            }
            2 => {
                // A swizzle or index of a vector of the same element type.
                let n = ty.width();
                let s = ty.scalar();
                let bases: Vec<Var> = leaves
                    .iter()
                    .filter(|v| matches!(v.ty, V(..)) && v.ty.scalar() == s && !matches!(ty, M(_)))
                    .cloned()
                    .collect();
                if !bases.is_empty() {
                    let v = self.pick(&bases);
                    let e = self.var_expr(&v);
                    let mut dsafe_index = true;
                    let text = if n == 1 && self.chance(1, 3) {
                        self.feat("vector index");
                        let i = self.index(ctx, v.ty.width());
                        dsafe_index &= i.dsafe;
                        format!("{}[{}]", e.text, i.text)
                    } else {
                        self.feat("swizzle");
                        format!("{}.{}", e.text, self.swizzle(v.ty.width(), n))
                    };
                    let e = E { text, dsafe: e.dsafe && dsafe_index, ..e };
                    return if nc && e.konst { self.nonconst(ctx, ty, MAX_EXPR_DEPTH) } else { e };
                }
                self.leaf_fallback(ctx, ty, nc)
            }
            3 => {
                // A uniform array element or a matrix column.
                let arrays: Vec<(String, u32)> =
                    self.arrays.iter().filter(|a| a.ty == ty).map(|a| (a.name.clone(), a.len)).collect();
                if !arrays.is_empty() {
                    self.feat("uniform array index");
                    let (name, len) = self.pick(&arrays);
                    let local = if ctx.deriv || self.chance(1, 2) { None } else { self.konst_local(ctx, &[INT, UINT]) };
                    let i = if let Some(local) = local {
                        // Any value: an index read at run time, out of range or not.
                        self.feat("local holding a constant as index");
                        local
                    } else if self.chance(1, 2) {
                        E::lit(format!("{}", self.below(len as usize)))
                    } else {
                        self.feat("dynamic index");
                        let t = if self.chance(1, 2) { INT } else { UINT };
                        self.nonconst(ctx, t, MAX_EXPR_DEPTH)
                    };
                    return E { text: format!("{name}[{}]", i.text), konst: false, dsafe: i.dsafe, literal: false };
                }
                if let V(S::F, n) = ty {
                    let mats: Vec<Var> = leaves.iter().filter(|v| v.ty == M(n)).cloned().collect();
                    if !mats.is_empty() {
                        self.feat("matrix column");
                        let m = self.pick(&mats);
                        let e = self.var_expr(&m);
                        let i = self.below(n as usize);
                        let e = E { text: format!("{}[{i}]", e.text), ..e };
                        return if nc && e.konst { self.nonconst(ctx, ty, MAX_EXPR_DEPTH) } else { e };
                    }
                }
                self.leaf_fallback(ctx, ty, nc)
            }
            _ => self.leaf_fallback(ctx, ty, nc),
        }
    }

    fn leaf_fallback(&mut self, ctx: &Ctx, ty: Ty, nc: bool) -> E {
        if nc || self.chance(1, 3) {
            self.nonconst(ctx, ty, MAX_EXPR_DEPTH)
        } else if self.chance(1, 3) {
            self.constant_operation(ty)
        } else {
            self.literal(ty)
        }
    }

    /// An operation whose operands are all constant, which WGSL evaluates
    /// when the shader is created (and the checker folds): builtins, `%`,
    /// shifts, bitwise operators, comparisons, swizzles and indexing of
    /// constants, `?:`, all with values inside the ranges and domains WGSL
    /// allows.
    fn constant_operation(&mut self, ty: Ty) -> E {
        self.feat("constant operation");
        let text = match ty {
            FLOAT => self
                .pick(&[
                    "sin(0.5)",
                    "cos(2.0)",
                    "tan(0.25)",
                    "exp(2.0)",
                    "exp2(3.0)",
                    "log(2.5)",
                    "log2(8.0)",
                    "sqrt(2.0)",
                    "inversesqrt(4.0)",
                    "pow(2.0, 3.0)",
                    "atan2(1.0, 2.0)",
                    "atan(3.0)",
                    "tanh(0.5)",
                    "cosh(2.0)",
                    "sinh(1.0)",
                    "asin(0.5)",
                    "acos(0.25)",
                    "degrees(1.0)",
                    "radians(90.0)",
                    "fract(2.75)",
                    "round(2.5)",
                    "floor(-1.5)",
                    "ceil(1.25)",
                    "trunc(-2.5)",
                    "saturate(1.5)",
                    "sign(-3.0)",
                    "abs(-0.5)",
                    "step(0.5, 0.25)",
                    "min(1.0, 2.0)",
                    "max(1.0, 2)",
                    "clamp(0.5, 0.0, 1.0)",
                    "length(float2(3.0, 4.0))",
                    "distance(float3(1.0), float3(2.0))",
                    "dot(float2(1.0, 2.0), float2(3.0, 4.0))",
                    "(7.5 % 2.0)",
                    "(1.5 / 4.0)",
                    "float(7 % 3)",
                    "float(1 << 4)",
                    "float3(1.0, 2.0, 3.0).z",
                    "float2(0.5, 1.5)[1]",
                    "(true ? 1.0 : 2.0)",
                    "float(0xF0u >> 4u)",
                    "float(5 & 3)",
                    "float2x2(1.0, 2.0, 3.0, 4.0)[1].x",
                    "(float2x2(1.0, 2.0, 3.0, 4.0) * float2(1.0, 0.5)).y",
                ])
                .to_string(),
            INT => self
                .pick(&[
                    "(7 % 3)",
                    "(-7 % 3)",
                    "(1 << 4)",
                    "(-1 << 30)",
                    "(256 >> 2)",
                    "(2147483647 >> 30)",
                    "(12 / 5)",
                    "(5 & 3)",
                    "(5 | 8)",
                    "(5 ^ 1)",
                    "~7",
                    "abs(-3)",
                    "min(2, 9)",
                    "max(-2, 1)",
                    "clamp(5, 0, 3)",
                    "sign(-4)",
                    "dot(int2(1, 2), int2(3, 4))",
                    "int3(1, 2, 3).y",
                    "int(2.5)",
                    "int(true)",
                    "(1 < 2 ? 3 : 4)",
                    "(1i << 30u)",
                ])
                .to_string(),
            UINT => self
                .pick(&[
                    "(7u % 3u)",
                    "(1u << 31u)",
                    "(0xFFu >> 4u)",
                    "(12u / 5u)",
                    "max(1u, 5u)",
                    "min(3u, 2u)",
                    "(0xF0u | 0x0Fu)",
                    "~0u",
                    "uint(2.5)",
                    "uint3(1u, 2u, 3u).z",
                    "(4294967295u / 2u)",
                    "dot(uint2(1u, 2u), uint2(3u, 4u))",
                ])
                .to_string(),
            BOOL => self
                .pick(&[
                    "(1 < 2)",
                    "all(bool2(true, false))",
                    "any(bool3(false))",
                    "((7 % 2) == 1)",
                    "!(2.5 > 1.0)",
                    "(true && false)",
                    "((5 & 1) != 0)",
                ])
                .to_string(),
            V(S::F, n) => match self.below(5) {
                0 => format!("normalize(float{n}(1.0))"),
                1 => format!("float{n}(sin(1.0))"),
                2 => format!("abs(float{n}(-1.5))"),
                3 => format!("(float{n}(7.5) % float{n}(2.0))"),
                _ if n == 3 => "cross(float3(1.0, 0.0, 0.0), float3(0.0, 1.0, 0.0))".into(),
                _ => format!("(float{n}(1.5) * 2.0)"),
            },
            V(S::I, n) => match self.below(3) {
                0 => format!("(int{n}(7) % int{n}(3))"),
                1 => format!("(int{n}(1) << uint{n}(3u))"),
                _ => format!("abs(int{n}(-2))"),
            },
            V(S::U, n) => match self.below(2) {
                0 => format!("(uint{n}(7u) >> uint{n}(1u))"),
                _ => format!("max(uint{n}(1u), uint{n}(2u))"),
            },
            V(S::B, n) => match self.below(2) {
                0 => format!("(int{n}(1) < int{n}(2))"),
                _ => format!("!bool{n}(true)"),
            },
            M(n) => {
                let cols: Vec<String> = (0..n).map(|k| format!("float{n}({}.0)", k + 1)).collect();
                format!("(float{n}x{n}({}) * 2.0)", cols.join(", "))
            }
            _ => unreachable!("no constant operation of {ty:?}"),
        };
        E { text, konst: true, dsafe: true, literal: false }
    }

    /// Arithmetic `a op b` of type `ty`; at least one side non-constant
    /// (constant folding is the checker's, and naga's, business).
    fn arith(&mut self, ctx: &Ctx, ty: Ty, depth: u32, ops: &[&'static str]) -> E {
        let op = self.pick(ops);
        self.feat(match op {
            "+" | "-" => "+ -",
            "*" => "*",
            "/" => "/",
            _ => "%",
        });
        let int = matches!(ty.scalar(), Some(S::I | S::U));
        // A scalar operand broadcast against a vector.
        let (lt, rt) = match ty {
            V(s, _) if self.chance(1, 4) => {
                self.feat("scalar broadcast");
                if self.chance(1, 2) { (ty, Ty::S(s)) } else { (Ty::S(s), ty) }
            }
            _ => (ty, ty),
        };
        if int && (op == "/" || op == "%") {
            // Never a constant divisor that could be zero.
            let a = self.expr(ctx, lt, depth + 1, false);
            let divisor_local = if a.konst || self.chance(3, 4) { None } else { self.konst_local(ctx, &[rt]) };
            let b = if let Some(local) = divisor_local {
                // A local holding a constant, maybe zero: a run-time divisor
                // (WGSL's integer division by zero gives the dividend).
                self.feat("local holding a constant as divisor");
                local
            } else if self.chance(1, 3) {
                E::lit(match rt {
                    Ty::S(S::U) => "3u".to_string(),
                    Ty::S(_) => "3".to_string(),
                    V(s, n) => format!("{}({})", V(s, n).name(), if s == S::U { "3u" } else { "3" }),
                    _ => unreachable!(),
                })
            } else {
                self.nonconst_nonzero(ctx, rt, depth)
            };
            let b = if a.konst && b.konst { self.nonconst_nonzero(ctx, rt, depth) } else { b };
            return E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b]);
        }
        let a = self.expr(ctx, lt, depth + 1, false);
        let b = self.expr(ctx, rt, depth + 1, a.konst);
        E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
    }

    /// A divisor that is never a constant: `x | 1` keeps integers away from 0.
    fn nonconst_nonzero(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> E {
        let x = self.nonconst(ctx, ty, depth + 1);
        let one = match ty {
            Ty::S(S::U) => "1u".to_string(),
            Ty::S(_) => "1".to_string(),
            V(s, n) => format!("{}({})", V(s, n).name(), if s == S::U { "1u" } else { "1" }),
            _ => unreachable!(),
        };
        E { text: format!("({} | {one})", x.text), ..x }
    }

    /// A local that holds a constant (WGSL reads it at run time), of one of
    /// `types`, if one is visible.
    fn konst_local(&mut self, ctx: &Ctx, types: &[Ty]) -> Option<E> {
        let locals: Vec<Var> = self
            .leaves(ctx)
            .into_iter()
            .filter(|v| matches!(v.kind, Kind::Local { konst: true, .. }) && types.contains(&v.ty))
            .collect();
        if locals.is_empty() {
            return None;
        }
        let v = self.pick(&locals);
        let e = self.var_expr(&v);
        // Constant to the generator's bookkeeping: an operand beside it must not be.
        Some(E { konst: true, ..e })
    }

    /// A builtin call whose first argument is non-constant.
    fn call(&mut self, name: &'static str, args: Vec<E>) -> E {
        self.feat("builtin call");
        let refs: Vec<&E> = args.iter().collect();
        let texts: Vec<&str> = args.iter().map(|a| a.text.as_str()).collect();
        E::new(format!("{name}({})", texts.join(", ")), &refs)
    }

    fn float_like(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> Option<E> {
        // Shared by float and floatN.
        Some(match self.below(12) {
            0..=2 => self.arith(ctx, ty, depth, &["+", "-", "*", "/", "%"]),
            3 => {
                let f = self.pick(&[
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
                ]);
                let a = self.expr(ctx, ty, depth + 1, true);
                self.call(f, vec![a])
            }
            4 => {
                let f = self.pick(&["pow", "atan2", "min", "max", "step", "distance"]);
                if f == "distance" {
                    return None;
                }
                let a = self.expr(ctx, ty, depth + 1, true);
                let bt = if matches!(f, "min" | "max") && self.chance(1, 3) { FLOAT } else { ty };
                let b = self.expr(ctx, bt, depth + 1, false);
                if f == "step" { self.call(f, vec![b, a]) } else { self.call(f, vec![a, b]) }
            }
            5 => {
                let f = self.pick(&["clamp", "mix", "lerp", "smoothstep"]);
                let a = self.expr(ctx, ty, depth + 1, true);
                let (bt, ct) = (if self.chance(1, 3) { FLOAT } else { ty }, if self.chance(1, 3) { FLOAT } else { ty });
                let b = self.expr(ctx, bt, depth + 1, false);
                let c = self.expr(ctx, ct, depth + 1, false);
                match f {
                    "smoothstep" => self.call(f, vec![b, c, a]),
                    "clamp" => self.call(f, vec![a, b, c]),
                    _ => {
                        let b = self.expr(ctx, ty, depth + 1, false);
                        self.call(f, vec![a, b, c])
                    }
                }
            }
            6 => {
                self.feat("unary -");
                let a = self.expr(ctx, ty, depth + 1, true);
                let op = self.pick(&["-", "+"]);
                E::new(format!("{op}{}", paren(&a.text)), &[&a])
            }
            7 => self.ternary(ctx, ty, depth),
            8 => self.user_call(ctx, ty, depth)?,
            9 => self.derivative(ctx, ty, depth)?,
            10 => {
                // A conversion from another element type.
                self.feat("conversion");
                let s = self.pick(&[S::I, S::U, S::B]);
                let from = Ty::with_width(s, ty.width());
                let a = self.expr(ctx, from, depth + 1, true);
                E::new(format!("{}({})", ty.name(), a.text), &[&a])
            }
            _ => self.texture_read(ctx, ty, depth)?,
        })
    }

    fn float_expr(&mut self, ctx: &Ctx, depth: u32) -> Option<E> {
        match self.below(5) {
            0 => {
                let n = 2 + self.below(3) as u8;
                let v = V(S::F, n);
                match self.below(3) {
                    0 => {
                        let a = self.expr(ctx, v, depth + 1, true);
                        Some(self.call("length", vec![a]))
                    }
                    1 => {
                        let a = self.expr(ctx, v, depth + 1, true);
                        let b = self.expr(ctx, v, depth + 1, false);
                        let f = self.pick(&["dot", "distance"]);
                        Some(self.call(f, vec![a, b]))
                    }
                    _ => {
                        let a = self.expr(ctx, v, depth + 1, false);
                        self.feat("swizzle");
                        let c = self.swizzle(n, 1);
                        Some(E::new(format!("{}.{c}", paren_postfix(&a.text)), &[&a]))
                    }
                }
            }
            1 => {
                let n = 2 + self.below(3) as u8;
                let m = self.expr(ctx, M(n), depth + 1, true);
                self.feat("determinant");
                Some(self.call("determinant", vec![m]))
            }
            _ => self.float_like(ctx, FLOAT, depth),
        }
    }

    fn fvec_expr(&mut self, ctx: &Ctx, n: u8, depth: u32) -> Option<E> {
        let ty = V(S::F, n);
        match self.below(8) {
            0 => {
                // Constructor concatenating scalars and vectors.
                self.feat("vector constructor");
                let mut left = n;
                let mut args = vec![];
                while left > 0 {
                    let w = if left >= 2 && self.chance(1, 3) { 2 + self.below((left - 1) as usize) as u8 } else { 1 };
                    let w = w.min(left);
                    let e = if w == 1 && self.chance(1, 4) {
                        self.feat("abstract int in float constructor");
                        E::lit(self.pick(&["1", "0", "2"]))
                    } else {
                        self.expr(ctx, Ty::with_width(S::F, w), depth + 1, false)
                    };
                    args.push(e);
                    left -= w;
                }
                let refs: Vec<&E> = args.iter().collect();
                let texts: Vec<&str> = args.iter().map(|a| a.text.as_str()).collect();
                Some(E::new(format!("{}({})", ty.name(), texts.join(", ")), &refs))
            }
            1 => {
                self.feat("splat");
                let a = self.expr(ctx, FLOAT, depth + 1, false);
                Some(E::new(format!("{}({})", ty.name(), a.text), &[&a]))
            }
            2 => {
                let f = self.pick(&["normalize", "reflect", "faceforward", "refract", "cross", "mat*vec"]);
                let a = self.expr(ctx, ty, depth + 1, true);
                match f {
                    "normalize" => Some(self.call(f, vec![a])),
                    "reflect" => {
                        let b = self.expr(ctx, ty, depth + 1, false);
                        Some(self.call(f, vec![a, b]))
                    }
                    "faceforward" => {
                        let b = self.expr(ctx, ty, depth + 1, false);
                        let c = self.expr(ctx, ty, depth + 1, false);
                        Some(self.call(f, vec![a, b, c]))
                    }
                    "refract" => {
                        let b = self.expr(ctx, ty, depth + 1, false);
                        let c = self.expr(ctx, FLOAT, depth + 1, false);
                        Some(self.call(f, vec![a, b, c]))
                    }
                    "cross" if n == 3 => {
                        let b = self.expr(ctx, ty, depth + 1, false);
                        Some(self.call(f, vec![a, b]))
                    }
                    _ => {
                        self.feat("matrix * vector");
                        let m = self.expr(ctx, M(n), depth + 1, false);
                        if self.chance(1, 2) {
                            Some(E::new(format!("({} * {})", m.text, a.text), &[&m, &a]))
                        } else {
                            Some(E::new(format!("({} * {})", a.text, m.text), &[&a, &m]))
                        }
                    }
                }
            }
            3 if n < 4 => {
                // A swizzle of a wider vector expression.
                let w = n + 1 + self.below((4 - n) as usize) as u8;
                let a = self.expr(ctx, V(S::F, w), depth + 1, false);
                self.feat("swizzle");
                let sw = self.swizzle(w, n);
                Some(E::new(format!("{}.{sw}", paren_postfix(&a.text)), &[&a]))
            }
            _ => self.float_like(ctx, ty, depth),
        }
    }

    fn int_expr(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> Option<E> {
        let s = ty.scalar().unwrap();
        Some(match self.below(10) {
            0..=2 => self.arith(ctx, ty, depth, &["+", "-", "*", "/", "%"]),
            3 => {
                self.feat("bitwise");
                let op = self.pick(&["&", "|", "^"]);
                let a = self.expr(ctx, ty, depth + 1, false);
                let b = self.expr(ctx, ty, depth + 1, false);
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            4 => {
                self.feat("shift");
                let op = self.pick(&["<<", ">>"]);
                let a = self.expr(ctx, ty, depth + 1, true);
                let at = Ty::with_width(if self.chance(1, 2) { S::U } else { S::I }, ty.width());
                let local = if ctx.deriv || self.chance(3, 4) { None } else { self.konst_local(ctx, &[at]) };
                let b = if let Some(local) = local {
                    // Any value: a run-time amount, which WGSL takes modulo 32.
                    self.feat("local holding a constant as shift amount");
                    local
                } else if self.chance(1, 2) {
                    let k = self.below(32);
                    let u = if at.scalar() == Some(S::U) { "u" } else { "" };
                    let k = if self.chance(1, 3) {
                        self.feat("constant shift amount expression");
                        format!("({}{u} & {}{u})", self.below(1000), 31)
                    } else {
                        format!("{k}{u}")
                    };
                    match at {
                        Ty::S(_) => E { text: k, konst: true, dsafe: true, literal: false },
                        V(s2, n) => {
                            E { text: format!("{}({k})", V(s2, n).name()), konst: true, dsafe: true, literal: false }
                        }
                        _ => unreachable!(),
                    }
                } else {
                    // A non-constant amount (WGSL takes it modulo 32).
                    self.nonconst(ctx, at, depth + 1)
                };
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            5 => {
                let a = self.expr(ctx, ty, depth + 1, true);
                if s == S::I && self.chance(1, 2) {
                    self.feat("unary -");
                    E::new(format!("-{}", paren(&a.text)), &[&a])
                } else {
                    self.feat("~");
                    E::new(format!("~{}", paren(&a.text)), &[&a])
                }
            }
            6 => {
                let f = if s == S::I {
                    self.pick(&["abs", "sign", "min", "max", "clamp"])
                } else {
                    self.pick(&["abs", "min", "max", "clamp"])
                };
                let a = self.expr(ctx, ty, depth + 1, true);
                match f {
                    "abs" | "sign" => self.call(f, vec![a]),
                    "min" | "max" => {
                        let bt = if self.chance(1, 3) { Ty::S(s) } else { ty };
                        let b = self.expr(ctx, bt, depth + 1, false);
                        self.call(f, vec![a, b])
                    }
                    _ => {
                        let b = self.expr(ctx, Ty::S(s), depth + 1, false);
                        let c = self.expr(ctx, Ty::S(s), depth + 1, false);
                        self.call(f, vec![a, b, c])
                    }
                }
            }
            7 => {
                self.feat("conversion");
                let from = Ty::with_width(self.pick(&[S::F, S::I, S::U, S::B]), ty.width());
                let a = self.expr(ctx, from, depth + 1, true);
                E::new(format!("{}({})", ty.name(), a.text), &[&a])
            }
            8 => {
                if ty == Ty::S(s) && self.chance(1, 2) {
                    let n = 2 + self.below(3) as u8;
                    let a = self.expr(ctx, V(s, n), depth + 1, true);
                    let b = self.expr(ctx, V(s, n), depth + 1, false);
                    self.feat("dot");
                    self.call("dot", vec![a, b])
                } else if ty == V(S::I, 2) && !self.texture_names(ctx).is_empty() {
                    let t = self.pick(&self.texture_names(ctx));
                    self.feat("texture_size");
                    E { text: format!("texture_size({t})"), konst: false, dsafe: true, literal: false }
                } else {
                    self.ternary(ctx, ty, depth)
                }
            }
            _ => match self.user_call(ctx, ty, depth) {
                Some(e) => e,
                None => self.ternary(ctx, ty, depth),
            },
        })
    }

    fn bool_expr(&mut self, ctx: &Ctx, depth: u32) -> Option<E> {
        Some(match self.below(6) {
            0 | 1 => {
                self.feat("comparison");
                let t = if self.chance(1, 2) { FLOAT } else { self.pick(&[INT, UINT, BOOL]) };
                let op =
                    if t == BOOL { self.pick(&["==", "!="]) } else { self.pick(&["<", "<=", ">", ">=", "==", "!="]) };
                let a = self.expr(ctx, t, depth + 1, false);
                let b = self.expr(ctx, t, depth + 1, false);
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            2 => {
                self.feat("&& ||");
                let op = self.pick(&["&&", "||", "&", "|", "^"]);
                let a = self.expr(ctx, BOOL, depth + 1, false);
                let b = self.expr(ctx, BOOL, depth + 1, false);
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            3 => {
                self.feat("!");
                let a = self.expr(ctx, BOOL, depth + 1, false);
                E::new(format!("!{}", paren(&a.text)), &[&a])
            }
            4 => {
                self.feat("any/all");
                let n = 2 + self.below(3) as u8;
                let a = self.expr(ctx, V(S::B, n), depth + 1, true);
                let f = self.pick(&["any", "all"]);
                self.call(f, vec![a])
            }
            _ => {
                self.feat("conversion");
                let s = self.pick(&[S::F, S::I, S::U]);
                let a = self.expr(ctx, Ty::S(s), depth + 1, true);
                E::new(format!("bool({})", a.text), &[&a])
            }
        })
    }

    fn bvec_expr(&mut self, ctx: &Ctx, n: u8, depth: u32) -> Option<E> {
        let ty = V(S::B, n);
        Some(match self.below(4) {
            0 | 1 => {
                self.feat("vector comparison");
                let s = self.pick(&[S::F, S::I, S::U]);
                let op = self.pick(&["<", "<=", ">", ">=", "==", "!="]);
                let a = self.expr(ctx, V(s, n), depth + 1, false);
                let b = self.expr(ctx, V(s, n), depth + 1, false);
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            2 => {
                self.feat("!");
                let a = self.expr(ctx, ty, depth + 1, false);
                E::new(format!("!{}", paren(&a.text)), &[&a])
            }
            _ => {
                let a = self.expr(ctx, BOOL, depth + 1, false);
                E::new(format!("{}({})", ty.name(), a.text), &[&a])
            }
        })
    }

    fn mat_expr(&mut self, ctx: &Ctx, n: u8, depth: u32) -> Option<E> {
        let ty = M(n);
        self.feat("matrix");
        Some(match self.below(5) {
            0 => {
                let cols: Vec<E> = (0..n).map(|_| self.expr(ctx, V(S::F, n), depth + 1, false)).collect();
                let refs: Vec<&E> = cols.iter().collect();
                let texts: Vec<&str> = cols.iter().map(|a| a.text.as_str()).collect();
                E::new(format!("{}({})", ty.name(), texts.join(", ")), &refs)
            }
            1 => {
                let op = self.pick(&["+", "-", "*"]);
                let a = self.expr(ctx, ty, depth + 1, false);
                let b = self.expr(ctx, ty, depth + 1, a.konst);
                E::new(format!("({} {op} {})", a.text, b.text), &[&a, &b])
            }
            2 => {
                let a = self.expr(ctx, ty, depth + 1, false);
                let s = self.expr(ctx, FLOAT, depth + 1, a.konst);
                if self.chance(1, 2) {
                    E::new(format!("({} * {})", a.text, s.text), &[&a, &s])
                } else {
                    E::new(format!("({} * {})", s.text, a.text), &[&s, &a])
                }
            }
            3 => {
                self.feat("?: on matrices");
                self.ternary(ctx, ty, depth)
            }
            _ => {
                let a = self.expr(ctx, ty, depth + 1, true);
                self.call("transpose", vec![a])
            }
        })
    }

    fn ternary(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> E {
        self.feat("?:");
        let a = self.expr(ctx, ty, depth + 1, false);
        let b = self.expr(ctx, ty, depth + 1, false);
        let c = self.expr(ctx, BOOL, depth + 1, a.konst && b.konst);
        E::new(format!("({} ? {} : {})", c.text, a.text, b.text), &[&c, &a, &b])
    }

    /// A call to an earlier user function returning `ty`.
    fn user_call(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> Option<E> {
        let candidates: Vec<usize> = (0..self.functions.len()).filter(|&i| self.functions[i].ret == ty).collect();
        if candidates.is_empty() {
            return None;
        }
        let i = self.pick(&candidates);
        let params = self.functions[i].params.clone();
        let name = self.functions[i].name.clone();
        let textures = self.texture_names(ctx);
        let samplers = self.sampler_names(ctx);
        // Decide before writing any argument: an argument thrown away may
        // have read an effect, which would then count as read (and stay
        // unread, W0001).
        if params.iter().any(|p| (*p == Ty::Tex && textures.is_empty()) || (*p == Ty::Smp && samplers.is_empty())) {
            return None;
        }
        let mut args = vec![];
        for p in params {
            args.push(match p {
                Ty::Tex if !textures.is_empty() => E::lit(self.pick(&textures)),
                Ty::Smp if !samplers.is_empty() => E::lit(self.pick(&samplers)),
                Ty::Tex | Ty::Smp => return None,
                _ => self.expr(ctx, p, depth + 1, false),
            });
        }
        self.feat("user function call");
        let refs: Vec<&E> = args.iter().collect();
        let texts: Vec<&str> = args.iter().map(|a| a.text.as_str()).collect();
        let mut e = E::new(format!("{name}({})", texts.join(", ")), &refs);
        e.konst = false;
        Some(e)
    }

    fn texture_names(&self, ctx: &Ctx) -> Vec<String> {
        let mut out: Vec<String> = self.visible(ctx).into_iter().filter(|v| v.ty == Ty::Tex).map(|v| v.name).collect();
        out.extend(self.textures.iter().cloned());
        out
    }

    fn sampler_names(&self, ctx: &Ctx) -> Vec<String> {
        let mut out: Vec<String> = self.visible(ctx).into_iter().filter(|v| v.ty == Ty::Smp).map(|v| v.name).collect();
        out.extend(self.samplers.iter().cloned());
        out
    }

    /// `ddx`/`ddy`/`fwidth` of a float type, in effect bodies only.
    fn derivative(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> Option<E> {
        if !matches!(ctx.body, Body::Effect(_)) || ctx.deriv {
            return None;
        }
        let f = self.pick(&["ddx", "ddy", "fwidth", "ddx_surface", "ddy_surface", "fwidth_surface"]);
        self.feat(f);
        let inner = Ctx {
            body: ctx.body,
            scopes: ctx.scopes.clone(),
            deriv: true,
            loops: ctx.loops.clone(),
            varying: ctx.varying,
            effect: ctx.effect.clone(),
            stmt_depth: ctx.stmt_depth,
        };
        let a = self.expr(&inner, ty, depth + 1, true);
        let mut e = self.call(f, vec![a]);
        e.konst = false;
        Some(e)
    }

    /// A texture read (`sample` in effects only), then a swizzle down to `ty`.
    fn texture_read(&mut self, ctx: &Ctx, ty: Ty, depth: u32) -> Option<E> {
        let textures = self.texture_names(ctx);
        let samplers = self.sampler_names(ctx);
        if textures.is_empty() {
            return None;
        }
        let t = self.pick(&textures);
        let mut in_effect = matches!(ctx.body, Body::Effect(_)) && !ctx.deriv;
        if samplers.is_empty() {
            in_effect = false;
        }
        let read = match self.below(4) {
            0 if in_effect => {
                self.feat("sample");
                let s = self.pick(&samplers);
                let inner = Ctx {
                    body: ctx.body,
                    scopes: ctx.scopes.clone(),
                    deriv: true,
                    loops: ctx.loops.clone(),
                    varying: ctx.varying,
                    effect: ctx.effect.clone(),
                    stmt_depth: ctx.stmt_depth,
                };
                let uv = self.expr(&inner, V(S::F, 2), depth + 1, true);
                E::new(format!("sample({t}, {s}, {})", uv.text), &[&uv])
            }
            1 if !samplers.is_empty() => {
                self.feat("sample_level");
                let s = self.pick(&samplers);
                let uv = self.expr(ctx, V(S::F, 2), depth + 1, false);
                let lod = self.expr(ctx, FLOAT, depth + 1, false);
                E::new(format!("sample_level({t}, {s}, {}, {})", uv.text, lod.text), &[&uv, &lod])
            }
            2 if !samplers.is_empty() => {
                self.feat("sample_grad");
                let s = self.pick(&samplers);
                let uv = self.expr(ctx, V(S::F, 2), depth + 1, false);
                let dx = self.expr(ctx, V(S::F, 2), depth + 1, false);
                let dy = self.expr(ctx, V(S::F, 2), depth + 1, false);
                E::new(format!("sample_grad({t}, {s}, {}, {}, {})", uv.text, dx.text, dy.text), &[&uv, &dx, &dy])
            }
            _ => {
                self.feat("load");
                let xy = self.expr(ctx, V(S::I, 2), depth + 1, false);
                if self.chance(1, 2) {
                    let lod = self.expr(ctx, INT, depth + 1, false);
                    E::new(format!("load({t}, {}, {})", xy.text, lod.text), &[&xy, &lod])
                } else {
                    E::new(format!("load({t}, {})", xy.text), &[&xy])
                }
            }
        };
        let sw = self.swizzle(4, ty.width());
        Some(E { text: format!("{}.{sw}", read.text), konst: false, ..read })
    }
}

/// Whether a derivative may read `v` (re-evaluate it at the neighbouring sample).
fn dsafe(v: &Var) -> bool {
    match v.kind {
        Kind::Input | Kind::Uniform | Kind::Const | Kind::Effect(_) => true,
        Kind::Local { deriv_ok, .. } | Kind::Counter { deriv_ok } | Kind::Own { deriv_ok, .. } => deriv_ok,
        Kind::Param => false,
    }
}

/// `e` as a `float`, to sum effects into the last output.
fn to_float(e: &str, ty: Ty) -> String {
    match ty {
        Ty::S(S::F) => e.into(),
        Ty::S(S::B) => format!("({e} ? 1.0 : 0.0)"),
        Ty::S(_) => format!("float({e})"),
        V(S::F, _) => format!("{e}.x"),
        V(S::B, _) => format!("({e}.y ? 1.0 : 0.0)"),
        V(_, _) => format!("float({e}.x)"),
        M(_) => format!("{e}[1].x"),
        _ => unreachable!(),
    }
}

/// The names `text` reads: its identifiers, except the components after a
/// `.` (`uv.b` does not read `b`).
fn names_in(text: &str) -> BTreeSet<&str> {
    let mut names = BTreeSet::new();
    let mut start = None;
    for (k, c) in text.char_indices().chain(std::iter::once((text.len(), ' '))) {
        let word = c.is_alphanumeric() || c == '_';
        match (start, word) {
            (None, true) => start = Some(k),
            (Some(from), false) => {
                if !text[..from].ends_with('.') {
                    names.insert(&text[from..k]);
                }
                start = None;
            }
            _ => {}
        }
    }
    names
}

fn paren(text: &str) -> String {
    format!("({text})")
}

/// `text` as the base of a postfix `.x`/`[i]`: parenthesised unless it is a name.
fn paren_postfix(text: &str) -> String {
    if text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') { text.into() } else { format!("({text})") }
}
