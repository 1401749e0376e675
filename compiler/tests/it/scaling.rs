//! Compile work that grows with the program, not faster: a generated program
//! of 1,000 coarse effects, held to bounds per effect that quadratic growth
//! breaks (not a timing assertion: sizes and expression counts).
//!
//! naga's WGSL front end takes time quadratic in the number of expressions
//! of one function (its typifier walks the function's expressions from the
//! first each time it grows), so a kernel function whose body grows with the
//! number of effects is what made compile time grow faster than the program
//! (issue 59: the hierarchical kernel's `mrsl_classify`, 200 expressions per
//! effect, took 19 s of naga's time at 1,000 effects; the fine kernels'
//! lanes, 57 to 83, 1.5 to 3.1 s each).

/// Coarse effects in the generated programs.
const EFFECTS: usize = 1000;

/// `n` independent coarse effects, each refining where its `fwidth` is
/// large, summed by the output as a balanced tree.
fn independent(n: usize) -> String {
    fn sum(terms: &[String]) -> String {
        match terms {
            [one] => one.clone(),
            _ => format!("({} + {})", sum(&terms[..terms.len() / 2]), sum(&terms[terms.len() / 2..])),
        }
    }
    let mut source = String::from("in float3 normal;\nin float2 uv;\nuniform float t = 0.05;\n");
    for k in 0..n {
        source.push_str(&format!(
            "coarse effect float e{k} {{\n    e{k} = saturate(dot(normal, float3(0.0, 1.0, 0.0)) + uv.x * {k}.0);\n    \
             if (fwidth(e{k}) > t) refine;\n}}\n"
        ));
    }
    let terms: Vec<String> = (0..n).map(|k| format!("e{k}")).collect();
    source.push_str(&format!("fine out float4 color = float4(float3({}), 1.0);\n", sum(&terms)));
    source
}

/// A chain of `n` coarse effects, each reading the one before.
fn chain(n: usize) -> String {
    let mut source = String::from("in float3 normal;\nin float2 uv;\nuniform float t = 0.05;\n");
    source.push_str("coarse effect float e0 {\n    e0 = saturate(normal.y);\n    if (fwidth(e0) > t) refine;\n}\n");
    for k in 1..n {
        source.push_str(&format!("coarse effect float e{k} = e{} * 0.5 + uv.x * 0.25;\n", k - 1));
    }
    source.push_str(&format!("fine out float4 color = float4(float3(e{}), 1.0);\n", n - 1));
    source
}

/// The largest number of expressions in one function (entry points
/// included) of a WGSL module, as naga's front end builds it.
fn largest_function(wgsl: &str) -> (usize, String) {
    let module = naga::front::wgsl::parse_str(wgsl).expect("the kernel parses");
    let functions = module.functions.iter().map(|(_, f)| (f.expressions.len(), f.name.clone().unwrap_or_default()));
    let entries = module.entry_points.iter().map(|e| (e.function.expressions.len(), e.name.clone()));
    functions.chain(entries).max().expect("a kernel has functions")
}

/// The hierarchical kernel of both programs: its size and its largest
/// function stay within a bound per effect. Before `mrsl_classify` called a
/// function per effect, its largest function took 202 expressions per
/// effect (independent effects) and 67 (the chain); now `mrsl_shade`, with
/// 21 and 11, is.
#[test]
fn a_thousand_effects_stay_within_bounds_per_effect() {
    let options = mrsl::Options::for_modes(&[mrsl::Mode::Hierarchical]);
    for (what, source) in [("independent", independent(EFFECTS)), ("chain", chain(EFFECTS))] {
        let program = match mrsl::compile(&source, &options) {
            Ok(p) => p,
            Err(d) => panic!("{what}:\n{}", mrsl::render_all(&d, "scaling.mrsl", &source)),
        };
        let kernel = program.kernel(mrsl::KernelKind::Hierarchical, 0).expect("a hierarchical kernel");
        let bytes = kernel.wgsl.len() / EFFECTS;
        assert!(bytes <= 8_000, "{what}: {bytes} bytes of WGSL per effect");
        let (expressions, function) = largest_function(&kernel.wgsl);
        assert!(expressions <= 40 * EFFECTS, "{what}: `{function}` has {expressions} expressions");
    }
}

/// Coarse effects in the generated programs compiled for every mode (fewer:
/// seventeen kernels in a debug build).
const EFFECTS_ALL_MODES: usize = 250;

/// Every kernel of every mode, for both programs: its largest function
/// stays within a bound per effect. Before each coarse effect's part of a
/// fine kernel's lanes became a function of its own (`mrsl_lane_<effect>`),
/// `fine_main`, `mrsl_tile_pixels` and `dynamic_fine_main` took 57, 57 and
/// 83 expressions per effect; the largest now take about 33 (the tile
/// kernel's `mrsl_corners`, per record word) and 28 (the rate-image
/// resolver).
#[test]
fn every_kernel_stays_within_bounds_per_effect() {
    let n = EFFECTS_ALL_MODES;
    for (what, source) in [("independent", independent(n)), ("chain", chain(n))] {
        let program = match mrsl::compile(&source, &mrsl::Options::default()) {
            Ok(p) => p,
            Err(d) => panic!("{what}:\n{}", mrsl::render_all(&d, "scaling.mrsl", &source)),
        };
        for kernel in &program.kernels {
            let (expressions, function) = largest_function(&kernel.wgsl);
            let name = format!("{what}, {:?} {:?}", kernel.kind, kernel.block_size);
            assert!(expressions <= 40 * n, "{name}: `{function}` has {expressions} expressions");
        }
    }
}
