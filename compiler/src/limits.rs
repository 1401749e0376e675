//! Nesting limits: the checks that keep every accepted program within what
//! WGSL compilers take, and every recursive pass of this compiler within its
//! stack.
//!
//! The WGSL front ends count levels of nesting as they parse: a statement,
//! an expression and each parenthesised or argument sub-expression count
//! one level. naga (which validates every kernel, and which wgpu runs when
//! a shader is created) gives up at level 200; Tint (Dawn's, so Chrome's)
//! at level 129, and it allows 126 levels of braces in a function where the
//! WGSL specification says 127. So no part of a kernel may stand deeper
//! than [`MAX_WGSL_LEVEL`] or open more than [`MAX_BRACE_LEVEL`] braces:
//! the strictest of them (`tests/tint` checks every kernel with Tint).
//! The code generator adds levels of its own (parentheses around every
//! operator, `select(...)` for `?:`, the braces and `return` of the function
//! it writes a body into, splats), so the limits are checked here, on the
//! source, with the generator's rules, instead of failing as an internal
//! error (E9000) in naga:
//!
//! - [`nesting`] runs right after parsing, before anything else walks the
//!   tree. It measures, iteratively, the level every expression reaches in
//!   the generated WGSL (E0602) and the brace level every block opens
//!   (E0603), and caps the depth of every expression at [`MAX_EXPR_DEPTH`]
//!   nodes (E0602). When it reports anything, compilation stops there: the
//!   checks, the derivative analysis and the code generator recurse over
//!   expressions and statements, and this bound on their depth is what keeps
//!   them within any stack of 2 MiB or more.
//! - [`derivatives`] runs after the derivative analysis. A derivative
//!   operand is recomputed at the neighbouring sample in a function of its
//!   own, with the definitions of the locals it reads inlined; the levels
//!   and the size that inlining adds are only known then (E0604).
//!
//! The rules mirror `codegen::body`; each constant below says which line of
//! generated code it stands for. `tests/it/limits.rs` compiles programs
//! exactly at every limit, so a generator change that adds a level fails
//! there rather than in a user's program.

use crate::builtins::{Builtin, Rule};
use crate::check::{Checked, LocalId, Symbol, UniformKind};
use crate::deriv::{DerivInfo, DerivSite};
use crate::diagnostic::{Diagnostic, Label};
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};
use std::collections::{HashMap, HashSet};

/// The deepest level both WGSL parsers accept: Tint fails with "maximum
/// parser recursive depth reached" past level 128 (naga, with "Parser
/// recursion limit exceeded", past 199).
pub const MAX_WGSL_LEVEL: u32 = 128;

/// The most levels of braces in a function, its own braces being level 1:
/// Tint's limit ("statement nesting depth / chaining length exceeds limit of
/// 127" at level 127), one below the WGSL specification's 127.
pub const MAX_BRACE_LEVEL: u32 = 126;

/// The most parameters a function may declare: WGSL's limit, which Tint
/// enforces (naga does not). A user function is written with its own
/// parameters alone; the effects' functions pack what would exceed it.
pub const MAX_PARAMETERS: usize = 255;

/// The most nodes on any path through one expression, field accesses
/// included (which the parsers nest at no cost, up to Tint's expression
/// depth of 512). Low enough that the compiler's recursive passes stay small
/// on a 2 MiB stack, high enough that it only ever rejects chains of field
/// accesses no program needs.
pub const MAX_EXPR_DEPTH: u32 = 398;

/// The most expression nodes a derivative operand may expand to once the
/// definitions of the locals it reads are inlined: each use of a local copies
/// its whole definition, so the size can double with every local, and the
/// generated code with it. The examples and the corpus stay below 20; at
/// this size a helper is some 40 KB of WGSL in each kernel.
pub const MAX_INLINED_SIZE: u64 = 4096;

/// `const NAME: T = value;` at module scope: the value is at level 1.
const CONST_LEVEL: u32 = 1;
/// Attribute arguments, uniform defaults and array lengths are folded, not
/// written; they are held to the limit of a constant.
const FOLDED_LEVEL: u32 = CONST_LEVEL;
/// `fn f(...) { statement }`: a function's statements are at level 1.
const FUNCTION_STATEMENTS: u32 = 1;
/// An effect with a block body: `fn mrsl_eval_e(...) { var e: T; { statement } ... }`.
const EFFECT_STATEMENTS: u32 = 2;
/// An effect `= value;`: `fn mrsl_eval_e(...) { return value; }`.
const EFFECT_VALUE_LEVEL: u32 = 2;
/// A derivative operand: `fn mrsl_d<k>(...) { return operand; }`.
const OPERAND_LEVEL: u32 = 2;

/// Checks every expression and block of a freshly parsed program against the
/// limits (E0602, E0603), without recursion. An empty result guarantees that
/// no expression has more than [`MAX_EXPR_DEPTH`] nodes on a path and no
/// statement nests more than [`MAX_BRACE_LEVEL`] deep.
pub fn nesting(program: &Program) -> Vec<Diagnostic> {
    // A name that may be a `bool` uniform costs a level: the generator
    // compares the stored word with zero, `(mrsl_u.b != 0u)`. A local of the
    // same name is counted the same way (the measure may only overestimate).
    let bool_uniforms: HashSet<&str> = program
        .items
        .iter()
        .filter_map(|item| match item {
            Item::Uniform(u) if Type::from_name(&u.ty.name).and_then(|t| t.scalar()) == Some(Scalar::Bool) => {
                Some(u.name.name.as_str())
            }
            _ => None,
        })
        .collect();
    let mut walk = Nesting { bool_uniforms, roots: vec![], diagnostics: vec![] };
    for item in &program.items {
        match item {
            Item::Input(d) => walk.attributes(&d.attrs),
            Item::Uniform(d) => {
                walk.attributes(&d.attrs);
                let elements = d.elements.iter().flat_map(|e| &e.items);
                walk.roots.extend(d.array_len.iter().chain(&d.default).chain(elements).map(Root::folded));
            }
            Item::Const(d) => walk.roots.push(Root { expr: &d.value, level: CONST_LEVEL, depth: 0, operand: false }),
            Item::Function(f) => {
                if let Some(first_excess) = f.params.get(MAX_PARAMETERS) {
                    walk.diagnostics.push(too_many_parameters(f, first_excess));
                }
                walk.statements(&f.body.stmts, FUNCTION_STATEMENTS)
            }
            Item::Effect(e) => {
                walk.attributes(&e.attrs);
                match &e.body {
                    EffectBody::Expr(x) => {
                        walk.roots.push(Root { expr: x, level: EFFECT_VALUE_LEVEL, depth: 0, operand: false })
                    }
                    EffectBody::Block(b) => walk.statements(&b.stmts, EFFECT_STATEMENTS),
                }
            }
        }
        walk.expressions();
    }
    walk.diagnostics
}

/// An expression to measure: where it stands in the generated code.
struct Root<'a> {
    expr: &'a Expr,
    /// The level of its outermost node.
    level: u32,
    /// Nodes above it in the source (for a derivative operand: its call's).
    depth: u32,
    /// A derivative operand, measured in the function that recomputes it.
    operand: bool,
}

impl<'a> Root<'a> {
    fn folded(expr: &'a Expr) -> Self {
        Root { expr, level: FOLDED_LEVEL, depth: 0, operand: false }
    }
}

struct Nesting<'a> {
    bool_uniforms: HashSet<&'a str>,
    roots: Vec<Root<'a>>,
    diagnostics: Vec<Diagnostic>,
}

impl<'a> Nesting<'a> {
    fn attributes(&mut self, attrs: &'a [Attribute]) {
        self.roots.extend(attrs.iter().flat_map(|a| &a.args).map(Root::folded));
    }

    /// Walks statements whose own level is `level` (see [`EFFECT_STATEMENTS`]):
    /// their expressions become roots, the blocks they open are checked.
    fn statements(&mut self, stmts: &'a [Stmt], level: u32) {
        let mut stack: Vec<(&Stmt, u32)> = stmts.iter().rev().map(|s| (s, level)).collect();
        let expr = |roots: &mut Vec<Root<'a>>, e: &'a Expr, level: u32| {
            roots.push(Root { expr: e, level, depth: 0, operand: false })
        };
        while let Some((s, level)) = stack.pop() {
            // `if (...) {`, `for (...) {` and `{` open the next brace level;
            // the statements inside stand one level deeper.
            let inner = level + 1;
            let keyword = match &s.kind {
                StmtKind::If { .. } => Some("if"),
                StmtKind::For { .. } => Some("for"),
                StmtKind::Block(_) => Some("{"),
                _ => None,
            };
            if let Some(keyword) = keyword
                && inner > MAX_BRACE_LEVEL
            {
                self.diagnostics.push(too_many_braces(s, keyword, inner));
                continue;
            }
            // A body that is a block is written as the statement's own braces.
            let body = |stack: &mut Vec<(&'a Stmt, u32)>, b: &'a Stmt| match &b.kind {
                StmtKind::Block(block) => stack.extend(block.stmts.iter().rev().map(|s| (s, inner))),
                _ => stack.push((b, inner)),
            };
            match &s.kind {
                // `let x: T = value;`, `return value;`, `target = value;`
                StmtKind::Local { init: Some(e), .. }
                | StmtKind::Return(Some(e))
                | StmtKind::Step { target: e, .. } => expr(&mut self.roots, e, inner),
                StmtKind::Assign { target, value, .. } => {
                    expr(&mut self.roots, target, inner);
                    expr(&mut self.roots, value, inner);
                }
                StmtKind::If { cond, then, otherwise } => {
                    // `if (cond) {`: the condition is parenthesised.
                    expr(&mut self.roots, cond, inner + 1);
                    if let Some(o) = otherwise {
                        body(&mut stack, o);
                    }
                    body(&mut stack, then);
                }
                StmtKind::For { init, cond, step, body: b } => {
                    // `for (init; cond; step) {`: all three parts as if statements at this level.
                    if let Some(c) = cond {
                        expr(&mut self.roots, c, inner);
                    }
                    body(&mut stack, b);
                    stack.extend(step.iter().chain(init).map(|x| (&**x, level)));
                }
                StmtKind::Block(b) => stack.extend(b.stmts.iter().rev().map(|s| (s, inner))),
                StmtKind::Local { init: None, .. }
                | StmtKind::Return(None)
                | StmtKind::Refine
                | StmtKind::Break
                | StmtKind::Continue => {}
            }
        }
    }

    /// Measures the pending roots, and the derivative operands found in them.
    fn expressions(&mut self) {
        while let Some(root) = self.roots.pop() {
            let bool_uniforms = &self.bool_uniforms;
            let mut operands = vec![];
            let reach = reach(
                root.expr,
                root.level,
                root.depth,
                &mut |e| match &e.kind {
                    ExprKind::Name(n) if bool_uniforms.contains(n.as_str()) => 1,
                    _ => call_extra(e),
                },
                &mut |operand, depth| operands.push(Root { expr: operand, level: OPERAND_LEVEL, depth, operand: true }),
            );
            self.roots.extend(operands);
            if reach.level > MAX_WGSL_LEVEL {
                self.diagnostics.push(too_deep(&root, reach));
            } else if reach.depth > MAX_EXPR_DEPTH {
                self.diagnostics.push(too_long(&root, reach));
            }
        }
    }
}

/// How deep the code written for one expression goes.
#[derive(Debug, Clone, Copy, Default)]
struct Reach {
    /// The deepest level of the generated WGSL (see [`MAX_WGSL_LEVEL`]).
    level: u32,
    /// The most nodes on a path, counting those above the root.
    depth: u32,
}

/// The deepest level and depth the WGSL for `root` reaches when `root`
/// stands at `level`, without recursion. `extra(e)` is what a node adds
/// below itself beyond its children (a name's parentheses, a derivative
/// call's arguments). The operands of `ddx`, `ddy` and `fwidth` are written
/// in a function of their own, not here: they go to `operand` with their
/// depth instead.
fn reach<'e>(
    root: &'e Expr,
    level: u32,
    depth: u32,
    extra: &mut dyn FnMut(&'e Expr) -> u32,
    operand: &mut dyn FnMut(&'e Expr, u32),
) -> Reach {
    let mut deepest = Reach::default();
    let mut stack = vec![(root, level, depth + 1)];
    while let Some((e, level, depth)) = stack.pop() {
        deepest.level = deepest.level.max(level.saturating_add(extra(e)));
        deepest.depth = deepest.depth.max(depth);
        // A child written `cost` levels below its parent (see codegen::body).
        let mut child = |x: &'e Expr, cost: u32| stack.push((x, level.saturating_add(cost), depth + 1));
        match &e.kind {
            // `-(x)`, `!(x)`, `~(x)`: Tint counts the operator and the
            // parenthesis, two levels (naga one); `(x)` for unary `+`.
            ExprKind::Unary(UnaryOp::Pos, a) => child(a, 1),
            ExprKind::Unary(_, a) => child(a, 2),
            // `(a op b)`; a shift amount may be converted, `(a << u32(b))`.
            ExprKind::Binary(op, a, b) => {
                child(a, 1);
                child(b, if matches!(op, BinaryOp::Shl | BinaryOp::Shr) { 2 } else { 1 });
            }
            // `select(b, a, c)`
            ExprKind::Ternary(c, a, b) => {
                child(c, 1);
                child(a, 1);
                child(b, 1);
            }
            // `base.field`, `base[index]`: a postfix costs nothing, an index is an argument.
            ExprKind::Field { base, .. } => child(base, 0),
            ExprKind::Index { base, index } => {
                child(base, 0);
                child(index, 1);
            }
            ExprKind::Call { callee, args } => match Builtin::from_name(&callee.name).map(Builtin::plain_derivative) {
                // `mrsl_ddx_<k>(mrsl_pos, ...)`: the operand is in `mrsl_d<k>`.
                // Past the depth limit, which this root already breaks, a
                // chain of derivatives is not followed further.
                Some(Builtin::Ddx | Builtin::Ddy | Builtin::Fwidth) => {
                    if depth <= MAX_EXPR_DEPTH {
                        args.iter().for_each(|a| operand(a, depth));
                    }
                }
                Some(builtin) => {
                    for (k, a) in args.iter().enumerate() {
                        child(a, argument_cost(builtin, k));
                    }
                }
                None => args.iter().for_each(|a| child(a, 1)),
            },
            ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) | ExprKind::Name(_) => {}
        }
    }
    deepest
}

/// The levels below a builtin call at which its argument `k` is written.
fn argument_cost(builtin: Builtin, k: usize) -> u32 {
    match builtin.signature().rule {
        // `vec2<i32>(textureDimensions(t))`
        _ if builtin == Builtin::TextureSize => 2,
        // A scalar where the builtin wants a vector is splatted: `max(v, vec3<f32>(s))`.
        Rule::Generic { widen, .. } if widen.contains(&k) => 2,
        _ => 1,
    }
}

/// What a derivative call adds below itself, beyond its arguments.
fn call_extra(e: &Expr) -> u32 {
    let ExprKind::Call { callee, .. } = &e.kind else { return 0 };
    match Builtin::from_name(&callee.name).map(Builtin::plain_derivative) {
        // `mrsl_ddx_<k>(mrsl_pos, ...)`
        Some(Builtin::Ddx | Builtin::Ddy) => 1,
        // `(abs(mrsl_ddx_<k>(mrsl_pos, ...)) + abs(mrsl_ddy_<k>(...)))`
        Some(Builtin::Fwidth) => 3,
        // `textureSampleGrad(t, s, uv, mrsl_ddx_<k>(mrsl_pos, ...), ...)`
        Some(Builtin::Sample) => 2,
        _ => 0,
    }
}

const LEVEL_NOTE: &str = "the WGSL compilers accept at most 128 levels of nesting (Tint, Chrome's; naga, wgpu's, 199); in the generated \
     code every operator is parenthesised and every call argument, `?:` operand (written `select(...)`) and index \
     is one level deeper than its expression, and the statements around the expression count as well (see \
     docs/language.md, section 14)";

fn too_deep(root: &Root, reach: Reach) -> Diagnostic {
    let (message, label) = if root.operand {
        (
            "derivative operand nested too deeply",
            format!("recomputing this at the neighbouring sample reaches level {} of the generated WGSL", reach.level),
        )
    } else {
        ("expression nested too deeply", format!("reaches level {} of the generated WGSL", reach.level))
    };
    Diagnostic::error("E0602", message)
        .with_label(Label::primary(root.expr.span, label))
        .with_note(LEVEL_NOTE)
        .with_note("split the expression with locals, e.g. `float part = ...;`, or move part of it into a function")
}

fn too_long(root: &Root, reach: Reach) -> Diagnostic {
    Diagnostic::error("E0602", "expression nested too deeply")
        .with_label(Label::primary(
            root.expr.span,
            format!("{} operations, calls and accesses nested in one another", reach.depth),
        ))
        .with_note(format!(
            "an expression may nest at most {MAX_EXPR_DEPTH} operations, calls, indexings and field accesses"
        ))
        .with_note("split the expression with locals, e.g. `float3 part = ...;`")
}

fn too_many_parameters(f: &FunctionDecl, first_excess: &Param) -> Diagnostic {
    Diagnostic::error("E0605", "function with too many parameters")
        .with_label(Label::primary(
            first_excess.name.span,
            format!("parameter {} of `{}`", MAX_PARAMETERS + 1, f.name.name),
        ))
        .with_note(format!(
            "WGSL allows at most {MAX_PARAMETERS} parameters in a function (Tint, Chrome's compiler, refuses more); \
             `{}` declares {}",
            f.name.name,
            f.params.len()
        ))
        .with_note("pass fewer values: compute some inside the function, or split it into several")
}

fn too_many_braces(s: &Stmt, keyword: &str, level: u32) -> Diagnostic {
    let span = Span::new(s.span.start as usize, s.span.start as usize + keyword.len());
    let what = if keyword == "{" { "block".to_string() } else { format!("`{keyword}`") };
    Diagnostic::error("E0603", "blocks nested too deeply")
        .with_label(Label::primary(span, format!("this {what} opens brace level {level} of the generated WGSL")))
        .with_note(
            "WGSL compilers allow at most 126 levels of braces in a function (Tint, Chrome's; the WGSL \
             specification says 127); the generated function's own braces are level 1, an effect body is written inside a block at level 2, and each `if`, `else`, `for` and \
             `{ }` opens one more level (an `else if` nests inside its `else`)",
        )
        .with_note("combine conditions with `&&`, return early, or move the inner part into a function")
}

/// Checks what recomputing each derivative operand at the neighbouring
/// sample costs once the definitions of the locals it reads are inlined
/// (E0604): the level the generated helper reaches, and its size. Run on a
/// program without errors, whose expressions [`nesting`] has bounded; the
/// chains of definitions are followed without recursion.
pub fn derivatives(checked: &Checked, deriv: &DerivInfo) -> Vec<Diagnostic> {
    let mut diagnostics = vec![];
    for site in &deriv.sites {
        let mut inliner = Inliner { checked, deriv, site, done: HashMap::new() };
        let (reach, size) = inliner.measure(site.operand);
        if reach.level <= MAX_WGSL_LEVEL && size <= MAX_INLINED_SIZE {
            continue;
        }
        // The inlined locals the operand reads directly, to name in the report.
        let mut through: Vec<&str> = vec![];
        inliner.locals_in(site.operand, &mut |l| {
            let name = checked.locals[l.index()].name.as_str();
            if !through.contains(&name) {
                through.push(name);
            }
        });
        let shown: Vec<String> = through.iter().take(3).map(|n| format!("`{n}`")).collect();
        let locals = match through.len() {
            0 => "the locals it reads".to_string(),
            1..=3 => format!("the locals it reads ({})", shown.join(", ")),
            _ => format!("the locals it reads ({}, ...)", shown.join(", ")),
        };
        let (message, label) = if reach.level > MAX_WGSL_LEVEL {
            (
                "derivative operand nested too deeply once its locals are inlined",
                format!(
                    "recomputing this at the neighbouring sample reaches level {} of the generated WGSL",
                    reach.level
                ),
            )
        } else {
            (
                "derivative operand too large once its locals are inlined",
                format!("recomputing this at the neighbouring sample takes {size} operations"),
            )
        };
        diagnostics.push(
            Diagnostic::error("E0604", message)
                .with_label(Label::primary(site.operand.span, label))
                .with_note(format!(
                    "a derivative recomputes its operand at the neighbouring sample with the definitions of {locals} \
                     written in place, each inside parentheses, and so on for the locals those read; the generated \
                     WGSL may nest at most {MAX_WGSL_LEVEL} levels, and the operand may grow to at most \
                     {MAX_INLINED_SIZE} operations"
                ))
                .with_note(
                    "compute part of the chain in an effect of its own: the neighbour reads an effect's value \
                     instead of recomputing it",
                ),
        );
    }
    diagnostics
}

/// Measures one derivative site's operand, as `codegen::body` writes it at
/// the neighbour (`Mode::Neighbour`).
struct Inliner<'i, 'a> {
    checked: &'i Checked<'a>,
    deriv: &'i DerivInfo<'a>,
    site: &'i DerivSite<'a>,
    /// The levels below its use and the size of each inlined local measured so far.
    done: HashMap<LocalId, (u32, u64)>,
}

impl<'a> Inliner<'_, 'a> {
    /// The definition written in place of `local`, if it is inlined.
    fn inlined(&self, local: LocalId) -> Option<&'a Expr> {
        if self.site.params.contains(&local) { None } else { self.deriv.definitions.get(&local).copied() }
    }

    /// Calls `f` on every inlined local `e` reads where it is written.
    fn locals_in(&self, e: &'a Expr, f: &mut dyn FnMut(LocalId)) {
        let checked = self.checked;
        reach(
            e,
            0,
            0,
            &mut |x| {
                if let Some(Symbol::Local(l)) = checked.symbols.get(&x.id)
                    && self.inlined(*l).is_some()
                {
                    f(*l);
                }
                0
            },
            &mut |_, _| {},
        );
    }

    /// The reach of `e` written at `mrsl_d<k>`'s `return`, and its size in nodes.
    fn measure(&mut self, e: &'a Expr) -> (Reach, u64) {
        // Measure the inlined locals first, deepest first, so that each
        // measurement finds those it reads done: no recursion along a chain.
        // `seen` holds the locals walked or being walked, so each is walked once.
        let mut seen = HashSet::new();
        let mut stack: Vec<(LocalId, Vec<LocalId>)> = vec![];
        let mut pending: Vec<LocalId> = vec![];
        self.locals_in(e, &mut |l| pending.push(l));
        for first in pending {
            if self.done.contains_key(&first) || !seen.insert(first) {
                continue;
            }
            stack.push((first, self.reads(first)));
            while let Some((local, reads)) = stack.last_mut() {
                match reads.pop() {
                    Some(next) => {
                        if !self.done.contains_key(&next) && seen.insert(next) {
                            let reads = self.reads(next);
                            stack.push((next, reads));
                        }
                    }
                    None => {
                        let local = *local;
                        stack.pop();
                        let (reach, size) = self.measure_one(self.inlined(local).expect("only inlined locals"));
                        self.done.insert(local, (reach.level, size));
                    }
                }
            }
        }
        let (reach, size) = self.measure_one(e);
        (Reach { level: reach.level.saturating_add(OPERAND_LEVEL), depth: reach.depth }, size)
    }

    /// The inlined locals the definition of `local` reads.
    fn reads(&self, local: LocalId) -> Vec<LocalId> {
        let mut reads = vec![];
        if let Some(def) = self.inlined(local) {
            self.locals_in(def, &mut |l| reads.push(l));
        }
        reads
    }

    /// The reach of `e` at level 0 and its size, with the locals it reads
    /// measured already (a local still being walked, which only a cycle of
    /// definitions leads back to and the derivative analysis reports as
    /// E0503, counts as a plain name).
    fn measure_one(&self, e: &'a Expr) -> (Reach, u64) {
        let checked = self.checked;
        let mut size: u64 = 0;
        let reach = reach(
            e,
            0,
            0,
            &mut |x| {
                size = size.saturating_add(1);
                match checked.symbols.get(&x.id) {
                    // `(definition)`
                    Some(Symbol::Local(l)) => match self.done.get(l) {
                        Some(&(levels, inlined)) if self.inlined(*l).is_some() => {
                            size = size.saturating_add(inlined);
                            levels.saturating_add(1)
                        }
                        _ => 0,
                    },
                    // `mrsl_load_<input>(mrsl_pos)`, `mrsl_at_<effect>(mrsl_pos)`
                    Some(Symbol::Input(_) | Symbol::Effect(_)) => 1,
                    // `(mrsl_u.b != 0u)`
                    Some(Symbol::Uniform(u)) => {
                        let info = &checked.uniforms[u.index()];
                        u32::from(
                            matches!(info.kind, UniformKind::Value { .. }) && info.ty.scalar() == Some(Scalar::Bool),
                        )
                    }
                    _ => call_extra(x),
                }
            },
            &mut |_, _| {},
        );
        (reach, size)
    }
}
