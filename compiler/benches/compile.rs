//! Compile-time benchmarks for mrsl (see docs/performance.md; the runs are in docs/eval/compile-performance.md).
//!
//! Run with `cargo bench -p mrsl --bench compile [-- FILTER]`. Groups:
//!
//! * `examples`: full [`mrsl::compile`] (default options: the seventeen
//!   kernels, coarse and fine for block sizes 2 and 4, reference, dynamic
//!   coarse and fine, hierarchical, checkerboard, rate-image coarse and
//!   fine, each validated by naga) of every `examples/*.mrsl`.
//! * `generated`: a generated program of N effects (N = 25 .. 400) mixing
//!   refining coarse effects, chains, blocker/shadow pairs, fine effects and one
//!   output, measured at several depths: `check` (front end only), `interface`
//!   (slot allocation alone, on a pre-built checked program and graph),
//!   `compile_reference` (one mode: the reference kernel), `compile_coarse4x4`
//!   (one mode: the tile, coarse and fine 4x4 kernels), `compile_default` (the seventeen
//!   kernels), and `naga_validate` (naga parsing + validation of the seventeen
//!   kernels alone, one after the other: the part of `compile_default` that is
//!   not mrsl's own code).
//! * `growth`: the same program at N = 1,000 and 3,000 (`check`,
//!   `compile_reference`, `compile_coarse4x4`, `compile_default`): slow, run it
//!   on its own (`-- growth`).
//! * `chain`: `compile_default` of the derivative chain
//!   (`mrsl::internals::derivative_chain`) of length 2 to 12, whose neighbour
//!   evaluations once grew exponentially.
//! * `colouring`: [`mrsl::internals::colour`] alone on deterministic random
//!   graphs (~30% edge density) around the exact/heuristic cut-off
//!   ([`mrsl::internals::EXACT_LIMIT`]).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mrsl::internals::EffectId;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

/// Effect counts of the generated programs.
const EFFECT_COUNTS: [usize; 5] = [25, 50, 100, 200, 400];
/// Effect counts of the growth curve.
const GROWTH_COUNTS: [usize; 2] = [1000, 3000];
/// Lengths of the derivative chains.
const CHAIN_LENGTHS: [usize; 6] = [2, 4, 6, 8, 10, 12];
/// Node counts of the colouring graphs: 24 is the last exact size, 25 the first heuristic one.
const COLOUR_SIZES: [usize; 6] = [10, 20, 24, 25, 100, 400];

fn configure(group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_millis(2500));
}

/// Every `examples/*.mrsl`, sorted by file name: (stem, source).
fn examples() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "mrsl"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            let source = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("reading {}: {e}", p.display()));
            (name, source)
        })
        .collect()
}

/// One generated effect: its declaration, its width, and the effects it reads.
struct Generated {
    name: String,
    components: u32,
    reads: Vec<usize>,
    decl: String,
}

/// A program of exactly `n` effects plus one output.
///
/// Effects come in blocks of eight, `b` being the block number:
///
/// | # | effect | rate   | refines | reads        | role                                   |
/// |---|--------|--------|---------|--------------|----------------------------------------|
/// | 0 | `r{b}` | coarse | fwidth  | inputs       | chain head, also read by a fine effect |
/// | 1 | `a{b}` | coarse | value   | `r{b}`       | chain link                             |
/// | 2 | `c{b}` | coarse | fwidth  | `a{b}`       | chain tail (float3), a leaf            |
/// | 3 | `k{b}` | coarse | no      | inputs       | blocker: read only by the shadow       |
/// | 4 | `s{b}` | coarse | band    | `k{b}`       | shadow: refines in its penumbra        |
/// | 5 | `f{b}` | fine   | -       | `r{b}`       | per-pixel term (float3), a leaf        |
/// | 6 | `p{b}` | coarse | no      | inputs       | smooth coarse term (float2)            |
/// | 7 | `g{b}` | fine   | -       | `p{b}, s{b}` | per-pixel combination, a leaf          |
///
/// The output sums every effect nobody else reads (the leaves), so every effect
/// is live; when `n` is not a multiple of 8 the last block is cut short and its
/// unread effects become leaves too.
fn generate(n: usize) -> String {
    let mut effects: Vec<Generated> = Vec::with_capacity(n);
    for i in 0..n {
        let b = i / 8;
        let base = b * 8;
        let scale = format!("{:.2}", 0.25 * ((b % 7) + 1) as f32);
        let (name, components, reads, decl) = match i % 8 {
            0 => {
                let r = format!("r{b}");
                let decl = format!(
                    "coarse effect float {r} {{\n    {r} = saturate(dot(normal, light) * {scale});\n    if (fwidth({r}) > t) refine;\n}}"
                );
                (r, 1, vec![], decl)
            }
            1 => {
                let a = format!("a{b}");
                let decl = format!(
                    "coarse effect float {a} {{\n    {a} = r{b} * 0.5 + normal.y * {scale};\n    if ({a} > t) refine;\n}}"
                );
                (a, 1, vec![base], decl)
            }
            2 => {
                let c = format!("c{b}");
                let decl = format!(
                    "coarse effect float3 {c} {{\n    {c} = float3(a{b}) * normal + sky;\n    if (fwidth({c}.x) > t) refine;\n}}"
                );
                (c, 3, vec![base + 1], decl)
            }
            3 => {
                let k = format!("k{b}");
                let decl = format!("coarse effect float {k} = uv.x * {scale} + normal.x * 0.5;");
                (k, 1, vec![], decl)
            }
            4 => {
                let s = format!("s{b}");
                let decl = format!(
                    "coarse effect float {s} {{\n    {s} = saturate(k{b} + normal.z);\n    if ({s} > 0.02 && {s} < 0.98) refine;\n}}"
                );
                (s, 1, vec![base + 3], decl)
            }
            5 => {
                let f = format!("f{b}");
                let decl = format!("fine effect float3 {f} = float3(uv, 1.0) * r{b};");
                (f, 3, vec![base], decl)
            }
            6 => {
                let p = format!("p{b}");
                let decl = format!("coarse effect float2 {p} = uv * normal.xy * {scale};");
                (p, 2, vec![], decl)
            }
            _ => {
                let g = format!("g{b}");
                let decl = format!("fine effect float {g} = length(p{b}) * s{b};");
                (g, 1, vec![base + 6, base + 4], decl)
            }
        };
        effects.push(Generated { name, components, reads, decl });
    }
    let mut read = vec![false; n];
    for e in &effects {
        for &r in &e.reads {
            read[r] = true;
        }
    }
    let mut src = String::from(
        "in float3 normal;\nin float2 uv;\n\
         uniform float t = 0.1;\n\
         uniform float3 light = float3(0.0, 1.0, 0.0);\n\
         uniform float3 sky = float3(0.1, 0.15, 0.2);\n\n",
    );
    for e in &effects {
        src.push_str(&e.decl);
        src.push('\n');
    }
    let leaves: Vec<String> = effects
        .iter()
        .zip(&read)
        .filter(|(_, read)| !**read)
        .map(|(e, _)| match e.components {
            1 => format!("float3({})", e.name),
            2 => format!("float3({}, 0.0)", e.name),
            _ => e.name.clone(),
        })
        .collect();
    src.push_str(&format!("fine out float4 color = float4({}, 1.0);\n", balanced_sum(&leaves)));
    src
}

/// `terms` summed as a balanced tree, `((a + b) + (c + d))`, so that the
/// expression nests only logarithmically deep however many leaves there are.
fn balanced_sum(terms: &[String]) -> String {
    match terms {
        [] => "float3(0.0)".to_string(),
        [one] => one.clone(),
        _ => {
            let (left, right) = terms.split_at(terms.len() / 2);
            format!("({} + {})", balanced_sum(left), balanced_sum(right))
        }
    }
}

/// One mode's kernels: the reference mode.
fn options_reference() -> mrsl::Options {
    mrsl::Options::for_modes(&[mrsl::Mode::Reference])
}

/// One mode's kernels: the coarse 4x4 mode (coarse and fine kernels for 4x4 blocks).
fn options_coarse4x4() -> mrsl::Options {
    mrsl::Options::for_modes(&[mrsl::Mode::Coarse4x4])
}

/// Panics with the rendered diagnostics if `source` does not compile.
fn assert_compiles(name: &str, source: &str, options: &mrsl::Options) {
    if let Err(diagnostics) = mrsl::compile(source, options) {
        panic!("benchmark program {name} does not compile:\n{}", mrsl::render_all(&diagnostics, name, source));
    }
}

fn bench_examples(c: &mut Criterion) {
    let options = mrsl::Options::default();
    let examples = examples();
    assert!(!examples.is_empty(), "no examples/*.mrsl found");
    let mut group = c.benchmark_group("examples");
    configure(&mut group);
    for (name, source) in &examples {
        assert_compiles(name, source, &options);
        group.bench_with_input(BenchmarkId::from_parameter(name), source, |bench, source| {
            bench.iter(|| mrsl::compile(black_box(source), black_box(&options)))
        });
    }
    group.finish();
}

fn bench_generated(c: &mut Criterion) {
    let default = mrsl::Options::default();
    let reference = options_reference();
    let coarse4x4 = options_coarse4x4();
    let mut group = c.benchmark_group("generated");
    configure(&mut group);
    for n in EFFECT_COUNTS {
        let source = generate(n);
        let name = format!("generated_{n}");
        assert_compiles(&name, &source, &default);

        group.bench_with_input(BenchmarkId::new("check", n), &source, |bench, source| {
            bench.iter(|| mrsl::check(black_box(source)))
        });

        // The same sequence as `mrsl::compile`, stopped before allocation.
        let program = mrsl::internals::parse(&source).expect("generated program parses");
        let (checked, _) = mrsl::internals::check_ast(&program);
        let (graph, _) = mrsl::internals::build_graph(&checked);
        let interface = mrsl::internals::allocate_interface(&checked, &graph);
        eprintln!(
            "generated/{n}: {} bytes of source, {} passed effects, {} interference edges, {} slots, stride {} words, exact: {}",
            source.len(),
            interface.slot_of.iter().flatten().count(),
            interface.interference.len(),
            interface.slots.len(),
            interface.stride,
            interface.exact
        );
        group.bench_function(BenchmarkId::new("interface", n), |bench| {
            bench.iter(|| mrsl::internals::allocate_interface(black_box(&checked), black_box(&graph)))
        });

        for (what, options) in
            [("compile_reference", &reference), ("compile_coarse4x4", &coarse4x4), ("compile_default", &default)]
        {
            group.bench_with_input(BenchmarkId::new(what, n), &source, |bench, source| {
                bench.iter(|| mrsl::compile(black_box(source), black_box(options)))
            });
        }

        // naga's share of `compile_default`: parsing and validating the seventeen kernels.
        let kernels: Vec<String> = mrsl::compile(&source, &default)
            .expect("generated program compiles")
            .compiled
            .kernels
            .into_iter()
            .map(|k| k.wgsl)
            .collect();
        let bytes = kernels.iter().map(String::len).sum::<usize>();
        eprintln!("generated/{n}: {bytes} bytes of WGSL in {} kernels", kernels.len());
        group.bench_with_input(BenchmarkId::new("naga_validate", n), &kernels, |bench, kernels| {
            bench.iter(|| {
                for wgsl in kernels {
                    mrsl::validate_wgsl(black_box(wgsl)).expect("valid WGSL");
                }
            })
        });
    }
    group.finish();
}

/// The growth curve: the generated program at 1,000 and 3,000 effects.
fn bench_growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("growth");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(100));
    group.measurement_time(Duration::from_millis(1000));
    for n in GROWTH_COUNTS {
        let source = generate(n);
        group.bench_with_input(BenchmarkId::new("check", n), &source, |bench, source| {
            bench.iter(|| mrsl::check(black_box(source)))
        });
        for (what, options) in [
            ("compile_reference", options_reference()),
            ("compile_coarse4x4", options_coarse4x4()),
            ("compile_default", mrsl::Options::default()),
        ] {
            group.bench_with_input(BenchmarkId::new(what, n), &source, |bench, source| {
                bench.iter(|| mrsl::compile(black_box(source), black_box(&options)))
            });
        }
    }
    group.finish();
}

/// The derivative chain of each length, all seventeen kernels.
fn bench_chain(c: &mut Criterion) {
    let options = mrsl::Options::default();
    let mut group = c.benchmark_group("chain");
    configure(&mut group);
    for n in CHAIN_LENGTHS {
        let source = mrsl::internals::derivative_chain(n);
        assert_compiles(&format!("chain_{n}"), &source, &options);
        group.bench_with_input(BenchmarkId::new("compile_default", n), &source, |bench, source| {
            bench.iter(|| mrsl::compile(black_box(source), black_box(&options)))
        });
    }
    group.finish();
}

/// A deterministic random graph: `n` nodes of width 1..=4, each pair joined
/// with probability ~30%.
fn random_graph(n: usize, seed: u64) -> (Vec<EffectId>, Vec<u32>, Vec<(EffectId, EffectId)>) {
    let mut state = seed;
    let mut next = move || {
        // xorshift64: deterministic and dependency-free.
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let nodes: Vec<EffectId> = (0..n as u32).map(EffectId).collect();
    let sizes: Vec<u32> = (0..n).map(|_| 1 + (next() % 4) as u32).collect();
    let mut edges = vec![];
    for a in 0..n {
        for b in a + 1..n {
            if next() % 100 < 30 {
                edges.push((nodes[a], nodes[b]));
            }
        }
    }
    (nodes, sizes, edges)
}

fn bench_colouring(c: &mut Criterion) {
    let mut group = c.benchmark_group("colouring");
    configure(&mut group);
    for n in COLOUR_SIZES {
        let (nodes, sizes, edges) = random_graph(n, 0x2545_F491_4F6C_DD1D ^ n as u64);
        let (classes, exact) = mrsl::internals::colour(&nodes, &sizes, &edges);
        let width: u32 = classes.iter().map(|c| c.iter().map(|&k| sizes[k]).max().unwrap_or(0)).sum();
        eprintln!("colouring/{n}: {} edges, {} slots, {width} words, exact: {exact}", edges.len(), classes.len());
        group.bench_function(BenchmarkId::from_parameter(n), |bench| {
            bench.iter(|| mrsl::internals::colour(black_box(&nodes), black_box(&sizes), black_box(&edges)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_examples, bench_generated, bench_chain, bench_colouring, bench_growth);
criterion_main!(benches);
