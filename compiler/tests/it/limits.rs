//! Nesting limits and stack safety: programs far past every limit (a sum of
//! 100,000 terms, 100,000 chained unary operators, 10,000 nested calls,
//! conditionals, `if`s, blocks and loops, long chains of locals, constants
//! and effects) get a diagnostic with a span, and programs exactly at a
//! limit compile, never with an internal error (E9000) and never with a
//! stack overflow, from a thread with a 2 MiB stack (a spawned thread's
//! default) as from one with 8 MiB (a main thread's). The inputs are
//! generated here; the corpus holds small cases at the limits
//! (`data/err/0061` to `0071`, `data/ok/0052`).

use mrsl::{Diagnostic, Options, Severity};

/// A spawned thread's default stack, and a main thread's.
const STACKS: [usize; 2] = [2 << 20, 8 << 20];

/// Runs `f` on a new thread with a `stack`-byte stack.
fn on_stack<R: Send>(stack: usize, f: impl FnOnce() -> R + Send) -> R {
    std::thread::scope(|scope| {
        std::thread::Builder::new().stack_size(stack).spawn_scoped(scope, f).expect("a test thread starts").join()
    })
    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
}

fn codes(diagnostics: &[Diagnostic]) -> Vec<&'static str> {
    diagnostics.iter().map(|d| d.code).collect()
}

/// Asserts that `check` and `compile` both report exactly `expected` (codes,
/// in order), each diagnostic with a span, on both stacks.
#[track_caller]
fn assert_rejected(what: &str, source: &str, expected: &[&str]) {
    for stack in STACKS {
        let checked = on_stack(stack, || mrsl::check(source));
        assert_eq!(codes(&checked), expected, "{what}: `check` on a {} MiB stack", stack >> 20);
        for d in &checked {
            assert!(d.span().is_some(), "{what}: {} without a span", d.code);
        }
        let compiled = on_stack(stack, || mrsl::compile(source, &Options::default()));
        let diagnostics = compiled.err().unwrap_or_else(|| panic!("{what}: compiled"));
        assert_eq!(diagnostics, checked, "{what}: `compile` and `check` disagree");
    }
}

/// Asserts that `source` compiles (so naga validated every kernel) and that
/// `check` finds nothing, from a 2 MiB stack: the compiler's own passes and
/// naga's run on stacks of their own (`mrsl::compile`'s documentation).
#[track_caller]
fn assert_compiles(what: &str, source: &str) {
    let [small, _] = STACKS;
    let checked = on_stack(small, || mrsl::check(source));
    assert_eq!(codes(&checked), Vec::<&str>::new(), "{what}: `check`");
    if let Err(d) = on_stack(small, || mrsl::compile(source, &Options::default())) {
        assert!(!d.iter().any(|d| d.severity == Severity::Bug), "{what}: internal error");
        panic!("{what} should compile:\n{}", mrsl::render_all(&d, "limits.mrsl", source));
    }
}

const HEADER: &str = "in float3 normal;\nuniform bool flag;\nuniform int k;\n";

/// An output whose value is `value`.
fn output(value: &str) -> String {
    format!("{HEADER}fine out float o = {value};\n")
}

/// An output whose block body is `body`.
fn block_output(body: &str) -> String {
    format!("{HEADER}fine out float o {{\n    o = 0.0;\n{body}\n}}\n")
}

fn sum(terms: usize) -> String {
    vec!["normal.x"; terms].join(" + ")
}

/// `n` unary operators, alternately `-` and `+`, before `normal.x`.
fn unary(n: usize) -> String {
    format!("{}normal.x", &"- + ".repeat(n.div_ceil(2))[..2 * n])
}

fn calls(n: usize, inner: &str) -> String {
    format!("{}{inner}{}", "abs(".repeat(n), ")".repeat(n))
}

fn conditionals(n: usize) -> String {
    format!("{}normal.x{}", "flag ? 1.0 : (".repeat(n), ")".repeat(n))
}

/// `n` nested `if`s around `inner`.
fn ifs(n: usize, inner: &str) -> String {
    format!("{}{inner}{}", "if (flag) {\n".repeat(n), "}\n".repeat(n))
}

fn blocks(n: usize) -> String {
    format!("{}o = 1.0;\n{}", "{\n".repeat(n), "}\n".repeat(n))
}

fn loops(n: usize, inner: &str) -> String {
    let heads: String = (0..n).map(|k| format!("for (int i{k} = 0; i{k} < 1; i{k}++) {{\n")).collect();
    format!("{heads}{inner}{}", "}\n".repeat(n))
}

/// `if (...) ... else if (...) ...` with `n` branches.
fn else_ifs(n: usize) -> String {
    let branches: Vec<String> = (0..n).map(|k| format!("if (normal.x > {k}.0) o = {k}.0;")).collect();
    branches.join("\nelse ")
}

/// A coarse effect differentiating `a<n>`, where `a<k>` is computed from `a<k-1>`
/// by `step` (with `{prev}` for `a<k-1>`).
fn derivative_chain(n: usize, step: &str) -> String {
    let locals: String =
        (1..=n).map(|k| format!("    float a{k} = {};\n", step.replace("{prev}", &format!("a{}", k - 1)))).collect();
    format!(
        "{HEADER}coarse effect float slope {{\n    float a0 = normal.x;\n{locals}    if (ddx(a{n}) > 0.0) refine;\n    slope = a0;\n}}\n\
         fine out float4 color = float4(slope);\n"
    )
}

#[test]
fn huge_sum() {
    assert_rejected("a sum of 100,000 terms", &output(&sum(100_000)), &["E0602"]);
}

#[test]
fn huge_chain_of_unary_operators() {
    assert_rejected("100,000 unary operators", &output(&unary(100_000)), &["E0602"]);
}

#[test]
fn huge_nesting_of_calls_and_conditionals() {
    assert_rejected("10,000 nested calls", &output(&calls(10_000, "normal.x")), &["E0602"]);
    assert_rejected("5,000 nested `?:`", &output(&conditionals(5_000)), &["E0602"]);
    let nested_derivatives = format!("{}normal.x{}", "ddx(".repeat(2_000), ")".repeat(2_000));
    assert_rejected(
        "2,000 nested `ddx`",
        &format!("{HEADER}coarse effect float c = {nested_derivatives};\nfine out float o = c;\n"),
        &["E0602"],
    );
    let swizzles = format!("{HEADER}fine out float3 o = normal{};\n", ".zyx".repeat(10_000));
    assert_rejected("10,000 swizzles", &swizzles, &["E0602"]);
}

#[test]
fn huge_nesting_of_statements() {
    assert_rejected("10,000 nested `if`s", &block_output(&ifs(10_000, "o = 1.0;\n")), &["E0603"]);
    assert_rejected("100,000 nested blocks", &block_output(&blocks(100_000)), &["E0603"]);
    assert_rejected("2,000 nested `for`s", &block_output(&loops(2_000, "o += 1.0;\n")), &["E0603"]);
    assert_rejected("2,000 `else if`s", &block_output(&else_ifs(2_000)), &["E0603"]);
}

/// Chains whose links are not nested in the source; longer ones run on a
/// small stack in the compiler's unit tests (`lib.rs`), without the stack
/// `check` and `compile` give the compiler.
#[test]
fn long_chains_of_definitions() {
    // Before: the derivative analysis recursed once per local, walked every
    // path through locals read twice, and code generation never finished a
    // local read by its own definition.
    assert_rejected("2,000 chained locals", &derivative_chain(2_000, "{prev} * normal.y"), &["E0604"]);
    assert_rejected("40 locals, each read twice", &derivative_chain(40, "{prev} * {prev}"), &["E0604"]);
    let own = format!(
        "{HEADER}coarse effect float slope {{\n    float a;\n    a = a + normal.x;\n    slope = ddx(a);\n}}\n\
         fine out float4 color = float4(slope);\n"
    );
    assert_rejected("a local read by its own definition", &own, &["E0503"]);
    // Constants declared last first; a cycle of effects.
    let n = 2_000;
    let consts: String = (0..n).map(|k| format!("const float c{k} = c{} + 1.0;\n", k + 1)).collect();
    let source = format!("{HEADER}{consts}const float c{n} = 1.0;\nfine out float o = c0 * normal.x;\n");
    for stack in STACKS {
        assert_eq!(on_stack(stack, || mrsl::check(&source)), vec![], "2,000 constants, last first");
    }
    let effects: String = (0..n).map(|k| format!("fine effect float e{k} = e{} + 1.0;\n", (k + 1) % n)).collect();
    assert_rejected("a cycle of 2,000 effects", &format!("{HEADER}{effects}fine out float o = e0;\n"), &["E0311"]);
}

/// A lattice of 40 diamonds of coarse effects behind a discontinuity key,
/// none of whose values reads a derivative: whether one does through the
/// effects it reads (edge-aware resampling, docs/language.md section 8.3)
/// is decided once per effect. A recursion over the dependencies, which
/// stops only at a derivative, revisited the shared ones 2^40 times and
/// never finished.
#[test]
fn a_lattice_of_diamonds_compiles() {
    let mut source = String::from("@key(0.3) in float3 normal;\ncoarse effect float a0 = normal.y;\n");
    for k in 1..=40 {
        let prev = k - 1;
        source.push_str(&format!(
            "coarse effect float b{k} = a{prev} + normal.x;\ncoarse effect float c{k} = a{prev} * 0.5;\n\
             coarse effect float a{k} = b{k} + c{k};\n"
        ));
    }
    source.push_str("fine out float4 color = float4(a40, 0.0, 0.0, 1.0);\n");
    assert_compiles("40 diamonds of coarse effects", &source);
}

/// One level (or brace, or operation) less than each case above compiles;
/// the limit itself is E0602/E0603/E0604.
#[test]
fn at_the_limits() {
    // An output `= value;` is written `return value;`: the value is at level 2, 126 levels left.
    assert_compiles("127 terms", &output(&sum(127)));
    assert_rejected("128 terms", &output(&sum(128)), &["E0602"]);
    // `-(x)` is two levels to Tint, `(x)` for `+` one: 42 of each.
    assert_compiles("84 unary operators", &output(&unary(84)));
    assert_rejected("85 unary operators", &output(&unary(85)), &["E0602"]);
    assert_compiles("126 nested calls", &output(&calls(126, "normal.x")));
    assert_rejected("127 nested calls", &output(&calls(127, "normal.x")), &["E0602"]);
    // The innermost condition, a bool uniform, is compared with zero: one level more.
    assert_compiles("125 nested `?:`", &output(&conditionals(125)));
    assert_rejected("126 nested `?:`", &output(&conditionals(126)), &["E0602"]);
    // An `int` shift amount is converted, `(a << u32(b))`: one level more.
    let shifts = |n: usize| format!("{HEADER}fine out int o = {}k{};\n", "k << (".repeat(n), ")".repeat(n));
    assert_compiles("63 nested shifts", &shifts(63));
    assert_rejected("64 nested shifts", &shifts(64), &["E0602"]);
    // A scalar argument splatted to a vector: `max(v, vec3<f32>(s))`.
    let splats = |n: usize| {
        format!("{HEADER}fine out float3 o = {}normal{};\n", "max(normal, length(".repeat(n), "))".repeat(n))
    };
    assert_compiles("42 levels of splatted calls", &splats(42));
    assert_rejected("43 levels of splatted calls", &splats(43), &["E0602"]);
    // Field accesses cost the parsers nothing; the compiler's passes take 398 nodes.
    let swizzles = |n: usize| format!("{HEADER}fine out float3 o = normal{};\n", ".zyx".repeat(n));
    assert_compiles("397 swizzles", &swizzles(397));
    assert_rejected("398 swizzles", &swizzles(398), &["E0602"]);
    // An effect's statements are at brace level 2: 124 more levels.
    assert_compiles("124 nested `if`s", &block_output(&ifs(124, "o = 1.0;\n")));
    assert_rejected("125 nested `if`s", &block_output(&ifs(125, "o = 1.0;\n")), &["E0603"]);
    assert_compiles("124 nested blocks", &block_output(&blocks(124)));
    assert_rejected("125 nested blocks", &block_output(&blocks(125)), &["E0603"]);
    // Each `else if` is written inside the `else` before it.
    assert_compiles("an `if` and 123 `else if`s", &block_output(&else_ifs(124)));
    assert_rejected("an `if` and 124 `else if`s", &block_output(&else_ifs(125)), &["E0603"]);
    // A function's statements are at brace level 1: 125 more levels.
    let function = |body: &str| {
        format!(
            "{HEADER}float f(float x) {{\n    float o = x;\n{body}    return o;\n}}\nfine out float o = f(normal.x);\n"
        )
    };
    assert_compiles("125 nested `for`s in a function", &function(&loops(125, "o += 1.0;\n")));
    assert_rejected("126 nested `for`s in a function", &function(&loops(126, "o += 1.0;\n")), &["E0603"]);
    // The statements around an expression count: inside 60 `for`s in an
    // effect, `o += value;` stands at level 62 and its value at 63.
    let deep = |n: usize| block_output(&loops(60, &format!("o += {};\n", calls(n, "normal.x"))));
    assert_compiles("65 calls inside 60 `for`s", &deep(65));
    assert_rejected("66 calls inside 60 `for`s", &deep(66), &["E0602"]);
    // An `if` condition is parenthesised, `if ((a > b)) {`: at level 4 in an effect.
    let condition = |n: usize| block_output(&format!("if ({} > 0.0) {{ o = 1.0; }}", calls(n, "normal.x")));
    assert_compiles("a condition of 123 calls", &condition(123));
    assert_rejected("a condition of 124 calls", &condition(124), &["E0602"]);
    // A constant is written at module scope, its value at level 1.
    let constant = |n: usize| {
        format!("{HEADER}const float scale = {};\nfine out float o = scale * normal.x;\n", vec!["1.0"; n].join(" + "))
    };
    assert_compiles("a constant of 128 terms", &constant(128));
    assert_rejected("a constant of 129 terms", &constant(129), &["E0602"]);
    // A derivative operand is recomputed with its locals inlined: two levels per local.
    assert_compiles("a derivative through 62 locals", &derivative_chain(62, "{prev} * normal.y"));
    assert_rejected("a derivative through 63 locals", &derivative_chain(63, "{prev} * normal.y"), &["E0604"]);
    // ... and each use of a local copies its definition: at most 4096 operations.
    let [small, _] = STACKS;
    let doubling = derivative_chain(9, "{prev} * {prev}");
    assert_eq!(on_stack(small, || mrsl::check(&doubling)), vec![], "a derivative of 2558 operations");
    assert_rejected("a derivative of 5118 operations", &derivative_chain(10, "{prev} * {prev}"), &["E0604"]);
}

/// A function may declare 255 parameters (WGSL's limit); an effect that
/// reads more effects than that passes them packed into structures, so no
/// generated function declares more either.
#[test]
fn parameters_stay_within_wgsl_s_limit() {
    let function = |n: usize| {
        let params: Vec<String> = (0..n).map(|k| format!("float p{k}")).collect();
        let args = vec!["normal.x"; n].join(", ");
        format!("{HEADER}float f({}) {{ return p0; }}\nfine out float o = f({args});\n", params.join(", "))
    };
    assert_compiles("a function of 255 parameters", &function(255));
    assert_rejected("a function of 256 parameters", &function(256), &["E0605"]);
    let n = 1100;
    let mut source = String::from(HEADER);
    for k in 0..n {
        source.push_str(&format!("coarse effect float e{k} = normal.x * {k}.0;\n"));
    }
    let reads: String = (0..n).map(|k| format!("    o += e{k};\n")).collect();
    source.push_str(&format!("fine out float o {{\n    o = 0.0;\n{reads}}}\n"));
    // One mode's kernels: validating eleven kernels of 1,100 functions each would take minutes in a debug build.
    let options = Options::for_modes(&[mrsl::Mode::Coarse4x4]);
    let program = mrsl::compile(&source, &options).expect("a program reading 1,100 effects compiles");
    for kernel in &program.kernels {
        let widest = kernel.wgsl.lines().filter(|l| l.starts_with("fn ")).map(|l| l.matches(": ").count()).max();
        assert!(widest.unwrap_or(0) <= 256, "{}: a function with {widest:?} typed names", kernel.kind);
    }
    let fine = program.kernel(mrsl::KernelKind::Fine, 4).unwrap();
    assert!(fine.wgsl.contains("struct MrslArgs1_o {"), "1,100 dependencies take two structures");
}
