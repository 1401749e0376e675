//! What an editor asks of a program ([`analyze`]): its diagnostics, every
//! declaration and every reference to one, and per effect the facts the
//! compiler decides (rate, cost in operations, interface slot and what
//! shares it, the keys and predicates that refine it, evaluations per
//! sample). A language server (`mrslc lsp`) answers hovers, definitions,
//! references, completions and inlay hints from it without knowing the
//! compiler's stages.
//!
//! It reuses the stages [`crate::compile`] runs: the front end always (a
//! program with errors still has its declarations and references), and,
//! for a program without errors, the interface allocation, the cost model
//! and the layout, which are cheap; it never generates or validates a
//! kernel, which is what takes a compile its time.

use crate::budget;
use crate::check::{Callee, Checked, EffectId, LocalId, Symbol};
use crate::deriv::DerivInfo;
use crate::diagnostic::Diagnostic;
use crate::graph::EffectGraph;
use crate::span::Span;
use crate::syntax::ast::*;
use crate::syntax::{visit_expr, visit_stmt_exprs};
use mrsl_abi::Layout;
use std::collections::HashMap;

/// Everything [`analyze`] found out about a program.
#[derive(Debug, Clone, Default)]
pub struct Analysis {
    /// Every diagnostic, as [`crate::check`] reports them.
    pub diagnostics: Vec<Diagnostic>,
    /// Every declaration: the top-level ones in source order, then the
    /// parameters and locals; empty when the program does not parse.
    pub declarations: Vec<Declaration>,
    /// Every name that refers to a declaration, in source order.
    pub references: Vec<Reference>,
    /// Every effect and output, in declaration order.
    pub effects: Vec<EffectFacts>,
}

/// What a declaration declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DeclarationKind {
    Input,
    Uniform,
    Const,
    Function,
    Effect,
    Output,
    Local,
    Parameter,
}

impl DeclarationKind {
    /// The word the documentation uses for it.
    pub fn word(self) -> &'static str {
        match self {
            DeclarationKind::Input => "G-buffer input",
            DeclarationKind::Uniform => "uniform",
            DeclarationKind::Const => "constant",
            DeclarationKind::Function => "function",
            DeclarationKind::Effect => "effect",
            DeclarationKind::Output => "output",
            DeclarationKind::Local => "local",
            DeclarationKind::Parameter => "parameter",
        }
    }
}

/// A declared name.
#[derive(Debug, Clone, PartialEq)]
pub struct Declaration {
    pub name: String,
    pub kind: DeclarationKind,
    /// The type (a function's return type), as diagnostics spell it.
    pub ty: String,
    /// The declaration in one line, as written (`float attenuation(float dist, float range)`).
    pub signature: String,
    pub name_span: Span,
    /// The whole declaration.
    pub span: Span,
    /// Where a local or parameter can be named (its scope after its
    /// declaration); `None` for the top-level names, which are visible everywhere.
    pub visible: Option<Span>,
    /// For an effect or output, its index in [`Analysis::effects`].
    pub effect: Option<usize>,
}

/// A name that refers to [`Analysis::declarations`]`[declaration]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reference {
    pub span: Span,
    pub declaration: usize,
}

/// What the compiler decides about an effect or output.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectFacts {
    pub name: String,
    /// `coarse`, `coarse(4)`, `coarse(2)`, `fine` or `out`.
    pub rate: String,
    /// The conditions under which the effect's body says `refine`, as
    /// written (conditions of nested `if`s joined by `&&`, an `else`
    /// branch's as `!(...)`); `always` for an unconditional `refine;`.
    pub predicates: Vec<String>,
    /// The layout's facts; `None` while the program has errors.
    pub layout: Option<EffectLayoutFacts>,
}

/// An effect's facts from the layout (a program without errors).
#[derive(Debug, Clone, PartialEq)]
pub struct EffectLayoutFacts {
    /// Whether an output needs it (a dead effect is never computed).
    pub live: bool,
    /// The cost model's operations per evaluation (loop bodies times their
    /// trip counts, texture reads weighted; the layout's `operations`).
    pub operations: Option<u64>,
    /// The fully inlined operations the size budget counts (E0701 past
    /// [`crate::MAX_EFFECT_OPERATIONS`]).
    pub inlined_operations: Option<u64>,
    /// The interface slot that carries it from the coarse to the fine pass.
    pub slot: Option<SlotFacts>,
    /// The discontinuity keys whose edges refine it.
    pub keys: Vec<String>,
    /// When a coarse pass must evaluate it, over refine flags `r_X`.
    pub pass_condition: Option<String>,
    /// Evaluations of its body per coarse sample in the tile kernel.
    pub sample_evaluations: Option<u32>,
}

/// An interface slot.
#[derive(Debug, Clone, PartialEq)]
pub struct SlotFacts {
    pub index: usize,
    /// Offset and size in 32-bit words of the per-sample record.
    pub offset: u32,
    pub size: u32,
    /// The other effects in the same slot (never needed at the same pixel).
    pub shared_with: Vec<String>,
}

/// Analyses `source` for an editor (see the module documentation). Never
/// panics on any input; runs on a large stack like [`crate::check`].
pub fn analyze(source: &str) -> Analysis {
    crate::validate::with_stack(|| {
        crate::stages(source, |analyses, diagnostics| {
            let mut analysis = match analyses {
                Some((checked, graph, deriv)) => {
                    let errors = diagnostics.iter().any(|d| d.is_error());
                    let layout = (!errors).then(|| layout(checked, graph, deriv));
                    Builder::new(source, checked).run(layout.as_ref().map(|(l, budget)| (l, budget)))
                }
                None => Analysis::default(),
            };
            analysis.diagnostics = diagnostics;
            analysis
        })
    })
}

/// The layout of a program without errors (no plan, no kernels), and the
/// size budget's count per effect.
fn layout(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo) -> (Layout, HashMap<EffectId, u64>) {
    let interface = crate::interface::allocate(checked, graph);
    let costs = budget::evaluation_costs(checked, graph, deriv);
    let layout = crate::layout::build(checked, graph, deriv, &interface, &costs);
    let inlined = budget::costs(checked, graph, deriv).effects.into_iter().collect();
    (layout, inlined)
}

/// Fills an [`Analysis`] from the checked program.
struct Builder<'s, 'c> {
    source: &'s str,
    checked: &'c Checked<'c>,
    out: Analysis,
    /// The declaration of each local (parameters and block effects' results included).
    locals: HashMap<LocalId, usize>,
    /// The declaration of each top-level item, by item index.
    items: Vec<usize>,
}

impl<'s, 'c> Builder<'s, 'c> {
    fn new(source: &'s str, checked: &'c Checked<'c>) -> Self {
        Builder { source, checked, out: Analysis::default(), locals: HashMap::new(), items: vec![] }
    }

    fn text(&self, span: Span) -> &'s str {
        self.source.get(span.range()).unwrap_or("")
    }

    fn run(mut self, layout: Option<(&Layout, &HashMap<EffectId, u64>)>) -> Analysis {
        self.items();
        let program = self.checked.program;
        for (index, item) in program.items.iter().enumerate() {
            match item {
                Item::Function(f) => self.function_locals(index, f),
                Item::Effect(e) => self.effect_locals(index, e),
                _ => {}
            }
        }
        for item in &program.items {
            self.item_references(item);
        }
        self.out.references.sort_by_key(|r| r.span.start);
        self.effects(layout);
        self.out
    }

    fn declare(&mut self, declaration: Declaration) -> usize {
        self.out.declarations.push(declaration);
        self.out.declarations.len() - 1
    }

    /// The top-level declarations, in item order.
    fn items(&mut self) {
        let checked = self.checked;
        let (mut inputs, mut uniforms, mut consts, mut functions, mut effects) = (0, 0, 0, 0, 0);
        for item in &checked.program.items {
            let next = |n: &mut usize| std::mem::replace(n, *n + 1);
            let (kind, ty, signature, span) = match item {
                Item::Input(d) => {
                    let ty = checked.inputs.get(next(&mut inputs)).map(|i| i.ty.name()).unwrap_or_default();
                    (DeclarationKind::Input, ty, format!("in {} {}", d.ty.name, d.name.name), d.span)
                }
                Item::Uniform(d) => {
                    let ty = checked.uniforms.get(next(&mut uniforms)).map(|u| u.ty.name()).unwrap_or_default();
                    let end = d.array_len.as_ref().map_or(d.name.span, |n| n.span);
                    let head = self.text(Span { start: d.span.start, end: end.end });
                    let array = if d.array_len.is_some() { "]" } else { "" };
                    (DeclarationKind::Uniform, ty, format!("{head}{array}"), d.span)
                }
                Item::Const(d) => {
                    let ty = checked.consts.get(next(&mut consts)).map(|c| c.ty.name()).unwrap_or_default();
                    let value = one_line(self.text(d.value.span));
                    (DeclarationKind::Const, ty, format!("const {} {} = {value}", d.ty.name, d.name.name), d.span)
                }
                Item::Function(d) => {
                    let ty = checked.functions.get(next(&mut functions)).map(|f| f.ret.name()).unwrap_or_default();
                    let params: Vec<String> =
                        d.params.iter().map(|p| format!("{} {}", p.ty.name, p.name.name)).collect();
                    (
                        DeclarationKind::Function,
                        ty,
                        format!("{} {}({})", d.ret.name, d.name.name, params.join(", ")),
                        d.span,
                    )
                }
                Item::Effect(d) => {
                    let ty = checked.effects.get(next(&mut effects)).map(|e| e.ty.name()).unwrap_or_default();
                    let kind = if d.rate == Rate::Out { DeclarationKind::Output } else { DeclarationKind::Effect };
                    let head = self.text(Span { start: d.rate_span.start, end: d.name.span.end });
                    (kind, ty, one_line(head), d.span)
                }
            };
            let name = item.name();
            let effect = matches!(item, Item::Effect(_)).then(|| effects - 1);
            let index = self.declare(Declaration {
                name: name.name.clone(),
                kind,
                ty,
                signature,
                name_span: name.span,
                span,
                visible: None,
                effect,
            });
            self.items.push(index);
        }
    }

    fn function_locals(&mut self, item: usize, f: &FunctionDecl) {
        let info = self.checked.functions.iter().find(|info| info.item == item);
        let params = info.map(|info| info.params.clone()).unwrap_or_default();
        for (param, local) in f.params.iter().zip(params) {
            let signature = format!("{} {}", param.ty.name, param.name.name);
            let span = param.ty.span.to(param.name.span);
            let index = self.local(local, DeclarationKind::Parameter, signature, span, f.body.span);
            self.locals.insert(local, index);
        }
        self.block_locals(&f.body);
    }

    fn effect_locals(&mut self, item: usize, e: &EffectDecl) {
        if let Some(info) = self.checked.effects.iter().find(|info| info.item == item)
            && let Some(result) = info.result
        {
            // A block effect assigns its own name: a reference to the effect.
            self.locals.insert(result, self.items[item]);
        }
        if let EffectBody::Block(b) = &e.body {
            self.block_locals(b);
        }
    }

    fn local(&mut self, id: LocalId, kind: DeclarationKind, signature: String, span: Span, scope: Span) -> usize {
        let info = &self.checked.locals[id.index()];
        self.declare(Declaration {
            name: info.name.clone(),
            kind,
            ty: info.ty.name(),
            signature,
            name_span: info.span,
            span,
            visible: Some(Span { start: span.end, end: scope.end }),
            effect: None,
        })
    }

    /// The locals a block declares, each visible to the end of its block
    /// (a `for` header's, to the end of the loop).
    fn block_locals(&mut self, block: &Block) {
        for stmt in &block.stmts {
            self.stmt_locals(stmt, block.span);
        }
    }

    fn stmt_locals(&mut self, stmt: &Stmt, scope: Span) {
        match &stmt.kind {
            StmtKind::Local { ty, name, .. } => {
                if let Some(&local) = self.checked.local_decls.get(&stmt.id) {
                    let signature = format!("{} {}", ty.name, name.name);
                    let index = self.local(local, DeclarationKind::Local, signature, stmt.span, scope);
                    self.locals.insert(local, index);
                }
            }
            StmtKind::If { then, otherwise, .. } => {
                self.stmt_locals(then, then.span);
                if let Some(o) = otherwise {
                    self.stmt_locals(o, o.span);
                }
            }
            StmtKind::For { init, step, body, .. } => {
                if let Some(i) = init {
                    self.stmt_locals(i, stmt.span);
                }
                if let Some(s) = step {
                    self.stmt_locals(s, stmt.span);
                }
                self.stmt_locals(body, body.span);
            }
            StmtKind::Block(b) => self.block_locals(b),
            _ => {}
        }
    }
}

impl Builder<'_, '_> {
    /// The references in an item: names read or assigned, functions called.
    fn item_references(&mut self, item: &Item) {
        let mut exprs: Vec<&Expr> = vec![];
        let mut stmts: Vec<&Stmt> = vec![];
        match item {
            Item::Input(d) => d.attrs.iter().for_each(|a| exprs.extend(&a.args)),
            Item::Uniform(d) => {
                d.attrs.iter().for_each(|a| exprs.extend(&a.args));
                exprs.extend(d.array_len.iter().chain(&d.default));
            }
            Item::Const(d) => exprs.push(&d.value),
            Item::Function(d) => stmts.extend(&d.body.stmts),
            Item::Effect(d) => {
                d.attrs.iter().for_each(|a| exprs.extend(&a.args));
                match &d.body {
                    EffectBody::Expr(e) => exprs.push(e),
                    EffectBody::Block(b) => stmts.extend(&b.stmts),
                }
            }
        }
        for stmt in stmts {
            visit_stmt_exprs(stmt, &mut |e| exprs.push(e));
        }
        for expr in exprs {
            visit_expr(expr, &mut |e| self.reference(e));
        }
    }

    fn reference(&mut self, e: &Expr) {
        let checked = self.checked;
        let found = match &e.kind {
            ExprKind::Name(_) => match checked.symbols.get(&e.id) {
                Some(Symbol::Local(l)) => self.locals.get(l).map(|&d| (d, e.span)),
                Some(symbol) => self.global(*symbol).map(|d| (d, e.span)),
                None => None,
            },
            ExprKind::Call { callee, .. } => match checked.callees.get(&e.id) {
                Some(Callee::Function(f)) => {
                    checked.functions.get(f.index()).map(|f| (self.items[f.item], callee.span))
                }
                _ => None,
            },
            _ => None,
        };
        if let Some((declaration, span)) = found {
            self.out.references.push(Reference { span, declaration });
        }
    }

    /// The declaration of a top-level symbol.
    fn global(&self, symbol: Symbol) -> Option<usize> {
        let checked = self.checked;
        let item = match symbol {
            Symbol::Input(i) => self.nth_item(i.index(), |item| matches!(item, Item::Input(_))),
            Symbol::Uniform(u) => self.nth_item(u.index(), |item| matches!(item, Item::Uniform(_))),
            Symbol::Const(c) => checked.consts.get(c.index()).map(|c| c.item),
            Symbol::Effect(e) => checked.effects.get(e.index()).map(|e| e.item),
            Symbol::Local(_) => None,
        }?;
        self.items.get(item).copied()
    }

    /// The index of the `n`th item that `is` holds for (inputs and
    /// uniforms are numbered in item order).
    fn nth_item(&self, n: usize, is: impl Fn(&Item) -> bool) -> Option<usize> {
        self.checked.program.items.iter().enumerate().filter(|(_, item)| is(item)).nth(n).map(|(i, _)| i)
    }

    /// Every effect's facts, with the layout's when there is one.
    fn effects(&mut self, layout: Option<(&Layout, &HashMap<EffectId, u64>)>) {
        let checked = self.checked;
        for (i, info) in checked.effects.iter().enumerate() {
            let rate = match (info.rate, info.block) {
                (Rate::Coarse, Some(n)) => format!("coarse({n})"),
                (Rate::Coarse, None) => "coarse".to_string(),
                (Rate::Fine, _) => "fine".to_string(),
                (Rate::Out, _) => "out".to_string(),
            };
            let mut predicates = vec![];
            if let Some(Item::Effect(EffectDecl { body: EffectBody::Block(b), .. })) =
                checked.program.items.get(info.item)
            {
                for stmt in &b.stmts {
                    self.predicates(stmt, &mut vec![], &mut predicates);
                }
            }
            let layout = layout.and_then(|(layout, inlined)| {
                let effect = layout.effects.get(i)?;
                Some(EffectLayoutFacts {
                    live: effect.live,
                    operations: effect.operations,
                    inlined_operations: inlined.get(&EffectId(i as u32)).copied(),
                    slot: effect.slot.and_then(|index| {
                        let slot = layout.interface.slots.get(index)?;
                        let shared_with = slot.effects.iter().filter(|e| **e != info.name).cloned().collect();
                        Some(SlotFacts { index, offset: slot.offset, size: slot.size, shared_with })
                    }),
                    keys: effect.keys.clone(),
                    pass_condition: effect.pass_condition.clone(),
                    sample_evaluations: effect.sample_evaluations,
                })
            });
            self.out.effects.push(EffectFacts { name: info.name.clone(), rate, predicates, layout });
        }
    }

    /// The conditions under which `stmt` says `refine`, given the
    /// conditions of the `if`s around it.
    fn predicates(&self, stmt: &Stmt, around: &mut Vec<String>, out: &mut Vec<String>) {
        match &stmt.kind {
            StmtKind::Refine if around.is_empty() => out.push("always".to_string()),
            StmtKind::Refine => out.push(around.join(" && ")),
            StmtKind::If { cond, then, otherwise } => {
                let cond = one_line(self.text(cond.span));
                around.push(cond.clone());
                self.predicates(then, around, out);
                around.pop();
                if let Some(o) = otherwise {
                    around.push(format!("!({cond})"));
                    self.predicates(o, around, out);
                    around.pop();
                }
            }
            StmtKind::For { body, .. } => self.predicates(body, around, out),
            StmtKind::Block(b) => b.stmts.iter().for_each(|s| self.predicates(s, around, out)),
            _ => {}
        }
    }
}

/// `text` on one line, runs of white space as one space.
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A mechanical fix: replace the text at `span` with `replacement`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fix {
    pub span: Span,
    pub replacement: String,
}

/// The fix a diagnostic's note names for the diagnostic's primary span,
/// where applying it is mechanical: a "did you mean `x`?" suggestion, or a
/// foreign word's "help: mrsl writes `x` (`vec3` is GLSL, WGSL)", when `x`
/// is one word. Notes that describe a rewrite in prose (`help: mrsl writes
/// a function declared C-style: ...`) name no fix, and neither do syntax
/// errors (E0003): there the word is one part of a construct to rewrite
/// (`vec3<f32>`'s fix is not `float3<f32>`).
pub fn quick_fix(diagnostic: &Diagnostic) -> Option<Fix> {
    if diagnostic.code == "E0003" {
        return None;
    }
    let span = diagnostic.span()?;
    diagnostic.notes.iter().find_map(|note| {
        let rest = note.strip_prefix("did you mean `").or_else(|| note.strip_prefix("help: mrsl writes `"))?;
        let (word, after) = rest.split_once('`')?;
        let ends = after == "?" || after.is_empty() || after.starts_with(" (");
        let is_word = !word.is_empty() && word.chars().all(|c| c.is_alphanumeric() || c == '_');
        (ends && is_word).then(|| Fix { span, replacement: word.to_string() })
    })
}
