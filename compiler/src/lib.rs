//! mrsl: a compiler for a multi-rate shading language.
//!
//! A program declares G-buffer inputs, uniforms, functions and *effects* at
//! coarse or fine rate; coarse effects may `refine` themselves where they are
//! not smooth. [`compile`] turns the source into WGSL compute kernels (coarse
//! and fine per block size, a per-pixel reference, and the kernels of the
//! dynamic, hierarchical and checkerboard modes), validated by naga, and a
//! [`Layout`] describing every binding and the coarse-to-fine interface. The
//! result is a [`Program`]: a [`CompiledProgram`] (the `mrsl-abi` contract
//! type the runtime consumes) plus warnings.
//!
//! ```
//! let source = "
//!     in float3 normal;
//!     uniform float3 light = float3(0.0, 1.0, 0.0);
//!     coarse effect float diffuse {
//!         diffuse = saturate(dot(normal, light));
//!         if (fwidth(diffuse) > 0.05) refine;
//!     }
//!     fine out float4 color = float4(float3(diffuse), 1.0);
//! ";
//! let program = mrsl::compile(source, &mrsl::Options::default()).expect("valid program");
//! assert!(program.kernel(mrsl::KernelKind::Fine, 4).unwrap().wgsl.contains("fn fine_main"));
//! assert_eq!(program.layout.interface.slots.len(), 1);
//! ```
//!
//! The crate does no I/O and touches no GPU: everything here runs anywhere.

mod analysis;
mod attributes;
mod budget;
mod builtins;
mod check;
mod codegen;
mod deriv;
mod deriv_warnings;
mod diagnostic;
mod foreign;
mod graph;
mod interface;
mod layout;
mod limits;
mod neighbours;
mod plan;
mod rates;
mod span;
mod syntax;
mod types;
mod validate;
pub mod vocabulary;

pub use analysis::{
    Analysis, Declaration, DeclarationKind, EffectFacts, EffectLayoutFacts, Fix, Reference, SlotFacts, analyze,
    quick_fix,
};
/// The most operations one effect's fully inlined code may take (E0701):
/// the limit [`EffectLayoutFacts::inlined_operations`] is measured against.
pub use budget::MAX_EFFECT_OPERATIONS;
pub use diagnostic::{Diagnostic, Label, Severity, emit_colored, render_all};
pub use mrsl_abi::{CompiledProgram, Kernel, KernelKind, KernelRef, Layout, Mode, Plan};
pub use span::Span;
use validate::{NagaFailure, generated_context, naga_validate, validate_all, with_stack};

/// The stages behind [`compile`], for the compiler's own benchmarks and tests
/// only: not part of the API, and free to change with the stages.
#[doc(hidden)]
pub mod internals {
    pub use crate::budget::{MAX_EFFECT_OPERATIONS, MAX_PROGRAM_OPERATIONS};
    pub use crate::check::{EffectId, check as check_ast};
    pub use crate::foreign::{Kind as ForeignKind, TABLE as FOREIGN_WORDS, rows as foreign_rows};
    pub use crate::graph::build as build_graph;
    pub use crate::interface::{EXACT_LIMIT, allocate as allocate_interface, colour};
    pub use crate::syntax::lexer::Lexer;
    pub use crate::syntax::parse;

    /// The operations of the program's fully inlined code, as the size
    /// budget (E0701) counts them: the whole program's and its costliest
    /// effect's; `None` if the program has errors before the budget is checked.
    pub fn inlined_operations(source: &str) -> Option<(u64, u64)> {
        let program = crate::syntax::parse(source).ok()?;
        let (checked, diagnostics) = crate::check::check(&program);
        let (graph, graph_diagnostics) = crate::graph::build(&checked);
        let (deriv, deriv_diagnostics) = crate::deriv::analyse(&checked);
        let errors = diagnostics.iter().chain(&graph_diagnostics).chain(&deriv_diagnostics).any(|d| d.is_error());
        (!errors).then(|| {
            let costs = crate::budget::costs(&checked, &graph, &deriv);
            (costs.total, costs.effects.iter().map(|(_, cost)| *cost).max().unwrap_or(0))
        })
    }

    /// A chain of `n` coarse effects `e0` .. `e{n-1}` (n >= 1), each reading
    /// the previous one and refining where its own `fwidth` is large, and
    /// one output reading the last: the program whose neighbour evaluations
    /// once grew exponentially with `n` (see docs/eval/compile-performance.md).
    pub fn derivative_chain(n: usize) -> String {
        let mut source = String::from("in float3 normal;\nin float2 uv;\nuniform float t = 0.05;\n\n");
        source.push_str(
            "coarse effect float e0 {\n    e0 = saturate(dot(normal, float3(0.0, 1.0, 0.0)));\n    if (fwidth(e0) > t) refine;\n}\n",
        );
        for k in 1..n.max(1) {
            source.push_str(&format!(
                "coarse effect float e{k} {{\n    e{k} = e{} * 0.5 + uv.x * 0.25;\n    if (fwidth(e{k}) > t) refine;\n}}\n",
                k - 1
            ));
        }
        source.push_str(&format!("fine out float4 color = float4(float3(e{}), 1.0);\n", n.max(1) - 1));
        source
    }
}

/// Which modes to compile for, and how.
///
/// [`compile`] generates and validates only the kernels these modes
/// dispatch ([`Options::kernels`], from the one table [`Mode::kernels`]),
/// and writes their passes into the layout's plan. The default is every
/// mode: fifteen kernels. A caller that runs fewer modes asks for them alone,
/// which takes a fraction of the time: `Options::for_modes(&[Mode::Coarse4x4])`.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The modes to compile for; the order does not matter.
    pub modes: Vec<Mode>,
    /// Name written in the header comment of every generated kernel.
    pub file_name: String,
    /// Compact the block modes' fine pass: the pixels of a workgroup that
    /// re-evaluate a coarse effect do so together, on consecutive lanes,
    /// exchanging values through workgroup memory (one barrier per coarse
    /// effect). The images are the same bit for bit. Off by default: on
    /// lavapipe, where a barrier switches every invocation's coroutine, it
    /// made the Sponza workload's fine pass slower (docs/eval/evaluation.md,
    /// `mrslc bench --ablation`); on GPUs, whose barriers are cheap, it is
    /// the layout He et al. describe, but it has not been measured on one.
    pub compact: bool,
    /// Read the G-buffer channels through read-only storage texture bindings
    /// instead of sampled ones: every channel but those rebuilt from depth
    /// ([`mrsl_abi::ChannelAccess::Storage`] in the layout). The engine's
    /// textures must then have exactly the layout's formats and
    /// `STORAGE_BINDING`, and every kernel binds one storage texture more
    /// per such channel, beyond WebGPU's default limit of 4 for most
    /// programs ([`mrsl_abi::Layout::storage_textures_per_stage`] says how
    /// many). The images are the same bit for bit. Off by default; on
    /// lavapipe a storage texel costs about a third of a sampled one, and
    /// the hierarchical mode, which loads the key channels of five pixels
    /// per pixel, gains most (docs/eval/evaluation.md).
    pub storage_channels: bool,
    /// Pack the hierarchical kernel's per-pixel records four words to a
    /// texel of an `rgba32uint` read-write storage texture instead of a
    /// texel per word of an `r32uint` one: the classification loads each
    /// neighbour's record in a texel or two, not a texel per word, and each
    /// pixel stores its record once. The images are the same bit for bit.
    /// Off by default: read-write storage access to `rgba32uint` is not in
    /// core WebGPU (wgpu grants it with `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`
    /// where the adapter has it, as lavapipe does; browsers with
    /// `texture-formats-tier2`). On lavapipe the hierarchical frame is about
    /// a tenth faster (docs/eval/evaluation.md).
    pub packed_records: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options::for_modes(&Mode::ALL)
    }
}

impl Options {
    /// Options that compile for `modes` alone.
    pub fn for_modes(modes: &[Mode]) -> Options {
        Options {
            modes: modes.to_vec(),
            file_name: "program.mrsl".into(),
            compact: false,
            storage_channels: false,
            packed_records: false,
        }
    }

    /// The kernels [`compile`] generates with these options: those of the
    /// modes, each once, by kind and then block size. The block size is
    /// `None` for the kinds that exist once per program.
    pub fn kernels(&self) -> Vec<KernelRef> {
        Mode::kernels_of(&self.modes)
    }
}

/// A compiled program: kernels and layout (dereferences to the
/// [`CompiledProgram`] the runtime takes), and the warnings found on the way.
#[derive(Debug, Clone)]
pub struct Program {
    pub compiled: CompiledProgram,
    /// Warnings (the program compiled regardless).
    pub warnings: Vec<Diagnostic>,
}

impl std::ops::Deref for Program {
    type Target = CompiledProgram;

    fn deref(&self) -> &CompiledProgram {
        &self.compiled
    }
}

/// Parses and checks a program without generating code: every diagnostic,
/// errors and warnings, in source order.
///
/// Like [`compile`], it runs on a thread of its own with a large stack, so
/// it works the same from any thread (see `validate::STACK`).
pub fn check(source: &str) -> Vec<Diagnostic> {
    with_stack(|| front_end(source, |_, _, _, warnings| warnings).unwrap_or_else(|errors| errors))
}

/// Formats a program in the canonical layout of `mrslc fmt` (see
/// `syntax::format`): the same program, every comment kept. A program that
/// does not parse is its syntax error. Runs on a thread with a large stack,
/// like [`check`].
pub fn format(source: &str) -> Result<String, Diagnostic> {
    with_stack(|| syntax::format::format(source))
}

/// Compiles a program to kernels and a layout, or returns its diagnostics
/// (errors, and warnings found alongside them).
pub fn compile(source: &str, options: &Options) -> Result<Program, Vec<Diagnostic>> {
    with_stack(|| {
        front_end(source, |checked, graph, deriv, diagnostics| {
            generate(source, options, checked, graph, deriv, diagnostics)
        })?
    })
}

/// The span of the name of the top-level declaration `name` in `source`
/// (an `in` channel, a uniform, a constant, a function or an effect): where
/// a diagnostic about it points when the problem is found at the edge,
/// binding a compiled program to a scene or an engine. `None` when `source`
/// does not parse or declares no such name.
pub fn declaration_span(source: &str, name: &str) -> Option<Span> {
    let program = syntax::parse(source).ok()?;
    program.items.iter().map(|item| item.name()).find(|ident| ident.name == name).map(|ident| ident.span)
}

/// Parses and validates WGSL with naga, as WebGPU requires (no optional
/// capabilities), on a thread with a large stack (see `validate::STACK`).
pub fn validate_wgsl(wgsl: &str) -> Result<(), String> {
    with_stack(|| naga_validate(wgsl)).map(|_| ()).map_err(|f| f.report)
}

/// Everything after the checks: interface, layout, kernels and their validation.
fn generate(
    source: &str,
    options: &Options,
    checked: &check::Checked,
    graph: &graph::EffectGraph,
    deriv: &deriv::DerivInfo,
    diagnostics: Vec<Diagnostic>,
) -> Result<Program, Vec<Diagnostic>> {
    let interface = interface::allocate(checked, graph);
    let costs = budget::evaluation_costs(checked, graph, deriv);
    let mut layout = layout::build(checked, graph, deriv, &interface, &costs);
    if options.storage_channels {
        layout::read_channels_from_storage(&mut layout);
    }
    layout.hierarchical.packed = options.packed_records;
    layout.tile = layout::tile_layout(&layout);
    let levels = options.modes.contains(&Mode::MultiRate).then(|| rates::levels(checked, graph));
    if let Some(levels) = &levels {
        layout.levels = Some(levels.layout(checked, layout::level_values_binding(checked)));
    }
    layout.plan = plan::build(&layout, &options.modes);
    let counters = codegen::counters(checked, graph);
    let inputs_of = |checked, graph, interface, level| codegen::Inputs {
        checked,
        graph,
        interface,
        deriv,
        layout: &layout,
        file_name: &options.file_name,
        compact: options.compact,
        source,
        // Each view writes its effects' functions differently: a cache of its own.
        cache: codegen::Cache::new(),
        counters: counters.clone(),
        level,
    };
    let inputs = inputs_of(checked, graph, &interface, codegen::ViewLevel::Program);
    let loaded: Vec<bool> =
        (0..checked.effects.len()).map(|i| rates::is_outer(checked, check::EffectId(i as u32))).collect();
    let views = levels.as_ref().map(|l| {
        let (values, words) = (l.values.as_slice(), l.words);
        let (o, i) = (&l.outer, &l.inner);
        (
            inputs_of(&o.checked, &o.graph, &o.interface, codegen::ViewLevel::Outer { values, words }),
            inputs_of(&i.checked, &i.graph, &i.interface, codegen::ViewLevel::Inner { values, words, loaded: &loaded }),
        )
    });
    let mut kernels = vec![];
    let mut memory = vec![];
    let wanted = options.kernels();
    let texts: Vec<(KernelKind, Option<u32>, String)> = wanted
        .into_iter()
        .map(|k| {
            let block = k.block.unwrap_or(1);
            let inputs = match (&views, k.kind) {
                (Some((outer, _)), KernelKind::MultiResolve) => outer,
                (Some((outer, _)), KernelKind::MultiCoarse) if block == mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK => {
                    outer
                }
                (Some((_, inner)), KernelKind::MultiCoarse | KernelKind::MultiFine) => inner,
                _ => &inputs,
            };
            (k.kind, k.block, codegen::write_string(inputs, k.kind, block))
        })
        .collect();
    // naga validation dominates compile time; the kernels are independent, so
    // they are validated in parallel, on as many threads as the machine runs.
    let wgsl: Vec<&str> = texts.iter().map(|(_, _, wgsl)| wgsl.as_str()).collect();
    let verdicts: Vec<Result<u32, NagaFailure>> = validate_all(&wgsl);
    for ((kind, block, wgsl), verdict) in texts.into_iter().zip(verdicts) {
        let workgroup_bytes = match verdict {
            Ok(bytes) => bytes,
            Err(failure) => {
                let what = match block {
                    Some(b) => format!("{} kernel ({b}x{b})", kind.name()),
                    None => format!("{} kernel", kind.name()),
                };
                return Err(vec![
                Diagnostic::bug(format!("internal compiler error: the generated {what} failed naga validation"))
                    .with_note(
                        "the program passed every check, so this is a bug in mrsl; please report it with the program",
                    )
                    .with_note(format!("naga: {}", failure.message))
                    .with_note(generated_context(&wgsl, failure.offset)),
            ]);
            }
        };
        kernels.push(Kernel { kind, block_size: block, wgsl });
        memory.push((KernelRef::new(kind, block), workgroup_bytes));
    }
    plan::set_workgroup_bytes(&mut layout.plan, &memory);
    Ok(Program { compiled: CompiledProgram::new(kernels, layout), warnings: diagnostics })
}

/// Parses and checks `source` (all stages that report diagnostics), then
/// hands the analyses and the warnings to `then`; errors stop before it.
fn front_end<R>(
    source: &str,
    then: impl FnOnce(&check::Checked, &graph::EffectGraph, &deriv::DerivInfo, Vec<Diagnostic>) -> R,
) -> Result<R, Vec<Diagnostic>> {
    stages(source, |analyses, diagnostics| match analyses {
        Some((checked, graph, deriv)) if !diagnostics.iter().any(|d| d.is_error()) => {
            Ok(then(checked, graph, deriv, diagnostics))
        }
        _ => Err(diagnostics),
    })
}

/// Runs every stage that reports diagnostics on `source` and hands `then`
/// the analyses, errors or not (`None` when the program does not parse or
/// is past the nesting limits), and every diagnostic, sorted. [`front_end`]
/// stops at errors; the tooling analysis ([`analyze`]) reads a program with
/// errors too.
fn stages<R>(
    source: &str,
    then: impl FnOnce(Option<(&check::Checked, &graph::EffectGraph, &deriv::DerivInfo)>, Vec<Diagnostic>) -> R,
) -> R {
    let program = match syntax::parse(source) {
        Ok(program) => program,
        Err(d) => return then(None, vec![d]),
    };
    // Before anything recurses over the tree: past the nesting limits, stop.
    let mut too_deep = limits::nesting(&program);
    if !too_deep.is_empty() {
        sort(&mut too_deep);
        return then(None, too_deep);
    }
    let (checked, mut diagnostics) = check::check(&program);
    let (graph, graph_diagnostics) = graph::build(&checked);
    diagnostics.extend(graph_diagnostics);
    let (deriv, deriv_diagnostics) = deriv::analyse(&checked);
    diagnostics.extend(deriv_diagnostics);
    diagnostics.extend(deriv::plain_surface_derivatives(&checked, &graph, &deriv));
    if !diagnostics.iter().any(|d| d.is_error()) {
        diagnostics.extend(limits::derivatives(&checked, &deriv));
    }
    // The size budget needs an acyclic, well-typed program whose derivative
    // operands are within the limits (which bound how deep it recurses).
    if !diagnostics.iter().any(|d| d.is_error()) {
        diagnostics.extend(budget::check(&checked, &graph, &deriv));
    }
    // Like W0001, said only of a program without errors.
    if !diagnostics.iter().any(|d| d.is_error()) {
        diagnostics.extend(deriv_warnings::warnings(&checked, &deriv));
    }
    sort(&mut diagnostics);
    then(Some((&checked, &graph, &deriv)), diagnostics)
}

fn sort(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by_key(|d| (d.span().map(|s| s.start).unwrap_or(u32::MAX), d.code));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The codes `front_end` reports for `source`, run on a 256 KiB stack
    /// rather than the one `check` and `compile` provide.
    fn front_end_on_a_small_stack(source: String) -> Vec<&'static str> {
        let run = move || {
            let diagnostics = front_end(&source, |_, _, _, warnings| warnings).unwrap_or_else(|errors| errors);
            diagnostics.iter().map(|d| d.code).collect()
        };
        std::thread::Builder::new().stack_size(256 << 10).spawn(run).expect("a thread starts").join().expect("no panic")
    }

    /// Nothing in the front end recurses along what the nesting limits do
    /// not bound (`tests/it/limits.rs` tests the limits themselves): a tree
    /// past them is measured and dropped without recursion, and chains of
    /// constants, effects and locals, which do not nest in the source, are
    /// followed without recursion, each link once.
    #[test]
    fn the_front_end_takes_long_inputs_on_a_small_stack() {
        let header = "in float3 normal;\n";
        let unary = format!("{header}fine out float o = {}normal.x;\n", "- + ".repeat(50_000));
        assert_eq!(front_end_on_a_small_stack(unary), ["E0602"]);
        let blocks =
            format!("{header}fine out float o {{\n o = 0.0;\n{}{}}}\n", "{\n".repeat(100_000), "}\n".repeat(100_000));
        assert_eq!(front_end_on_a_small_stack(blocks), ["E0603"]);
        let n = 3_000;
        let consts: String = (0..n).map(|k| format!("const float c{k} = c{} + 1.0;\n", k + 1)).collect();
        let consts = format!("{header}{consts}const float c{n} = 1.0;\nfine out float o = c0 * normal.x;\n");
        assert_eq!(front_end_on_a_small_stack(consts), [""; 0]);
        let chain: String = (1..n).map(|k| format!("fine effect float e{k} = e{} + 1.0;\n", k - 1)).collect();
        let chain = format!("{header}fine effect float e0 = normal.x;\n{chain}fine out float o = e{};\n", n - 1);
        assert_eq!(front_end_on_a_small_stack(chain), [""; 0]);
        let cycle: String = (0..n).map(|k| format!("fine effect float e{k} = e{} + 1.0;\n", (k + 1) % n)).collect();
        assert_eq!(front_end_on_a_small_stack(format!("{header}{cycle}fine out float o = e0;\n")), ["E0311"]);
        let derivative = |n: usize, step: &str| {
            let locals: String = (1..=n)
                .map(|k| format!("float a{k} = {};\n", step.replace("{prev}", &format!("a{}", k - 1))))
                .collect();
            format!(
                "{header}coarse effect float s {{\nfloat a0 = normal.x;\n{locals}s = ddx(a{n});\n}}\nfine out float o = s;\n"
            )
        };
        assert_eq!(front_end_on_a_small_stack(derivative(n, "{prev} * normal.y")), ["E0604"]);
        assert_eq!(front_end_on_a_small_stack(derivative(60, "{prev} * {prev}")), ["E0604"]);
        // The size budget counts along chains of functions and of effects
        // that differentiate the one before without recursing along them.
        let functions: String =
            (1..n).map(|k| format!("float f{k}(float x) {{ return f{}(x) + 1.0; }}\n", k - 1)).collect();
        let functions =
            format!("{header}float f0(float x) {{ return x; }}\n{functions}fine out float o = f{}(normal.x);\n", n - 1);
        // (3,000 calls inlined into one another exceed the budget.)
        assert_eq!(front_end_on_a_small_stack(functions), ["E0701"]);
        let differentiating: String =
            (1..n).map(|k| format!("coarse effect float e{k} = ddx(e{}) + e{};\n", k - 1, k - 1)).collect();
        let differentiating =
            format!("{header}coarse effect float e0 = normal.x;\n{differentiating}fine out float o = e{};\n", n - 1);
        assert_eq!(front_end_on_a_small_stack(differentiating), ["E0701"]);
    }
}
