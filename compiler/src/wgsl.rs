//! WGSL code generation: the coarse, fine and reference compute kernels.
//!
//! All three kernels share the same per-effect functions
//! (`mrsl_eval_<effect>`); they differ in what a "position" is (a coarse
//! sample or a pixel), in how an effect's value at another position is
//! obtained (`mrsl_at_<effect>`, used by derivatives), and in their entry
//! point. See docs/language.md, "What the kernels do", for the contract.

use crate::builtins::Builtin;
use crate::check::{Callee, Checked, EffectId, KeyCompare, LocalId, Symbol, UniformKind};
use crate::deriv::DerivInfo;
use crate::graph::EffectGraph;
use crate::interface::Interface;
use crate::layout;
use mrsl_abi::geometry::TILE;
use mrsl_abi::{CONTROL_FIELDS, Layout, entry};
use crate::syntax::ast::*;
use crate::syntax::{visit_expr, visit_stmt_exprs};
use crate::types::{Scalar, Type};
use std::collections::{BTreeSet, HashMap};

pub use mrsl_abi::KernelKind;

/// One level of coarse samples as the fine stage reads it.
struct Level {
    /// Suffix of the generated functions (`mrsl_resolve{suffix}`).
    suffix: &'static str,
    block: u32,
    buffer: &'static str,
    /// Refines only within the parent level's refined effects (dynamic mode).
    parent: bool,
}

impl Level {
    const DYNAMIC_OUTER: Level = Level { suffix: "", block: 4, buffer: "mrsl_interface", parent: false };
    const DYNAMIC_INNER: Level = Level { suffix: "2", block: 2, buffer: "mrsl_interface2", parent: true };
}

/// Everything the writer reads.
pub struct Inputs<'a, 'b> {
    pub checked: &'b Checked<'a>,
    pub graph: &'b EffectGraph,
    pub interface: &'b Interface,
    pub deriv: &'b DerivInfo<'a>,
    pub layout: &'b Layout,
    pub file_name: &'b str,
    pub source: &'b str,
}

/// Writes one kernel. `block` is the coarse block size (ignored by the reference kernel).
pub fn write_string(inputs: &Inputs, kind: KernelKind, block: u32) -> String {
    let mut w = Writer::new(inputs, kind, if kind == KernelKind::Reference { 1 } else { block });
    w.module();
    w.out
}


/// Renames user identifiers that collide with WGSL keywords, WGSL builtins or
/// the generated `mrsl_` namespace, so source names survive everywhere else.
fn wgsl_ident(name: &str) -> String {
    let reserved = naga::keywords::wgsl::RESERVED.contains(&name)
        || naga::keywords::wgsl::BUILTIN_IDENTIFIERS.contains(&name)
        || name.to_ascii_lowercase().starts_with("mrsl")
        || KernelKind::ALL.iter().any(|k| k.entry_points().contains(&name))
        || entry::RESERVED_PREFIXES.iter().any(|p| name.starts_with(p))
        || name.starts_with("__")
        || matches!(name, "u" | "pos");
    if reserved { format!("{name}_") } else { name.to_string() }
}

/// Names of the module-scope values each kind of symbol becomes.
fn local_name(checked: &Checked, id: LocalId) -> String {
    let info = &checked.locals[id.index()];
    // Locals may shadow module-scope user names (C allows it, WGSL would then
    // hide the function or texture), so they are suffixed when they would.
    let base = wgsl_ident(&info.name);
    let clashes = checked.functions.iter().any(|f| f.name == info.name)
        || checked.consts.iter().any(|c| c.name == info.name)
        || checked.uniforms.iter().any(|u| u.name == info.name && !matches!(u.kind, UniformKind::Value { .. }));
    if clashes { format!("{base}_l") } else { base }
}

#[derive(Clone, Copy)]
enum Mode<'s> {
    /// Inside an effect body or function: names are in scope.
    Body,
    /// Rebuilding a derivative operand at another position.
    Neighbour(&'s crate::deriv::DerivSite<'s>),
}

struct Writer<'i, 'a, 'b> {
    i: &'i Inputs<'a, 'b>,
    kind: KernelKind,
    block: u32,
    out: String,
    /// Live coarse effects, numbered for the fine kernel's refine masks.
    coarse_index: HashMap<EffectId, u32>,
}

impl<'i, 'a, 'b> Writer<'i, 'a, 'b> {
    fn new(i: &'i Inputs<'a, 'b>, kind: KernelKind, block: u32) -> Self {
        let coarse_index = i
            .graph
            .order
            .iter()
            .filter(|e| i.checked.effects[e.index()].rate == Rate::Coarse)
            .enumerate()
            .map(|(k, e)| (*e, k as u32))
            .collect();
        Writer { i, kind, block, out: String::new(), coarse_index }
    }

    fn checked(&self) -> &'b Checked<'a> {
        self.i.checked
    }

    fn line(&mut self, indent: usize, text: impl AsRef<str>) {
        for _ in 0..indent {
            self.out.push_str("    ");
        }
        self.out.push_str(text.as_ref());
        self.out.push('\n');
    }

    fn effect_name(&self, e: EffectId) -> String {
        wgsl_ident(&self.checked().effects[e.index()].name)
    }

    fn line_of(&self, span: Span) -> usize {
        self.i.source[..(span.start as usize).min(self.i.source.len())].matches('\n').count() + 1
    }

    fn module(&mut self) {
        let c = self.checked();
        let what = match self.kind {
            KernelKind::Coarse => {
                format!("coarse kernel, {b}x{b} blocks: one invocation per coarse sample", b = self.block)
            }
            KernelKind::Fine => format!("fine kernel, {b}x{b} blocks: one invocation per pixel", b = self.block),
            KernelKind::Reference => "reference kernel: every effect per pixel".to_string(),
            KernelKind::DynamicCoarse => {
                "dynamic mode, second level: one invocation per 2x2 coarse sample inside refined 4x4 blocks".to_string()
            }
            KernelKind::DynamicFine => "dynamic mode, fine kernel: 4x4, then 2x2, then per pixel".to_string(),
            KernelKind::Hierarchical => {
                "hierarchical (DACS) mode: every 4th pixel, then four levels interpolated or shaded".to_string()
            }
            KernelKind::Checkerboard => {
                "checkerboard baseline: half the 2x2 quads shaded, the rest reconstructed".to_string()
            }
        };
        self.line(
            0,
            format!("// Generated by mrslc {} from `{}`: {what}.", env!("CARGO_PKG_VERSION"), self.i.file_name),
        );
        self.line(0, "// Bindings and the interface layout are described by the layout JSON emitted alongside.");
        self.line(0, "");
        self.line(0, format!("const MRSL_BLOCK: i32 = {};", self.block));
        if self.kind != KernelKind::Reference {
            // The dynamic mode's second level carries a validity tag after each record.
            let extra = u32::from(self.kind == KernelKind::DynamicCoarse);
            self.line(0, format!("const MRSL_STRIDE: u32 = {}u;", self.i.interface.stride + extra));
        }
        self.line(0, "");
        self.bindings();
        // Constants.
        for (k, info) in c.consts.iter().enumerate() {
            let decl = c.const_decl(crate::check::ConstId(k as u32));
            let value = self.expr(&decl.value, Mode::Body);
            self.line(0, format!("const {}: {} = {};", wgsl_ident(&info.name), info.ty.wgsl(), value));
        }
        if !c.consts.is_empty() {
            self.line(0, "");
        }
        self.position_helpers();
        self.input_loaders();
        for (k, _) in c.functions.iter().enumerate() {
            self.function(crate::check::FunctionId(k as u32));
        }
        for e in self.kernel_effects() {
            self.eval_function(e);
        }
        self.derivative_helpers();
        self.neighbour_functions();
        match self.kind {
            KernelKind::Coarse | KernelKind::DynamicCoarse => self.coarse_entry(),
            KernelKind::Fine | KernelKind::DynamicFine => {
                self.fine_support();
                self.pixel_entry();
            }
            KernelKind::Reference => self.pixel_entry(),
            KernelKind::Hierarchical => self.hierarchical_entries(),
            KernelKind::Checkerboard => self.checkerboard_entries(),
        }
    }

    fn bindings(&mut self) {
        let l = self.i.layout;
        self.line(0, "struct MrslControl {");
        for f in &CONTROL_FIELDS {
            match f.comment {
                Some(comment) => self.line(1, format!("{}: {}, // {comment}", f.name, f.wgsl_type)),
                None => self.line(1, format!("{}: {},", f.name, f.wgsl_type)),
            }
        }
        self.line(0, "}");
        self.line(
            0,
            format!("@group({}) @binding({}) var<uniform> mrsl_ctl: MrslControl;", l.control.group, l.control.binding),
        );
        if let Some(u) = &l.uniforms {
            self.line(0, "");
            self.line(0, "struct MrslUniforms {");
            for f in &u.fields {
                self.line(1, format!("{}: {}, // offset {}", wgsl_ident(&f.name), f.wgsl_type, f.offset));
            }
            self.line(0, "}");
            self.line(0, format!("@group({}) @binding({}) var<uniform> mrsl_u: MrslUniforms;", u.group, u.binding));
        }
        for t in &l.textures {
            self.line(
                0,
                format!("@group({}) @binding({}) var {}: texture_2d<f32>;", t.group, t.binding, wgsl_ident(&t.name)),
            );
        }
        for s in &l.samplers {
            self.line(0, format!("@group({}) @binding({}) var {}: sampler;", s.group, s.binding, wgsl_ident(&s.name)));
        }
        self.line(0, "");
        self.line(0, "// G-buffer channels.");
        for ch in &l.channels {
            let sample = ch.format.scalar().wgsl();
            self.line(
                0,
                format!(
                    "@group({}) @binding({}) var mrsl_gb_{}: texture_2d<{sample}>; // {}",
                    ch.group, ch.binding, ch.name, ch.format
                ),
            );
        }
        self.line(0, "");
        match self.kind {
            KernelKind::Coarse => {
                self.line(0, "// Interface: per coarse sample, refine flag words then value slots (see layout).");
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read_write> mrsl_interface: array<u32>;",
                        l.interface.group, l.interface.binding
                    ),
                );
            }
            KernelKind::Fine | KernelKind::DynamicFine => {
                self.line(0, "// Interface: per coarse sample, refine flag words then value slots (see layout).");
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read> mrsl_interface: array<u32>;",
                        l.interface.group, l.interface.binding
                    ),
                );
                if self.kind == KernelKind::DynamicFine {
                    self.line(0, "// Second level (2x2) interface, each record followed by its validity tag.");
                    self.line(
                        0,
                        format!(
                            "@group({}) @binding({}) var<storage, read> mrsl_interface2: array<u32>;",
                            l.interface2.group, l.interface2.binding
                        ),
                    );
                }
            }
            KernelKind::DynamicCoarse => {
                self.line(
                    0,
                    "// The 4x4 level, read to find refined blocks; the 2x2 level, written with validity tags.",
                );
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read> mrsl_parent: array<u32>;",
                        l.interface.group, l.interface.binding
                    ),
                );
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read_write> mrsl_interface: array<u32>;",
                        l.interface2.group, l.interface2.binding
                    ),
                );
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read_write> mrsl_stats: array<atomic<u32>>;",
                        l.stats.group, l.stats.binding
                    ),
                );
            }
            KernelKind::Checkerboard => {
                self.line(
                    0,
                    "// Checkerboard mode: per pixel records of the coarse effects' values (layout `hierarchical`).",
                );
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var<storage, read_write> mrsl_values: array<u32>;",
                        l.interface.group, l.hierarchical.values_binding
                    ),
                );
            }
            KernelKind::Hierarchical => {
                let h = &l.hierarchical;
                self.line(
                    0,
                    "// Hierarchical mode: per pixel record (flags, evaluated-mask, values), work lists, queues.",
                );
                for (binding, decl) in [
                    (h.values_binding, "var<storage, read_write> mrsl_values: array<u32>;"),
                    (h.work_binding, "var<storage, read_write> mrsl_work: array<u32>;"),
                    (h.queue_binding, "var<storage, read_write> mrsl_queue: array<atomic<u32>>;"),
                ] {
                    self.line(0, format!("@group({}) @binding({binding}) {decl}", l.interface.group));
                }
                self.line(0, "// Indirect dispatch arguments, bound only for the `hier_args_*` entry points.");
                self.line(
                    0,
                    format!("@group({}) @binding(0) var<storage, read_write> mrsl_args: array<u32>;", h.args_group),
                );
            }
            KernelKind::Reference => {}
        }
        if (self.kind.is_fine() || matches!(self.kind, KernelKind::Hierarchical | KernelKind::Checkerboard))
            && !self.coarse_live().is_empty()
        {
            self.line(
                0,
                "// Statistics: element k counts the pixels that re-evaluated coarse effect k (layout `stats`).",
            );
            self.line(
                0,
                format!(
                    "@group({}) @binding({}) var<storage, read_write> mrsl_stats: array<atomic<u32>>;",
                    l.stats.group, l.stats.binding
                ),
            );
            self.line(0, format!("var<workgroup> mrsl_wg_stats: array<atomic<u32>, {}>;", self.coarse_live().len()));
            self.line(
                0,
                "// Per pixel: .x bit k = coarse effect k evaluated per pixel, .y bit k = taken from the 2x2 level.",
            );
            self.line(
                0,
                format!(
                    "@group({}) @binding({}) var mrsl_rate: texture_storage_2d<rg32uint, write>;",
                    l.rate_image.group, l.rate_image.binding
                ),
            );
        }
        if !self.kind.is_coarse() {
            for o in &l.outputs {
                self.line(
                    0,
                    format!(
                        "@group({}) @binding({}) var mrsl_out_{}: texture_storage_2d<{}, write>;",
                        o.group, o.binding, o.name, o.format
                    ),
                );
            }
        }
        self.line(0, "");
    }

    fn position_helpers(&mut self) {
        self.line(0, "// A position is a coarse-sample index in the coarse kernel and a pixel elsewhere.");
        self.line(0, "fn mrsl_grid() -> vec2<i32> {");
        self.line(1, "let size = vec2<i32>(mrsl_ctl.size);");
        if self.kind.is_coarse() {
            self.line(1, "return (size + vec2<i32>(MRSL_BLOCK - 2)) / MRSL_BLOCK + vec2<i32>(1);");
        } else {
            self.line(1, "return size;");
        }
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "fn mrsl_pixel(pos: vec2<i32>) -> vec2<i32> {");
        if self.kind.is_coarse() {
            self.line(1, "return min(pos * MRSL_BLOCK, vec2<i32>(mrsl_ctl.size) - vec2<i32>(1));");
        } else {
            self.line(1, "return pos;");
        }
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "// The two positions of pos's quad along x (xy, zw), as hardware 2x2 quads pair them;");
        self.line(0, "// at the last odd column the pair is taken to the left instead.");
        for (axis, comp) in [("x", "x"), ("y", "y")] {
            self.line(0, format!("fn mrsl_pair_{axis}(pos: vec2<i32>) -> vec4<i32> {{"));
            self.line(1, "let n = mrsl_grid();");
            self.line(1, format!("var a = pos.{comp} & ~1;"));
            self.line(1, "var b = a + 1;");
            self.line(1, format!("if (b >= n.{comp}) {{ a = max(pos.{comp} - 1, 0); b = pos.{comp}; }}"));
            if axis == "x" {
                self.line(1, "return vec4<i32>(a, pos.y, b, pos.y);");
            } else {
                self.line(1, "return vec4<i32>(pos.x, a, pos.x, b);");
            }
            self.line(0, "}");
            self.line(0, "");
        }
    }

    fn input_loaders(&mut self) {
        for input in &self.checked().inputs {
            let swizzle = match input.ty.components() {
                1 => ".x",
                2 => ".xy",
                3 => ".xyz",
                _ => "",
            };
            self.line(0, format!("fn mrsl_load_{}(pos: vec2<i32>) -> {} {{", input.name, input.ty.wgsl()));
            self.line(1, format!("return textureLoad(mrsl_gb_{}, mrsl_pixel(pos), 0){swizzle};", input.name));
            self.line(0, "}");
            self.line(0, "");
        }
    }

    fn function(&mut self, id: crate::check::FunctionId) {
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
        self.line(0, format!("// function `{}` (line {})", f.name.name, self.line_of(f.span)));
        self.line(0, format!("fn {}({}) -> {} {{", wgsl_ident(&f.name.name), params.join(", "), info.ret.wgsl()));
        for p in &info.params {
            if c.locals[p.index()].reassigned {
                let name = local_name(c, *p);
                self.line(1, format!("var {name} = {name}_in;"));
            }
        }
        for s in &f.body.stmts {
            self.stmt(s, 1);
        }
        self.line(0, "}");
        self.line(0, "");
    }

    fn deps_params(&self, e: EffectId) -> Vec<EffectId> {
        self.checked().effects[e.index()].deps.iter().map(|(d, _)| *d).collect()
    }

    fn eval_signature(&self, e: EffectId) -> String {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let mut params = vec!["mrsl_pos: vec2<i32>".to_string()];
        if info.has_refine {
            params.push("mrsl_refine: ptr<function, bool>".into());
        }
        for d in self.deps_params(e) {
            params.push(format!("{}: {}", self.effect_name(d), c.effects[d.index()].ty.wgsl()));
        }
        format!("fn mrsl_eval_{}({}) -> {}", info.name, params.join(", "), info.ty.wgsl())
    }

    /// Inputs an effect body reads directly.
    fn inputs_read(&self, decl: &EffectDecl) -> BTreeSet<usize> {
        let c = self.checked();
        let mut read = BTreeSet::new();
        let mut visit = |e: &Expr| {
            visit_expr(e, &mut |x| {
                if let Some(Symbol::Input(i)) = c.symbols.get(&x.id) {
                    read.insert(i.index());
                }
            })
        };
        match &decl.body {
            EffectBody::Expr(e) => visit(e),
            EffectBody::Block(b) => b.stmts.iter().for_each(|s| visit_stmt_exprs(s, &mut visit)),
        }
        read
    }

    fn eval_function(&mut self, e: EffectId) {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let decl = c.effect_decl(e);
        let rate = match info.rate {
            Rate::Coarse => "coarse effect",
            Rate::Fine => "fine effect",
            Rate::Out => "fine out",
        };
        self.line(0, format!("// ---- {rate} `{}` (line {}) ----", info.name, self.line_of(decl.span)));
        let sig = self.eval_signature(e);
        self.line(0, format!("{sig} {{"));
        for i in self.inputs_read(decl) {
            let name = &c.inputs[i].name;
            self.line(1, format!("let {} = mrsl_load_{name}(mrsl_pos);", wgsl_ident(name)));
        }
        match &decl.body {
            EffectBody::Expr(x) => {
                let v = self.expr(x, Mode::Body);
                self.line(1, format!("return {v};"));
            }
            EffectBody::Block(b) => {
                let result = info.result.expect("block effects have a result local");
                let name = local_name(c, result);
                self.line(1, format!("var {name}: {};", info.ty.wgsl()));
                self.line(1, "{");
                for s in &b.stmts {
                    self.stmt(s, 2);
                }
                self.line(1, "}");
                self.line(1, format!("return {name};"));
            }
        }
        self.line(0, "}");
        self.line(0, "");
    }

    fn stmt(&mut self, s: &Stmt, indent: usize) {
        let c = self.checked();
        match &s.kind {
            StmtKind::Local { init, .. } => {
                let id = c.local_decls[&s.id];
                let info = &c.locals[id.index()];
                let name = local_name(c, id);
                match init {
                    Some(v) => {
                        let keyword = if info.reassigned { "var" } else { "let" };
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
                self.body(then, indent + 1);
                if let Some(o) = otherwise {
                    self.line(indent, "} else {");
                    self.body(o, indent + 1);
                }
                self.line(indent, "}");
            }
            StmtKind::For { init, cond, step, body } => {
                let init = init.as_ref().map(|i| self.for_init(i)).unwrap_or_default();
                let cond = cond.as_ref().map(|x| self.expr(x, Mode::Body)).unwrap_or_default();
                let step = step.as_ref().map(|st| self.simple_stmt(st)).unwrap_or_default();
                self.line(indent, format!("for ({init}; {cond}; {step}) {{"));
                self.body(body, indent + 1);
                self.line(indent, "}");
            }
            StmtKind::Block(b) => {
                self.line(indent, "{");
                for s in &b.stmts {
                    self.stmt(s, indent + 1);
                }
                self.line(indent, "}");
            }
            StmtKind::Refine => self.line(indent, "*mrsl_refine = true; // refine"),
            StmtKind::Return(Some(v)) => {
                let v = self.expr(v, Mode::Body);
                self.line(indent, format!("return {v};"));
            }
            StmtKind::Return(None) => self.line(indent, "return;"),
            StmtKind::Break => self.line(indent, "break;"),
            StmtKind::Continue => self.line(indent, "continue;"),
        }
    }

    fn body(&mut self, s: &Stmt, indent: usize) {
        match &s.kind {
            StmtKind::Block(b) => b.stmts.iter().for_each(|s| self.stmt(s, indent)),
            _ => self.stmt(s, indent),
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

    fn expr(&self, e: &Expr, mode: Mode) -> String {
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
                format!("select({y}, {x}, {cond})")
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
                Mode::Neighbour(site) if !site.params.contains(l) => match self.i.deriv.definitions.get(l) {
                    Some(def) => format!("({})", self.expr(def, mode)),
                    None => local_name(c, *l),
                },
                _ => local_name(c, *l),
            },
            Some(Symbol::Input(i)) => match mode {
                Mode::Body => wgsl_ident(name),
                Mode::Neighbour(_) => format!("mrsl_load_{}(mrsl_pos)", c.inputs[i.index()].name),
            },
            Some(Symbol::Uniform(u)) => {
                let info = &c.uniforms[u.index()];
                match (&info.kind, &info.ty) {
                    (UniformKind::Value { .. }, Type::Scalar(Scalar::Bool)) => {
                        format!("(mrsl_u.{} != 0u)", wgsl_ident(name))
                    }
                    (UniformKind::Value { .. }, Type::Vector(Scalar::Bool, n)) => {
                        format!("(mrsl_u.{} != vec{n}<u32>(0u))", wgsl_ident(name))
                    }
                    (UniformKind::Value { .. }, _) => format!("mrsl_u.{}", wgsl_ident(name)),
                    _ => wgsl_ident(name),
                }
            }
            Some(Symbol::Const(_)) => wgsl_ident(name),
            Some(Symbol::Effect(id)) => match mode {
                Mode::Body => self.effect_name(*id),
                Mode::Neighbour(_) => format!("mrsl_at_{}(mrsl_pos)", c.effects[id.index()].name),
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
                let mut call_args = vec!["mrsl_pos".to_string()];
                call_args.extend(site.params.iter().map(|p| local_name(c, *p)));
                let call_args = call_args.join(", ");
                let dx = format!("mrsl_ddx_{site_index}({call_args})");
                let dy = format!("mrsl_ddy_{site_index}({call_args})");
                match builtin {
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

    // ---- Derivatives and values at other positions ------------------------------

    /// Effects this kernel computes: the coarse kernel only coarse ones.
    fn kernel_effects(&self) -> Vec<EffectId> {
        let c = self.checked();
        self.i
            .graph
            .order
            .iter()
            .copied()
            .filter(|e| !self.kind.is_coarse() || c.effects[e.index()].rate == Rate::Coarse)
            .collect()
    }

    fn live_sites(&self) -> Vec<usize> {
        let effects = self.kernel_effects();
        (0..self.i.deriv.sites.len()).filter(|&k| effects.contains(&self.i.deriv.sites[k].effect)).collect()
    }

    fn derivative_helpers(&mut self) {
        let c = self.checked();
        for k in self.live_sites() {
            let site = &self.i.deriv.sites[k];
            let ty = c.ty(site.operand).concretize();
            let mut params = vec!["mrsl_pos: vec2<i32>".to_string()];
            params.extend(
                site.params.iter().map(|p| format!("{}: {}", local_name(c, *p), c.locals[p.index()].ty.wgsl())),
            );
            let mut args = vec![];
            args.extend(site.params.iter().map(|p| local_name(c, *p)));
            let effect = &c.effects[site.effect.index()].name;
            let operand_span = site.operand.span;
            let text = &self.i.source[operand_span.range()];
            let text: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
            self.line(0, format!("// derivative operand #{k} in `{effect}`: {text}"));
            let operand = self.expr(site.operand, Mode::Neighbour(site));
            self.line(0, format!("fn mrsl_d{k}({}) -> {} {{", params.join(", "), ty.wgsl()));
            self.line(1, format!("return {operand};"));
            self.line(0, "}");
            let rest = if args.is_empty() { String::new() } else { format!(", {}", args.join(", ")) };
            for axis in ["x", "y"] {
                self.line(0, format!("fn mrsl_dd{axis}_{k}({}) -> {} {{", params.join(", "), ty.wgsl()));
                self.line(1, format!("let mrsl_q = mrsl_pair_{axis}(mrsl_pos);"));
                self.line(1, format!("return mrsl_d{k}(mrsl_q.zw{rest}) - mrsl_d{k}(mrsl_q.xy{rest});"));
                self.line(0, "}");
            }
            self.line(0, "");
        }
    }

    /// `mrsl_at_<effect>(pos)`: the effect's value at another position, as this kernel sees it.
    fn neighbour_functions(&mut self) {
        let c = self.checked();
        let mut needed: BTreeSet<EffectId> = BTreeSet::new();
        for k in self.live_sites() {
            let site = &self.i.deriv.sites[k];
            needed.extend(site.effects.iter().copied().filter(|e| self.i.graph.live[e.index()]));
        }
        for e in needed {
            let info = &c.effects[e.index()];
            self.line(
                0,
                format!(
                    "// `{}` at another position, as the {} kernel computes it there.",
                    info.name,
                    self.kind.name()
                ),
            );
            self.line(0, format!("fn mrsl_at_{}(mrsl_pos: vec2<i32>) -> {} {{", info.name, info.ty.wgsl()));
            let chain = self.i.graph.closure(e, c);
            if chain.iter().any(|x| c.effects[x.index()].rate == Rate::Coarse) {
                self.resolve_preamble(1);
            }
            self.effect_chain(&chain, 1);
            self.line(1, format!("return {};", self.effect_name(e)));
            self.line(0, "}");
            self.line(0, "");
        }
    }

    /// Computes `effects` (in dependency order) into locals named after them.
    fn effect_chain(&mut self, effects: &[EffectId], indent: usize) {
        let c = self.checked();
        for &e in effects {
            let info = &c.effects[e.index()];
            let name = self.effect_name(e);
            let mut args = vec!["mrsl_pos".to_string()];
            if info.has_refine {
                args.push(format!("&mrsl_r_{}", info.name));
            }
            args.extend(self.deps_params(e).into_iter().map(|d| self.effect_name(d)));
            let call = format!("mrsl_eval_{}({})", info.name, args.join(", "));
            let declare_flag = |w: &mut Self| {
                if info.has_refine {
                    w.line(indent + 1, format!("var mrsl_r_{} = false;", info.name));
                }
            };
            match (self.kind, info.rate) {
                (KernelKind::DynamicFine, Rate::Coarse) => {
                    let index = self.coarse_index[&e];
                    self.line(indent, format!("var {name}: {};", info.ty.wgsl()));
                    if self.i.interface.is_passed(e) {
                        self.line(indent, format!("if (!mrsl_is_refined(mrsl_b, {index}u)) {{"));
                        self.line(indent + 1, format!("{name} = mrsl_resample_{}(mrsl_b);", info.name));
                        self.line(indent, format!("}} else if (!mrsl_is_refined(mrsl_b2, {index}u)) {{"));
                        self.line(indent + 1, format!("{name} = mrsl_resample2_{}(mrsl_b2);", info.name));
                        self.line(indent, "} else {");
                    } else {
                        self.line(indent, format!("if (mrsl_is_refined(mrsl_b2, {index}u)) {{"));
                    }
                    declare_flag(self);
                    self.line(indent + 1, format!("{name} = {call};"));
                    self.line(indent, "}");
                }
                (KernelKind::Fine, Rate::Coarse) => {
                    let index = self.coarse_index[&e];
                    self.line(indent, format!("var {name}: {};", info.ty.wgsl()));
                    self.line(indent, format!("if (mrsl_is_refined(mrsl_b, {index}u)) {{"));
                    declare_flag(self);
                    self.line(indent + 1, format!("{name} = {call};"));
                    if self.i.interface.is_passed(e) {
                        self.line(indent, "} else {");
                        self.line(indent + 1, format!("{name} = mrsl_resample_{}(mrsl_b);", info.name));
                    }
                    self.line(indent, "}");
                }
                _ => {
                    if info.has_refine {
                        self.line(indent, format!("var mrsl_r_{} = false;", info.name));
                    }
                    self.line(indent, format!("let {name} = {call};"));
                }
            }
        }
    }

    /// Evaluates effect `e` into an already declared variable of its name.
    fn effect_chain_into(&mut self, e: EffectId, indent: usize) {
        let c = self.checked();
        let info = &c.effects[e.index()];
        let mut args = vec!["mrsl_pos".to_string()];
        if info.has_refine {
            self.line(indent, format!("var mrsl_r_{} = false;", info.name));
            args.push(format!("&mrsl_r_{}", info.name));
        }
        args.extend(self.deps_params(e).into_iter().map(|d| self.effect_name(d)));
        self.line(indent, format!("{} = mrsl_eval_{}({});", self.effect_name(e), info.name, args.join(", ")));
    }

    /// Declares `mrsl_b` (and in the dynamic mode `mrsl_b2`) for the pixel at `mrsl_pos`.
    fn resolve_preamble(&mut self, indent: usize) {
        match self.kind {
            KernelKind::Fine => self.line(indent, "let mrsl_b = mrsl_resolve(mrsl_pos);"),
            KernelKind::DynamicFine => {
                self.line(indent, "let mrsl_b = mrsl_resolve(mrsl_pos);");
                self.line(indent, "var mrsl_b2 = mrsl_b;");
                self.line(indent, "if (mrsl_any_refined(mrsl_b)) { mrsl_b2 = mrsl_resolve2(mrsl_pos, mrsl_b); }");
            }
            _ => {}
        }
    }

    // ---- Coarse kernel ----------------------------------------------------------

    /// Dynamic mode: whether any 4x4 block holding a pixel of the 2x2 blocks
    /// around the sample at pixel `p` was refined (flags, key disagreement, force).
    fn parent_refined(&mut self) {
        let c = self.checked();
        let iface = self.i.interface;
        self.line(0, "fn mrsl_parent_refined(p: vec2<i32>) -> bool {");
        self.line(1, "let size = vec2<i32>(mrsl_ctl.size);");
        self.line(1, "let n = (size + vec2<i32>(2)) / 4 + vec2<i32>(1);");
        self.line(1, "var refined = mrsl_ctl.force_refine != 0u;");
        self.line(1, "for (var k = 0; k < 4; k++) {");
        self.line(2, "let q = clamp(p + vec2<i32>(select(-2, 1, (k & 1) != 0), select(-2, 1, (k & 2) != 0)), vec2<i32>(0), size - vec2<i32>(1));");
        self.line(2, "let i0 = q / 4;");
        self.line(2, "let i1 = min(i0 + vec2<i32>(1), n - vec2<i32>(1));");
        self.line(2, "let corners = array<vec2<i32>, 4>(i0, vec2<i32>(i1.x, i0.y), vec2<i32>(i0.x, i1.y), i1);");
        self.line(2, "for (var j = 0; j < 4; j++) {");
        self.line(3, "let s = u32(corners[j].y * n.x + corners[j].x);");
        for w in 0..iface.flag_words {
            self.line(3, format!("refined = refined || mrsl_parent[s * {}u + {w}u] != 0u;", iface.stride));
        }
        self.line(2, "}");
        for (i, input) in c.inputs.iter().enumerate() {
            let Some(key) = input.key else { continue };
            let _ = i;
            let name = &input.name;
            let differs = |a: &str, b: &str| match key {
                KeyCompare::Exact if input.ty.components() == 1 => format!("({a} != {b})"),
                KeyCompare::Exact => format!("any({a} != {b})"),
                KeyCompare::Threshold { threshold } => format!("(distance({a}, {b}) > {})", float_literal(threshold)),
            };
            self.line(2, format!("let k00_{name} = mrsl_load_{name}(min(i0 * 4, size - vec2<i32>(1)));"));
            self.line(
                2,
                format!("let k10_{name} = mrsl_load_{name}(min(vec2<i32>(i1.x, i0.y) * 4, size - vec2<i32>(1)));"),
            );
            self.line(
                2,
                format!("let k01_{name} = mrsl_load_{name}(min(vec2<i32>(i0.x, i1.y) * 4, size - vec2<i32>(1)));"),
            );
            self.line(2, format!("let k11_{name} = mrsl_load_{name}(min(i1 * 4, size - vec2<i32>(1)));"));
            self.line(
                2,
                format!(
                    "refined = refined || {} || {} || {};",
                    differs(&format!("k00_{name}"), &format!("k10_{name}")),
                    differs(&format!("k00_{name}"), &format!("k01_{name}")),
                    differs(&format!("k00_{name}"), &format!("k11_{name}"))
                ),
            );
        }
        self.line(1, "}");
        self.line(1, "return refined;");
        self.line(0, "}");
        self.line(0, "");
    }

    fn coarse_entry(&mut self) {
        if self.kind == KernelKind::DynamicCoarse {
            self.parent_refined();
        }
        let c = self.checked();
        let iface = self.i.interface;
        let [wx, wy, wz] = self.kind.workgroup_size();
        self.line(0, format!("@compute @workgroup_size({wx}, {wy}, {wz})"));
        self.line(0, format!("fn {}(@builtin(global_invocation_id) mrsl_gid: vec3<u32>) {{", self.kind.main_entry_point()));
        self.line(1, "let mrsl_n = mrsl_grid();");
        self.line(1, "if (mrsl_gid.x >= u32(mrsl_n.x) || mrsl_gid.y >= u32(mrsl_n.y)) { return; }");
        self.line(1, "let mrsl_pos = vec2<i32>(mrsl_gid.xy);");
        self.line(1, "let mrsl_rec = (mrsl_gid.y * u32(mrsl_n.x) + mrsl_gid.x) * MRSL_STRIDE;");
        if self.kind == KernelKind::DynamicCoarse {
            self.line(1, "// Shade this 2x2 sample only where a 4x4 block around it was refined; the fine");
            self.line(1, "// kernel treats an untagged (skipped) corner as a reason to shade per pixel.");
            self.line(1, "if (!mrsl_parent_refined(mrsl_pixel(mrsl_pos))) { return; }");
            self.line(1, format!("atomicAdd(&mrsl_stats[{}], 1u);", self.coarse_live().len()));
            self.line(1, "mrsl_interface[mrsl_rec + MRSL_STRIDE - 1u] = mrsl_ctl.frame + 1u;");
        }
        let coarse: Vec<EffectId> =
            self.i.graph.order.iter().copied().filter(|e| c.effects[e.index()].rate == Rate::Coarse).collect();
        for &e in &coarse {
            self.line(1, format!("// coarse effect `{}`", c.effects[e.index()].name));
            self.effect_chain(&[e], 1);
        }
        if iface.flag_words > 0 {
            self.line(1, "// Refine flags (all set when the runtime forces refinement).");
            self.line(1, "let mrsl_force = mrsl_ctl.force_refine != 0u;");
            for w in 0..iface.flag_words {
                self.line(1, format!("var mrsl_flags{w} = 0u;"));
            }
            for &e in &coarse {
                if let Some(bit) = iface.refine_bit[e.index()] {
                    let name = &c.effects[e.index()].name;
                    self.line(
                        1,
                        format!(
                            "if (mrsl_r_{name} || mrsl_force) {{ mrsl_flags{} |= {}u; }}",
                            bit / 32,
                            1u32 << (bit % 32)
                        ),
                    );
                }
            }
            for w in 0..iface.flag_words {
                self.line(1, format!("mrsl_interface[mrsl_rec + {w}u] = mrsl_flags{w};"));
            }
        }
        for (k, slot) in iface.slots.iter().enumerate() {
            let names: Vec<&str> = slot.effects.iter().map(|e| c.effects[e.index()].name.as_str()).collect();
            self.line(
                1,
                format!("// slot {k}: words {}..{} ({})", slot.offset, slot.offset + slot.size, names.join(", ")),
            );
            for &e in &slot.effects {
                let words = pack_words(&self.effect_name(e), &c.effects[e.index()].ty);
                let writes: Vec<String> = words
                    .iter()
                    .enumerate()
                    .map(|(j, w)| format!("mrsl_interface[mrsl_rec + {}u] = {w};", slot.offset as usize + j))
                    .collect();
                if slot.effects.len() > 1 {
                    // A shared slot holds whichever effect this sample's own flags say is passed.
                    let cond = self.store_condition(e, &|bit| {
                        format!("((mrsl_flags{} & {}u) != 0u)", bit / 32, 1u32 << (bit % 32))
                    });
                    self.line(1, format!("if ({cond}) {{"));
                    for wline in writes {
                        self.line(2, wline);
                    }
                    self.line(1, "}");
                } else {
                    for wline in writes {
                        self.line(1, wline);
                    }
                }
            }
        }
        self.line(0, "}");
    }

    /// The pass condition of `e` as WGSL, over flag bits rendered by `bit`.
    fn store_condition(&self, e: EffectId, bit: &dyn Fn(u32) -> String) -> String {
        let iface = self.i.interface;
        let cond = iface.conditions[e.index()].as_ref().expect("passed effects have a condition");
        let mut any = vec![];
        if cond.fine_user {
            any.push("true".to_string());
        }
        for u in &cond.refining_users {
            any.push(bit(iface.refine_bit[u.index()].expect("refining users have a bit")));
        }
        let any = if any.is_empty() { "false".to_string() } else { any.join(" || ") };
        match iface.refine_bit[e.index()] {
            Some(b) if cond.self_refines => format!("!{} && ({any})", bit(b)),
            _ => format!("({any})"),
        }
    }

    // ---- Fine kernel ------------------------------------------------------------

    fn coarse_live(&self) -> Vec<EffectId> {
        self.i.graph.order.iter().copied().filter(|e| self.checked().effects[e.index()].rate == Rate::Coarse).collect()
    }

    fn fine_support(&mut self) {
        let coarse = self.coarse_live();
        if coarse.is_empty() {
            return;
        }
        let mask_words = (coarse.len() as u32).div_ceil(32);
        self.line(0, "// Where a pixel takes its coarse values from, and which coarse effects it re-evaluates.");
        self.line(0, "struct MrslBlock {");
        self.line(1, "corners: vec4<u32>, // coarse samples c00, c10, c01, c11");
        self.line(1, "weights: vec4<f32>, // bilinear weights of the corners");
        self.line(1, "nearest: u32,       // index of the nearest corner");
        // Separate words, not an array: llvmpipe spills dynamically indexed
        // arrays in structs to memory, which made every lookup a memory access.
        for w in 0..mask_words {
            self.line(1, format!("refined{w}: u32, // bit k: coarse effect 32 * {w} + k is evaluated per pixel"));
        }
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "fn mrsl_is_refined(b: MrslBlock, k: u32) -> bool {");
        let mut word = "b.refined0".to_string();
        for w in 1..mask_words {
            word = format!("select({word}, b.refined{w}, k >= {}u)", 32 * w);
        }
        self.line(1, format!("return (({word} >> (k % 32u)) & 1u) != 0u;"));
        self.line(0, "}");
        self.line(0, "");
        if self.kind == KernelKind::DynamicFine {
            self.line(0, "fn mrsl_any_refined(b: MrslBlock) -> bool {");
            let words: Vec<String> = (0..mask_words).map(|w| format!("b.refined{w}")).collect();
            self.line(1, format!("return ({}) != 0u;", words.join(" | ")));
            self.line(0, "}");
            self.line(0, "");
            self.fine_level(&Level::DYNAMIC_OUTER);
            self.fine_level(&Level::DYNAMIC_INNER);
        } else {
            self.fine_level(&Level { suffix: "", block: self.block, buffer: "mrsl_interface", parent: false });
        }
    }

    /// `mrsl_resolve{suffix}` and the getters and resamplers of one level of coarse samples.
    fn fine_level(&mut self, level: &Level) {
        let c = self.checked();
        let coarse = self.coarse_live();
        let iface = self.i.interface;
        let (sfx, bk, buf) = (level.suffix, level.block, level.buffer);
        // A level read by the dynamic mode's inner pass carries a validity tag
        // after the values: samples the inner coarse pass skipped are stale.
        let stride = if level.parent { iface.stride + 1 } else { iface.stride };
        let keys: Vec<(usize, KeyCompare)> =
            c.inputs.iter().enumerate().filter_map(|(i, x)| x.key.map(|k| (i, k))).collect();
        if level.parent {
            self.line(
                0,
                format!("// Second level ({bk}x{bk}) of the dynamic mode: only effects refined at the first level"),
            );
            self.line(0, "// look here; a corner the inner coarse pass did not shade (stale tag) means per-pixel.");
            self.line(0, format!("fn mrsl_resolve{sfx}(pos: vec2<i32>, parent: MrslBlock) -> MrslBlock {{"));
        } else {
            self.line(0, format!("fn mrsl_resolve{sfx}(pos: vec2<i32>) -> MrslBlock {{"));
        }
        self.line(1, "let size = vec2<i32>(mrsl_ctl.size);");
        self.line(1, format!("let n = (size + vec2<i32>({})) / {bk} + vec2<i32>(1);", bk as i32 - 2));
        self.line(1, format!("let i0 = pos / {bk};"));
        self.line(1, "let i1 = min(i0 + vec2<i32>(1), n - vec2<i32>(1));");
        self.line(1, format!("let p0 = min(i0 * {bk}, size - vec2<i32>(1));"));
        self.line(1, format!("let p1 = min(i1 * {bk}, size - vec2<i32>(1));"));
        self.line(1, "let extent = p1 - p0;");
        self.line(
            1,
            "let t = select(vec2<f32>(0.0), vec2<f32>(pos - p0) / vec2<f32>(max(extent, vec2<i32>(1))), extent > vec2<i32>(0));",
        );
        self.line(1, "var b: MrslBlock;");
        self.line(
            1,
            "b.corners = vec4<u32>(u32(i0.y * n.x + i0.x), u32(i0.y * n.x + i1.x), u32(i1.y * n.x + i0.x), u32(i1.y * n.x + i1.x));",
        );
        self.line(
            1,
            "b.weights = vec4<f32>((1.0 - t.x) * (1.0 - t.y), t.x * (1.0 - t.y), (1.0 - t.x) * t.y, t.x * t.y);",
        );
        self.line(1, "b.nearest = select(0u, 1u, t.x > 0.5) + select(0u, 2u, t.y > 0.5);");
        self.line(1, "var disc = mrsl_ctl.force_refine != 0u;");
        if level.parent {
            let tags: Vec<String> = ["x", "y", "z", "w"]
                .iter()
                .map(|corner| format!("{buf}[b.corners.{corner} * {stride}u + {}u] != mrsl_ctl.frame + 1u", stride - 1))
                .collect();
            self.line(1, format!("disc = disc || {};", tags.join(" || ")));
        }
        for (i, key) in &keys {
            let name = &c.inputs[*i].name;
            let differs = |a: &str, b: &str| match key {
                KeyCompare::Exact if c.inputs[*i].ty.components() == 1 => format!("({a} != {b})"),
                KeyCompare::Exact => format!("any({a} != {b})"),
                KeyCompare::Threshold { threshold } => format!("(distance({a}, {b}) > {})", float_literal(*threshold)),
            };
            self.line(1, format!("// discontinuity key `{name}`"));
            self.line(1, format!("let k_{name} = mrsl_load_{name}(pos);"));
            self.line(1, format!("let k00_{name} = mrsl_load_{name}(p0);"));
            self.line(1, format!("let k10_{name} = mrsl_load_{name}(vec2<i32>(p1.x, p0.y));"));
            self.line(1, format!("let k01_{name} = mrsl_load_{name}(vec2<i32>(p0.x, p1.y));"));
            self.line(1, format!("let k11_{name} = mrsl_load_{name}(p1);"));
            let mut tests = vec![];
            for corner in ["k00", "k10", "k01", "k11"] {
                tests.push(differs(&format!("k_{name}"), &format!("{corner}_{name}")));
            }
            for corner in ["k10", "k01", "k11"] {
                tests.push(differs(&format!("k00_{name}"), &format!("{corner}_{name}")));
            }
            self.line(1, format!("disc = disc || {};", tests.join(" || ")));
        }
        if iface.flag_words > 0 {
            for (ci, corner) in ["x", "y", "z", "w"].iter().enumerate() {
                for w in 0..iface.flag_words {
                    self.line(1, format!("let f{ci}_{w} = {buf}[b.corners.{corner} * {stride}u + {w}u];"));
                }
            }
        }
        self.line(1, "// Effective refinement, users before what they use: an effect is evaluated per pixel");
        self.line(1, "// when a corner flagged it, at a discontinuity, or when it is needed coarsely but a");
        self.line(1, "// corner's shared slot holds another effect (an interface miss).");
        let bit_of_corner = |ci: usize, bit: u32| format!("((f{ci}_{} & {}u) != 0u)", bit / 32, 1u32 << (bit % 32));
        for &e in coarse.iter().rev() {
            let info = &c.effects[e.index()];
            let k = self.coarse_index[&e];
            let mut terms = vec!["disc".to_string()];
            if let Some(bit) = iface.refine_bit[e.index()] {
                let words: Vec<String> = (0..4).map(|ci| format!("f{ci}_{}", bit / 32)).collect();
                terms.push(format!("((({}) & {}u) != 0u)", words.join(" | "), 1u32 << (bit % 32)));
            }
            // Needed coarsely: some live user runs per pixel here.
            let mut needed = vec![];
            for &u in &self.i.graph.users[e.index()] {
                if !self.i.graph.live[u.index()] {
                    continue;
                }
                match c.effects[u.index()].rate {
                    Rate::Coarse => needed.push(format!("mrsl_r{}", self.coarse_index[&u])),
                    _ => needed.push("true".into()),
                }
            }
            needed.sort();
            needed.dedup();
            let needed = if needed.is_empty() { "false".to_string() } else { needed.join(" || ") };
            if !iface.is_passed(e) {
                terms.push(format!("({needed})"));
            } else if iface.is_shared(e) {
                let misses: Vec<String> =
                    (0..4).map(|ci| format!("!({})", self.store_condition(e, &|bit| bit_of_corner(ci, bit)))).collect();
                terms.push(format!("(({needed}) && ({}))", misses.join(" || ")));
            }
            let value = if level.parent {
                format!("mrsl_is_refined(parent, {k}u) && ({})", terms.join(" || "))
            } else {
                terms.join(" || ")
            };
            self.line(1, format!("let mrsl_r{k} = {value}; // `{}`", info.name));
            self.line(1, format!("if (mrsl_r{k}) {{ b.refined{} |= {}u; }}", k / 32, 1u32 << (k % 32)));
        }
        self.line(1, "return b;");
        self.line(0, "}");
        self.line(0, "");
        for &e in &coarse {
            let Some(slot) = iface.slot_of[e.index()].map(|s| &iface.slots[s]) else {
                continue;
            };
            let info = &c.effects[e.index()];
            let ty = &info.ty;
            self.line(0, format!("fn mrsl_get{sfx}_{}(s: u32) -> {} {{", info.name, ty.wgsl()));
            self.line(1, format!("let base = s * {stride}u + {}u;", slot.offset));
            self.line(1, format!("return {};", unpack_words(ty, buf)));
            self.line(0, "}");
            let nearest = layout::uses_nearest(c, e);
            self.line(0, format!("fn mrsl_resample{sfx}_{}(b: MrslBlock) -> {} {{", info.name, ty.wgsl()));
            for (k, corner) in ["x", "y", "z", "w"].iter().enumerate() {
                self.line(1, format!("let v{k} = mrsl_get{sfx}_{}(b.corners.{corner});", info.name));
            }
            if nearest {
                self.line(1, "// nearest corner");
                self.line(
                    1,
                    "return select(select(v0, v1, b.nearest == 1u), select(v2, v3, b.nearest == 3u), b.nearest >= 2u);",
                );
            } else {
                self.line(1, "// bilinear");
                self.line(1, "return v0 * b.weights.x + v1 * b.weights.y + v2 * b.weights.z + v3 * b.weights.w;");
            }
            self.line(0, "}");
            self.line(0, "");
        }
    }

    /// Entry point of the fine and reference kernels.
    fn pixel_entry(&mut self) {
        let tile = TILE;
        let b = if self.kind.is_fine() { self.block } else { 2 };
        self.line(0, format!("// Pixel of a {tile}x{tile} tile for lane `li`: {b}x{b} blocks are laid out so that"));
        self.line(0, "// consecutive lanes (a SIMD group) cover whole blocks and share their refine decisions.");
        self.line(0, "fn mrsl_tile_pixel(wg: vec2<u32>, li: u32) -> vec2<i32> {");
        self.line(1, format!("let per_block = {}u;", b * b));
        self.line(1, format!("let blocks_x = {}u;", tile / b));
        self.line(1, "let blk = li / per_block;");
        self.line(1, "let within = li % per_block;");
        self.line(1, format!("let x = (blk % blocks_x) * {b}u + within % {b}u;"));
        self.line(1, format!("let y = (blk / blocks_x) * {b}u + within / {b}u;"));
        self.line(1, format!("return vec2<i32>(wg * {tile}u + vec2<u32>(x, y));"));
        self.line(0, "}");
        self.line(0, "");
        let [wx, wy, wz] = self.kind.workgroup_size();
        self.line(0, format!("@compute @workgroup_size({wx}, {wy}, {wz})"));
        self.line(
            0,
            format!(
                "fn {}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {{",
                self.kind.main_entry_point()
            ),
        );
        self.line(1, "let mrsl_pos = mrsl_tile_pixel(mrsl_wg.xy, mrsl_li);");
        let order = self.i.graph.order.clone();
        let counted = self.kind.is_fine() && !self.coarse_live().is_empty();
        if !counted {
            self.line(1, "if (any(mrsl_pos >= mrsl_grid())) { return; }");
            self.effect_chain(&order, 1);
            self.output_stores(&order, 1);
            self.line(0, "}");
            return;
        }
        // With statistics the whole workgroup must reach the barrier below,
        // so pixels outside the image skip the work instead of returning.
        let nc = self.coarse_live().len();
        self.line(1, "if (all(mrsl_pos < mrsl_grid())) {");
        self.resolve_preamble(2);
        // `mrsl_last` holds the innermost level: effects refined there are evaluated per pixel.
        if self.kind == KernelKind::DynamicFine {
            self.line(2, "let mrsl_last = mrsl_b2;");
            self.line(
                2,
                "textureStore(mrsl_rate, mrsl_pos, vec4<u32>(mrsl_b2.refined0, mrsl_b.refined0 & ~mrsl_b2.refined0, 0u, 1u));",
            );
        } else {
            self.line(2, "let mrsl_last = mrsl_b;");
            self.line(2, "textureStore(mrsl_rate, mrsl_pos, vec4<u32>(mrsl_b.refined0, 0u, 0u, 1u));");
        }
        for k in 0..nc {
            self.line(2, format!("if (mrsl_is_refined(mrsl_last, {k}u)) {{ atomicAdd(&mrsl_wg_stats[{k}], 1u); }}"));
        }
        self.effect_chain(&order, 2);
        self.output_stores(&order, 2);
        self.line(1, "}");
        self.line(1, "workgroupBarrier();");
        self.line(1, format!("for (var k = mrsl_li; k < {nc}u; k += {}u) {{", TILE * TILE));
        self.line(2, "atomicAdd(&mrsl_stats[k], atomicLoad(&mrsl_wg_stats[k]));");
        self.line(1, "}");
        self.line(0, "}");
    }

    // ---- Hierarchical (DACS) kernel ------------------------------------------------

    fn hierarchical_entries(&mut self) {
        let c = self.checked();
        let l = self.i.layout;
        let h = &l.hierarchical;
        let iface = self.i.interface;
        let coarse = self.coarse_live();
        let (fw, mw) = (h.flag_words, h.mask_words);
        self.record_helpers();
        self.line(0, "// Pixels of a lattice starting at `start` with step `step` along one axis of length `n`.");
        self.line(0, "fn mrsl_count(start: u32, step: u32, n: u32) -> u32 {");
        self.line(1, "return select(0u, (n - start - 1u) / step + 1u, n > start);");
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "// Start of each level's work list: levels 1..4 take at most their dispatch grid's size.");
        self.line(0, "fn mrsl_work_offset(level: u32) -> u32 {");
        self.line(1, "let w = mrsl_ctl.size.x;");
        self.line(1, "let h = mrsl_ctl.size.y;");
        self.line(1, "let c1 = mrsl_count(2u, 4u, w) * mrsl_count(2u, 4u, h);");
        self.line(1, "let c2 = mrsl_count(0u, 2u, w) * mrsl_count(0u, 2u, h);");
        self.line(1, "let c3 = mrsl_count(1u, 2u, w) * mrsl_count(1u, 2u, h);");
        self.line(
            1,
            "return select(select(select(0u, c1, level >= 2u), c1 + c2, level >= 3u), c1 + c2 + c3, level >= 4u);",
        );
        self.line(0, "}");
        self.line(0, "");

        // Shading a pixel: the effects its mask names are evaluated, the others read.
        self.line(0, "// Evaluates the coarse effects `mrsl_pos`'s mask names (reading the others) and stores");
        self.line(0, "// their values and refine flags.");
        self.line(0, "fn mrsl_shade(mrsl_pos: vec2<i32>) {");
        self.line(1, "let mrsl_r0 = mrsl_rec(mrsl_pos);");
        for w in 0..fw {
            self.line(1, format!("var mrsl_flags{w} = 0u;"));
        }
        self.line(1, "let mrsl_force = mrsl_ctl.force_refine != 0u;");
        for &e in &coarse {
            let info = &c.effects[e.index()];
            let k = self.coarse_index[&e];
            let name = self.effect_name(e);
            let mut args = vec!["mrsl_pos".to_string()];
            if info.has_refine {
                args.push(format!("&mrsl_r_{}", info.name));
            }
            args.extend(self.deps_params(e).into_iter().map(|d| self.effect_name(d)));
            self.line(1, format!("var {name}: {};", info.ty.wgsl()));
            self.line(1, format!("if ((mrsl_values[mrsl_r0 + {}u] & {}u) != 0u) {{", fw + k / 32, 1u32 << (k % 32)));
            if info.has_refine {
                self.line(2, format!("var mrsl_r_{} = false;", info.name));
            }
            self.line(2, format!("{name} = mrsl_eval_{}({});", info.name, args.join(", ")));
            self.line(2, format!("mrsl_hput_{}(mrsl_pos, {name});", info.name));
            if let Some(bit) = iface.refine_bit[e.index()] {
                self.line(
                    2,
                    format!(
                        "if (mrsl_r_{} || mrsl_force) {{ mrsl_flags{} |= {}u; }}",
                        info.name,
                        bit / 32,
                        1u32 << (bit % 32)
                    ),
                );
            }
            self.line(1, "} else {");
            self.line(2, format!("{name} = mrsl_hget_{}(mrsl_pos);", info.name));
            self.line(1, "}");
        }
        for w in 0..fw {
            self.line(1, format!("mrsl_values[mrsl_r0 + {w}u] = mrsl_flags{w};"));
        }
        self.line(0, "}");
        self.line(0, "");
        // Level 0.
        self.line(0, "// Level 0: every 4th pixel in both directions is shaded.");
        self.line(0, "@compute @workgroup_size(8, 8, 1)");
        self.line(0, "fn hier_level0(@builtin(global_invocation_id) gid: vec3<u32>) {");
        self.line(1, "let p = vec2<i32>(gid.xy) * 4;");
        self.line(1, "if (any(p >= vec2<i32>(mrsl_ctl.size))) { return; }");
        self.line(1, "let r = mrsl_rec(p);");
        for w in 0..mw {
            let bits = (coarse.len() as u32).saturating_sub(w * 32).min(32);
            let mask = if bits == 32 { u32::MAX } else { (1u32 << bits) - 1 };
            self.line(1, format!("mrsl_values[r + {}u] = {mask}u;", fw + w));
        }
        self.line(1, "mrsl_shade(p);");
        self.line(0, "}");
        self.line(0, "");
        // Classification shared by the levels.
        let keys: Vec<(usize, KeyCompare)> =
            c.inputs.iter().enumerate().filter_map(|(i, x)| x.key.map(|k| (i, k))).collect();
        self.line(0, "// Decides, per coarse effect, whether pixel `p` interpolates its four previous-level");
        self.line(0, "// neighbours `n` (those inside the image) or is shaded; queues it for shading if any.");
        self.line(0, "fn mrsl_classify(p: vec2<i32>, n: array<vec2<i32>, 4>, level: u32) {");
        self.line(1, "let size = vec2<i32>(mrsl_ctl.size);");
        self.line(1, "var ok: array<bool, 4>;");
        self.line(1, "var q: array<vec2<i32>, 4>;");
        self.line(1, "var total = 0.0;");
        self.line(1, "for (var k = 0; k < 4; k++) {");
        self.line(2, "ok[k] = all(n[k] >= vec2<i32>(0)) && all(n[k] < size);");
        self.line(1, "}");
        self.line(1, "// Neighbours come in opposite pairs (0, 1) and (2, 3); at a border only complete pairs");
        self.line(1, "// are used, so interpolation stays centred (exact for linear values). A pixel with no");
        self.line(1, "// complete pair is shaded.");
        self.line(1, "let pair_a = ok[0] && ok[1];");
        self.line(1, "let pair_b = ok[2] && ok[3];");
        self.line(1, "ok = array<bool, 4>(pair_a, pair_a, pair_b, pair_b);");
        self.line(1, "for (var k = 0; k < 4; k++) {");
        self.line(2, "q[k] = select(p, n[k], ok[k]);");
        self.line(2, "total += select(0.0, 1.0, ok[k]);");
        self.line(1, "}");
        self.line(1, "var disc = mrsl_ctl.force_refine != 0u || total == 0.0;");
        for (i, key) in &keys {
            let name = &c.inputs[*i].name;
            let differs = |a: &str, b: &str| match key {
                KeyCompare::Exact if c.inputs[*i].ty.components() == 1 => format!("({a} != {b})"),
                KeyCompare::Exact => format!("any({a} != {b})"),
                KeyCompare::Threshold { threshold } => format!("(distance({a}, {b}) > {})", float_literal(*threshold)),
            };
            self.line(1, format!("let k_{name} = mrsl_load_{name}(p);"));
            self.line(1, "for (var k = 0; k < 4; k++) {");
            self.line(
                2,
                format!(
                    "disc = disc || (ok[k] && {});",
                    differs(&format!("k_{name}"), &format!("mrsl_load_{name}(q[k])"))
                ),
            );
            self.line(1, "}");
        }
        self.line(1, "let r = mrsl_rec(p);");
        for w in 0..mw {
            self.line(1, format!("var mask{w} = 0u;"));
        }
        for &e in &coarse {
            let info = &c.effects[e.index()];
            let k = self.coarse_index[&e];
            let ty = info.ty.wgsl();
            self.line(1, format!("// `{}`", info.name));
            self.line(1, "{");
            for j in 0..4 {
                self.line(2, format!("let v{j} = mrsl_hget_{}(q[{j}]);", info.name));
            }
            let mut need = vec!["disc".to_string()];
            if let Some(bit) = iface.refine_bit[e.index()] {
                // The program's own predicate, as evaluated at the neighbours.
                self.line(2, "var flagged = false;");
                self.line(2, "for (var j = 0; j < 4; j++) {");
                self.line(
                    3,
                    format!(
                        "flagged = flagged || (ok[j] && (mrsl_values[mrsl_rec(q[j]) + {}u] & {}u) != 0u);",
                        bit / 32,
                        1u32 << (bit % 32)
                    ),
                );
                self.line(2, "}");
                need.push("flagged".into());
            }
            let interpolable = matches!(info.ty, Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _));
            if interpolable {
                let zero = format!("{ty}(0.0)");
                let w = |j: usize| format!("select({zero}, v{j}, ok[{j}])");
                self.line(2, format!("let mean = ({} + {} + {} + {}) / total;", w(0), w(1), w(2), w(3)));
                let dev = |j: usize| format!("select({zero}, (v{j} - mean) * (v{j} - mean), ok[{j}])");
                self.line(2, format!("let variance = ({} + {} + {} + {}) / total;", dev(0), dev(1), dev(2), dev(3)));
                let spread = match info.ty.components() {
                    1 => "variance".to_string(),
                    2 => "max(variance.x, variance.y)".to_string(),
                    3 => "max(max(variance.x, variance.y), variance.z)".to_string(),
                    _ => "max(max(variance.x, variance.y), max(variance.z, variance.w))".to_string(),
                };
                need.push(format!("!({spread} <= mrsl_ctl.similarity)"));
                self.line(2, format!("if ({}) {{", need.join(" || ")));
                self.line(3, format!("mask{} |= {}u;", k / 32, 1u32 << (k % 32)));
                self.line(2, "} else {");
                self.line(3, format!("mrsl_hput_{}(p, mean);", info.name));
                self.line(2, "}");
            } else {
                // Integer, bool and matrix values are copied only when every neighbour agrees.
                let agree = if matches!(info.ty, Type::Matrix(_)) {
                    "false".to_string()
                } else {
                    let eq = |j: usize| {
                        if info.ty.components() == 1 {
                            format!("(!ok[{j}] || v{j} == v0)")
                        } else {
                            format!("(!ok[{j}] || all(v{j} == v0))")
                        }
                    };
                    format!("{} && {} && {}", eq(1), eq(2), eq(3))
                };
                need.push(format!("!({agree})"));
                self.line(2, format!("if ({}) {{", need.join(" || ")));
                self.line(3, format!("mask{} |= {}u;", k / 32, 1u32 << (k % 32)));
                self.line(2, "} else {");
                self.line(3, format!("mrsl_hput_{}(p, v0);", info.name));
                self.line(2, "}");
            }
            self.line(1, "}");
        }
        for w in 0..fw {
            self.line(1, format!("mrsl_values[r + {w}u] = 0u;"));
        }
        for w in 0..mw {
            self.line(1, format!("mrsl_values[r + {}u] = mask{w};", fw + w));
        }
        let any: Vec<String> = (0..mw).map(|w| format!("mask{w}")).collect();
        self.line(1, format!("if (({}) != 0u) {{", any.join(" | ")));
        self.line(2, "let slot = atomicAdd(&mrsl_queue[level * 4u], 1u);");
        self.line(2, "mrsl_work[mrsl_work_offset(level) + slot] = u32(p.y) * mrsl_ctl.size.x + u32(p.x);");
        self.line(1, "}");
        self.line(0, "}");
        self.line(0, "");
        // The four levels.
        let levels: [(&str, &str, &str, [(i32, i32); 4]); 4] = [
            (
                "every 4th pixel offset by (2, 2), from its diagonal neighbours at distance 2",
                "vec2<i32>(2) + vec2<i32>(gid.xy) * 4",
                "true",
                [(-2, -2), (2, 2), (2, -2), (-2, 2)],
            ),
            (
                "the remaining pixels of the 2-grid, from axis neighbours at distance 2",
                "vec2<i32>(gid.xy) * 2",
                "((gid.x + gid.y) & 1u) == 1u",
                [(-2, 0), (2, 0), (0, -2), (0, 2)],
            ),
            (
                "odd pixels, from diagonal neighbours at distance 1",
                "vec2<i32>(1) + vec2<i32>(gid.xy) * 2",
                "true",
                [(-1, -1), (1, 1), (1, -1), (-1, 1)],
            ),
            (
                "the rest, from axis neighbours at distance 1",
                "vec2<i32>(gid.xy)",
                "((gid.x + gid.y) & 1u) == 1u",
                [(-1, 0), (1, 0), (0, -1), (0, 1)],
            ),
        ];
        for (index, (what, pixel, valid, offsets)) in levels.iter().enumerate() {
            let level = index + 1;
            self.line(0, format!("// Level {level}: {what}."));
            self.line(0, "@compute @workgroup_size(8, 8, 1)");
            self.line(0, format!("fn hier_classify_{level}(@builtin(global_invocation_id) gid: vec3<u32>) {{"));
            self.line(1, format!("let p = {pixel};"));
            self.line(1, format!("if (any(p >= vec2<i32>(mrsl_ctl.size)) || !({valid})) {{ return; }}"));
            let n: Vec<String> = offsets.iter().map(|(x, y)| format!("p + vec2<i32>({x}, {y})")).collect();
            self.line(1, format!("mrsl_classify(p, array<vec2<i32>, 4>({}), {level}u);", n.join(", ")));
            self.line(0, "}");
            self.line(0, "");
            self.line(0, "@compute @workgroup_size(1, 1, 1)");
            self.line(0, format!("fn hier_args_{level}() {{"));
            self.line(1, format!("let count = atomicLoad(&mrsl_queue[{}u]);", level * 4));
            self.line(1, format!("mrsl_args[{}u] = (count + 63u) / 64u;", level * 4));
            self.line(1, format!("mrsl_args[{}u] = 1u;", level * 4 + 1));
            self.line(1, format!("mrsl_args[{}u] = 1u;", level * 4 + 2));
            self.line(0, "}");
            self.line(0, "");
            self.line(0, "// Shades the compacted work list of the level: every lane has a pixel to shade.");
            self.line(0, "@compute @workgroup_size(64, 1, 1)");
            self.line(0, format!("fn hier_shade_{level}(@builtin(global_invocation_id) gid: vec3<u32>) {{"));
            self.line(1, format!("if (gid.x >= atomicLoad(&mrsl_queue[{}u])) {{ return; }}", level * 4));
            self.line(1, format!("let index = mrsl_work[mrsl_work_offset({level}u) + gid.x];"));
            self.line(1, "mrsl_shade(vec2<i32>(i32(index % mrsl_ctl.size.x), i32(index / mrsl_ctl.size.x)));");
            self.line(0, "}");
            self.line(0, "");
        }
        // Final pass: coarse values from the records, fine effects and outputs per pixel.
        self.record_final_entry(entry::HIER_FINAL);
        let order = self.i.graph.order.clone();
        let nc = coarse.len();
        self.line(1, "if (all(mrsl_pos < mrsl_grid())) {");
        if nc > 0 {
            self.line(2, "let mrsl_r0 = mrsl_rec(mrsl_pos);");
            self.line(2, format!("let mrsl_mask = mrsl_values[mrsl_r0 + {fw}u];"));
            self.line(2, "textureStore(mrsl_rate, mrsl_pos, vec4<u32>(mrsl_mask, 0u, 0u, 1u));");
            for k in 0..nc {
                self.line(
                    2,
                    format!(
                        "if ((mrsl_values[mrsl_r0 + {}u] & {}u) != 0u) {{ atomicAdd(&mrsl_wg_stats[{k}], 1u); }}",
                        fw + k as u32 / 32,
                        1u32 << (k % 32)
                    ),
                );
            }
        }
        for &e in &order {
            let info = &c.effects[e.index()];
            if info.rate == Rate::Coarse {
                self.line(2, format!("let {} = mrsl_hget_{}(mrsl_pos);", self.effect_name(e), info.name));
            } else {
                self.effect_chain(&[e], 2);
            }
        }
        self.output_stores(&order, 2);
        self.line(1, "}");
        self.stats_flush(nc);
    }

    /// Per-pixel records of the hierarchical and checkerboard modes:
    /// `mrsl_rec`, and `mrsl_hget_X` / `mrsl_hput_X` for every live coarse effect.
    fn record_helpers(&mut self) {
        let c = self.checked();
        let h = &self.i.layout.hierarchical;
        self.line(0, format!("const MRSL_RECORD: u32 = {}u;", h.record_words));
        self.line(0, "");
        self.line(0, "fn mrsl_rec(p: vec2<i32>) -> u32 {");
        self.line(1, "return (u32(p.y) * mrsl_ctl.size.x + u32(p.x)) * MRSL_RECORD;");
        self.line(0, "}");
        self.line(0, "");
        for (k, &e) in self.coarse_live().iter().enumerate() {
            let info = &c.effects[e.index()];
            let offset = h.value_offsets[k];
            self.line(0, format!("fn mrsl_hget_{}(p: vec2<i32>) -> {} {{", info.name, info.ty.wgsl()));
            self.line(1, format!("let base = mrsl_rec(p) + {offset}u;"));
            self.line(1, format!("return {};", unpack_words(&info.ty, "mrsl_values")));
            self.line(0, "}");
            self.line(0, format!("fn mrsl_hput_{}(p: vec2<i32>, v: {}) {{", info.name, info.ty.wgsl()));
            self.line(1, format!("let base = mrsl_rec(p) + {offset}u;"));
            for (j, word) in pack_words("v", &info.ty).iter().enumerate() {
                self.line(1, format!("mrsl_values[base + {j}u] = {word};"));
            }
            self.line(0, "}");
        }
        self.line(0, "");
    }

    // ---- Checkerboard kernel -------------------------------------------------------

    fn checkerboard_entries(&mut self) {
        let c = self.checked();
        let coarse = self.coarse_live();
        self.record_helpers();
        self.line(0, "// Quad (qx, qy) of 2x2 pixels is shaded when qx + qy is even (a checkerboard of quads).");
        self.line(0, "fn mrsl_shaded_quad(p: vec2<i32>) -> bool {");
        self.line(1, "return ((p.x / 2 + p.y / 2) & 1) == 0;");
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "// One lane per pixel of the shaded quads only: 16 quads of 4 lanes per workgroup, along");
        self.line(0, "// one row of quads (workgroup y), every other quad (shifted on odd rows).");
        self.line(0, "@compute @workgroup_size(64, 1, 1)");
        self.line(
            0,
            "fn cb_shade(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {",
        );
        self.line(1, "let mrsl_qy = i32(mrsl_wg.y);");
        self.line(1, "// Forced refinement shades every quad (the runtime dispatches twice as many).");
        self.line(1, "let mrsl_k = i32(mrsl_wg.x) * 16 + i32(mrsl_li / 4u);");
        self.line(1, "let mrsl_qx = select(2 * mrsl_k + (mrsl_qy & 1), mrsl_k, mrsl_ctl.force_refine != 0u);");
        self.line(
            1,
            "let mrsl_pos = vec2<i32>(mrsl_qx * 2 + i32(mrsl_li % 2u), mrsl_qy * 2 + i32((mrsl_li / 2u) % 2u));",
        );
        self.line(1, "if (any(mrsl_pos >= mrsl_grid())) { return; }");
        for &e in &coarse {
            self.effect_chain(&[e], 1);
            let info = &c.effects[e.index()];
            self.line(1, format!("mrsl_hput_{}(mrsl_pos, {});", info.name, self.effect_name(e)));
        }
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "// Reconstruction of a pixel in an unshaded quad from the pixels at the same place in the");
        self.line(0, "// edge-adjacent quads, (x +- 2, y) and (x, y +- 2), which are all shaded. Taps across a");
        self.line(0, "// discontinuity key are rejected, and only complete opposite pairs are used (a centred");
        self.line(0, "// mean, exact for linear values). `ok` is all false when no pair is usable: the pixel is");
        self.line(0, "// then shaded in place.");
        self.line(0, "fn mrsl_taps(p: vec2<i32>) -> array<bool, 4> {");
        self.line(1, "let size = vec2<i32>(mrsl_ctl.size);");
        self.line(1, "let taps = array<vec2<i32>, 4>(p + vec2<i32>(-2, 0), p + vec2<i32>(2, 0), p + vec2<i32>(0, -2), p + vec2<i32>(0, 2));");
        self.line(1, "var ok: array<bool, 4>;");
        self.line(1, "for (var k = 0; k < 4; k++) {");
        self.line(2, "ok[k] = all(taps[k] >= vec2<i32>(0)) && all(taps[k] < size);");
        for input in c.inputs.iter() {
            let Some(key) = input.key else { continue };
            let name = &input.name;
            let same = match key {
                KeyCompare::Exact if input.ty.components() == 1 => {
                    format!("mrsl_load_{name}(taps[k]) == mrsl_load_{name}(p)")
                }
                KeyCompare::Exact => format!("all(mrsl_load_{name}(taps[k]) == mrsl_load_{name}(p))"),
                KeyCompare::Threshold { threshold } => {
                    format!("distance(mrsl_load_{name}(taps[k]), mrsl_load_{name}(p)) <= {}", float_literal(threshold))
                }
            };
            self.line(2, format!("ok[k] = ok[k] && ({same});"));
        }
        self.line(1, "}");
        self.line(1, "let pair_x = ok[0] && ok[1];");
        self.line(1, "let pair_y = ok[2] && ok[3];");
        self.line(1, "// Without a complete pair the pixel is shaded in place: one-sided means would extrapolate.");
        self.line(1, "return array<bool, 4>(pair_x, pair_x, pair_y, pair_y);");
        self.line(0, "}");
        self.line(0, "");
        for &e in &coarse {
            let info = &c.effects[e.index()];
            let ty = info.ty.wgsl();
            let blendable =
                matches!(info.ty, Type::Scalar(Scalar::Float) | Type::Vector(Scalar::Float, _) | Type::Matrix(_));
            self.line(0, format!("fn mrsl_reconstruct_{}(p: vec2<i32>, ok: array<bool, 4>) -> {ty} {{", info.name));
            self.line(1, "let taps = array<vec2<i32>, 4>(p + vec2<i32>(-2, 0), p + vec2<i32>(2, 0), p + vec2<i32>(0, -2), p + vec2<i32>(0, 2));");
            if blendable {
                self.line(1, format!("var sum = {ty}();"));
                self.line(1, "var n = 0.0;");
                self.line(1, "for (var k = 0; k < 4; k++) {");
                self.line(2, format!("if (ok[k]) {{ sum = sum + mrsl_hget_{}(taps[k]); n += 1.0; }}", info.name));
                self.line(1, "}");
                self.line(1, "return sum * (1.0 / n);");
            } else {
                self.line(1, "// Not blendable: the first usable tap.");
                self.line(1, "for (var k = 0; k < 4; k++) {");
                self.line(2, format!("if (ok[k]) {{ return mrsl_hget_{}(taps[k]); }}", info.name));
                self.line(1, "}");
                self.line(1, format!("return mrsl_hget_{}(p);", info.name));
            }
            self.line(0, "}");
        }
        self.line(0, "");
        self.record_final_entry(entry::CB_FINAL);
        let order = self.i.graph.order.clone();
        let nc = coarse.len();
        self.line(1, "if (all(mrsl_pos < mrsl_grid())) {");
        self.line(2, "let mrsl_shaded = mrsl_shaded_quad(mrsl_pos) || mrsl_ctl.force_refine != 0u;");
        self.line(2, "let mrsl_ok = mrsl_taps(mrsl_pos);");
        self.line(2, "// No usable tap (isolated by discontinuities): shaded here instead.");
        self.line(2, "let mrsl_alone = !mrsl_shaded && !(mrsl_ok[0] || mrsl_ok[1] || mrsl_ok[2] || mrsl_ok[3]);");
        if nc > 0 {
            let all = if nc >= 32 { u32::MAX } else { (1u32 << nc) - 1 };
            self.line(2, format!("textureStore(mrsl_rate, mrsl_pos, vec4<u32>(select(0u, {all}u, mrsl_shaded || mrsl_alone), 0u, 0u, 1u));"));
            self.line(2, "if (mrsl_shaded || mrsl_alone) {");
            for k in 0..nc {
                self.line(3, format!("atomicAdd(&mrsl_wg_stats[{k}], 1u);"));
            }
            self.line(2, "}");
        }
        for &e in &order {
            let info = &c.effects[e.index()];
            if info.rate == Rate::Coarse {
                let name = self.effect_name(e);
                self.line(2, format!("var {name}: {};", info.ty.wgsl()));
                self.line(2, format!("if (mrsl_shaded) {{ {name} = mrsl_hget_{0}(mrsl_pos); }}", info.name));
                self.line(
                    2,
                    format!("else if (!mrsl_alone) {{ {name} = mrsl_reconstruct_{0}(mrsl_pos, mrsl_ok); }}", info.name),
                );
                self.line(2, "else {");
                self.effect_chain_into(e, 3);
                self.line(2, "}");
            } else {
                self.effect_chain(&[e], 2);
            }
        }
        self.output_stores(&order, 2);
        self.line(1, "}");
        self.stats_flush(nc);
    }

    /// Opens the final per-pixel entry point of a record-based mode (an 8x8 tile
    /// per workgroup, lanes in row-major order) up to `mrsl_pos`; closed by [`Self::stats_flush`].
    fn record_final_entry(&mut self, name: &str) {
        self.line(0, "fn mrsl_tile_pixel(wg: vec2<u32>, li: u32) -> vec2<i32> {");
        self.line(1, "return vec2<i32>(wg * 8u + vec2<u32>(li % 8u, li / 8u));");
        self.line(0, "}");
        self.line(0, "");
        self.line(0, "@compute @workgroup_size(64, 1, 1)");
        self.line(
            0,
            format!(
                "fn {name}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {{"
            ),
        );
        self.line(1, "let mrsl_pos = mrsl_tile_pixel(mrsl_wg.xy, mrsl_li);");
    }

    /// Ends a per-pixel entry point: adds the workgroup's counters to the global
    /// statistics once every lane has counted, then closes the function.
    fn stats_flush(&mut self, counters: usize) {
        if counters > 0 {
            self.line(1, "workgroupBarrier();");
            self.line(1, format!("for (var k = mrsl_li; k < {counters}u; k += 64u) {{"));
            self.line(2, "atomicAdd(&mrsl_stats[k], atomicLoad(&mrsl_wg_stats[k]));");
            self.line(1, "}");
        }
        self.line(0, "}");
    }

    fn output_stores(&mut self, order: &[EffectId], indent: usize) {
        let c = self.checked();
        for e in order {
            let info = &c.effects[e.index()];
            if info.rate != Rate::Out {
                continue;
            }
            let value = to_vec4(&self.effect_name(*e), &info.ty);
            self.line(indent, format!("textureStore(mrsl_out_{}, mrsl_pos, {value});", info.name));
        }
    }
}

fn float_literal(v: f64) -> String {
    let text = format!("{v:?}");
    if text.contains('.') || text.contains('e') || text.contains("inf") || text.contains("NaN") {
        text
    } else {
        format!("{text}.0")
    }
}

/// WGSL expressions for the 32-bit words of a value, in order.
fn pack_words(value: &str, ty: &Type) -> Vec<String> {
    let scalar = |x: String, s: Scalar| match s {
        Scalar::Float | Scalar::Int => format!("bitcast<u32>({x})"),
        Scalar::Uint => x,
        Scalar::Bool => format!("select(0u, 1u, {x})"),
    };
    match ty {
        Type::Scalar(s) => vec![scalar(value.to_string(), *s)],
        Type::Vector(s, n) => (0..*n).map(|k| scalar(format!("{value}[{k}]"), *s)).collect(),
        Type::Matrix(n) => {
            (0..*n).flat_map(|col| (0..*n).map(move |row| format!("bitcast<u32>({value}[{col}][{row}])"))).collect()
        }
        _ => vec![],
    }
}

/// A WGSL expression reading a value from `mrsl_interface` at word `base`.
fn unpack_words(ty: &Type, buffer: &str) -> String {
    let word = |k: u32| format!("{buffer}[base + {k}u]");
    let scalar = |k: u32, s: Scalar| match s {
        Scalar::Float => format!("bitcast<f32>({})", word(k)),
        Scalar::Int => format!("bitcast<i32>({})", word(k)),
        Scalar::Uint => word(k),
        Scalar::Bool => format!("({} != 0u)", word(k)),
    };
    match ty {
        Type::Scalar(s) => scalar(0, *s),
        Type::Vector(s, n) => {
            format!("{}({})", ty.wgsl(), (0..*n as u32).map(|k| scalar(k, *s)).collect::<Vec<_>>().join(", "))
        }
        Type::Matrix(n) => {
            let n = *n as u32;
            let cols: Vec<String> = (0..n)
                .map(|col| {
                    format!(
                        "vec{n}<f32>({})",
                        (0..n).map(|row| scalar(col * n + row, Scalar::Float)).collect::<Vec<_>>().join(", ")
                    )
                })
                .collect();
            format!("{}({})", ty.wgsl(), cols.join(", "))
        }
        _ => "0u".into(),
    }
}

/// Widens an output value to the `vec4` that `textureStore` takes.
fn to_vec4(value: &str, ty: &Type) -> String {
    let (s, one) = match ty.scalar() {
        Some(Scalar::Uint) => ("u32", "1u"),
        Some(Scalar::Int) => ("i32", "1i"),
        _ => ("f32", "1.0"),
    };
    match ty.components() {
        1 => format!("vec4<{s}>({value}, 0, 0, {one})"),
        2 => format!("vec4<{s}>({value}, 0, {one})"),
        3 => format!("vec4<{s}>({value}, {one})"),
        _ => value.to_string(),
    }
}
