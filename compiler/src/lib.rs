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

mod budget;
mod builtins;
mod check;
mod codegen;
mod deriv;
mod diagnostic;
mod graph;
mod interface;
mod layout;
mod syntax;
mod types;

pub use diagnostic::{Diagnostic, Label, Severity, emit_colored, render_all};
pub use mrsl_abi::{CompiledProgram, Kernel, KernelKind, Layout};

/// The stages behind [`compile`], for the compiler's own benchmarks and tests
/// only: not part of the API, and free to change with the stages.
#[doc(hidden)]
pub mod internals {
    pub use crate::budget::{MAX_EFFECT_OPERATIONS, MAX_PROGRAM_OPERATIONS};
    pub use crate::check::{EffectId, check as check_ast};
    pub use crate::graph::build as build_graph;
    pub use crate::interface::{EXACT_LIMIT, allocate as allocate_interface, colour};
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
    /// once grew exponentially with `n` (see docs/performance.md).
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

/// Which kernels to generate, and for which block sizes.
///
/// [`compile`] generates and validates only the kernels these options ask
/// for ([`Options::kernels`]). The default asks for all nine: coarse and
/// fine for blocks 2 and 4, the reference, the dynamic mode's coarse (2x2)
/// and fine (4x4) kernels, the hierarchical and the checkerboard kernel.
/// A caller that runs fewer modes asks for their kernels alone, which takes
/// a fraction of the time: `Options { block_sizes: vec![4], coarse: true,
/// fine: true, ..Options::none() }` for the coarse 4x4 mode (the runtime's
/// `compile_modes` does this from its modes).
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Coarse block sizes to generate coarse and fine kernels for (2 and/or 4).
    pub block_sizes: Vec<u32>,
    pub coarse: bool,
    pub fine: bool,
    pub reference: bool,
    /// The dynamic mode's kernels (4x4, refined to 2x2, then per pixel).
    pub dynamic: bool,
    /// The hierarchical (DACS) mode's kernel.
    pub hierarchical: bool,
    /// The checkerboard baseline's kernel.
    pub checkerboard: bool,
    /// Name written in the header comment of every generated kernel.
    pub file_name: String,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            block_sizes: vec![2, 4],
            coarse: true,
            fine: true,
            reference: true,
            dynamic: true,
            hierarchical: true,
            checkerboard: true,
            file_name: "program.mrsl".into(),
        }
    }
}

impl Options {
    /// The kernels [`compile`] generates with these options, in generation
    /// order: per block size the coarse and fine kernels, then the
    /// reference, the dynamic mode's (its 4x4 level is the ordinary 4x4
    /// coarse kernel, added if not asked for already), the hierarchical and
    /// the checkerboard kernel. The block size is `None` for the kinds that
    /// exist once per program.
    pub fn kernels(&self) -> Vec<(KernelKind, Option<u32>)> {
        let mut wanted = vec![];
        for &b in &self.block_sizes {
            if self.coarse {
                wanted.push((KernelKind::Coarse, Some(b)));
            }
            if self.fine {
                wanted.push((KernelKind::Fine, Some(b)));
            }
        }
        if self.reference {
            wanted.push((KernelKind::Reference, None));
        }
        if self.dynamic {
            let (outer, inner) = (mrsl_abi::geometry::DYNAMIC_OUTER_BLOCK, mrsl_abi::geometry::DYNAMIC_INNER_BLOCK);
            if !wanted.contains(&(KernelKind::Coarse, Some(outer))) {
                wanted.push((KernelKind::Coarse, Some(outer)));
            }
            wanted.push((KernelKind::DynamicCoarse, Some(inner)));
            wanted.push((KernelKind::DynamicFine, Some(outer)));
        }
        if self.hierarchical {
            wanted.push((KernelKind::Hierarchical, None));
        }
        if self.checkerboard {
            wanted.push((KernelKind::Checkerboard, None));
        }
        wanted
    }

    /// Options that ask for no kernel at all; set the flags of the kernels wanted.
    pub fn none() -> Options {
        Options {
            block_sizes: vec![],
            coarse: false,
            fine: false,
            reference: false,
            dynamic: false,
            hierarchical: false,
            checkerboard: false,
            ..Options::default()
        }
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
pub fn check(source: &str) -> Vec<Diagnostic> {
    front_end(source, |_, _, _, warnings| warnings).unwrap_or_else(|errors| errors)
}

/// Compiles a program to kernels and a layout, or returns its diagnostics
/// (errors, and warnings found alongside them).
pub fn compile(source: &str, options: &Options) -> Result<Program, Vec<Diagnostic>> {
    if let Some(bad) = options.block_sizes.iter().find(|b| !BLOCK_SIZES.contains(b)) {
        return Err(vec![
            Diagnostic::error("E0900", format!("unsupported block size {bad}"))
                .with_note("supported block sizes: 2, 4"),
        ]);
    }
    front_end(source, |checked, graph, deriv, diagnostics| {
        generate(source, options, checked, graph, deriv, diagnostics)
    })?
}

/// Parses and validates WGSL with naga, as WebGPU requires (no optional capabilities).
pub fn validate_wgsl(wgsl: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| e.emit_to_string_with_path(wgsl, "generated.wgsl"))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| e.emit_to_string_with_path(wgsl, "generated.wgsl"))?;
    Ok(())
}

/// Block sizes the generated kernels support.
const BLOCK_SIZES: [u32; 2] = [2, 4];

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
    let layout = layout::build(checked, graph, &interface);
    let inputs = codegen::Inputs {
        checked,
        graph,
        interface: &interface,
        deriv,
        layout: &layout,
        file_name: &options.file_name,
        source,
        cache: codegen::Cache::new(source),
    };
    let mut kernels = vec![];
    let wanted = options.kernels();
    let texts: Vec<(KernelKind, Option<u32>, String)> = wanted
        .into_iter()
        .map(|(kind, block)| (kind, block, codegen::write_string(&inputs, kind, block.unwrap_or(1))))
        .collect();
    // naga validation dominates compile time; the kernels are independent, so
    // they are validated on as many threads as there are kernels.
    let verdicts: Vec<Result<(), String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = texts.iter().map(|(_, _, wgsl)| scope.spawn(move || validate_wgsl(wgsl))).collect();
        handles.into_iter().map(|h| h.join().unwrap_or_else(|_| Err("naga panicked while validating".into()))).collect()
    });
    for ((kind, block, wgsl), verdict) in texts.into_iter().zip(verdicts) {
        if let Err(message) = verdict {
            let what = match block {
                Some(b) => format!("{} kernel ({b}x{b})", kind.name()),
                None => format!("{} kernel", kind.name()),
            };
            return Err(vec![
                Diagnostic::bug(format!("internal compiler error: the generated {what} failed naga validation"))
                    .with_note(
                        "the program passed every check, so this is a bug in mrsl; please report it with the program",
                    )
                    .with_note(message),
            ]);
        }
        kernels.push(Kernel { kind, block_size: block, wgsl });
    }
    Ok(Program { compiled: CompiledProgram::new(kernels, layout), warnings: diagnostics })
}

/// Parses and checks `source` (all stages that report diagnostics), then
/// hands the analyses and the warnings to `then`; errors stop before it.
fn front_end<R>(
    source: &str,
    then: impl FnOnce(&check::Checked, &graph::EffectGraph, &deriv::DerivInfo, Vec<Diagnostic>) -> R,
) -> Result<R, Vec<Diagnostic>> {
    let program = syntax::parse(source).map_err(|d| vec![d])?;
    let (checked, mut diagnostics) = check::check(&program);
    let (graph, graph_diagnostics) = graph::build(&checked);
    diagnostics.extend(graph_diagnostics);
    let (deriv, deriv_diagnostics) = deriv::analyse(&checked);
    diagnostics.extend(deriv_diagnostics);
    // The size budget needs an acyclic, well-typed program.
    if !diagnostics.iter().any(|d| d.is_error()) {
        diagnostics.extend(budget::check(&checked, &graph, &deriv));
    }
    sort(&mut diagnostics);
    if diagnostics.iter().any(|d| d.is_error()) {
        return Err(diagnostics);
    }
    Ok(then(&checked, &graph, &deriv, diagnostics))
}

fn sort(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by_key(|d| (d.span().map(|s| s.start).unwrap_or(u32::MAX), d.code));
}
