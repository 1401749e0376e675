//! Well-typed programs from the grammar-aware generator
//! (compiler/tests/it/wellformed.rs), driven by the fuzzer's bytes: each must
//! pass every check with no diagnostic at all and compile to kernels naga
//! accepts, with no warning. The first input byte picks the kernels of one
//! mode to build (see `kernels.rs`); the rest drive the generator.
#![no_main]

mod kernels;
#[path = "../../tests/it/wellformed.rs"]
mod wellformed;

use arbitrary::Unstructured;
use libfuzzer_sys::fuzz_target;

struct Bytes<'a, 'b>(&'b mut Unstructured<'a>);

impl wellformed::Choices for Bytes<'_, '_> {
    fn below(&mut self, n: usize) -> usize {
        if n <= 1 { 0 } else { self.0.choose_index(n).unwrap_or(0) }
    }
}

fuzz_target!(|data: &[u8]| {
    let (choice, rest) = data.split_first().map_or((0, data), |(&b, rest)| (b as usize, rest));
    let options = kernels::options(choice);
    let mut u = Unstructured::new(rest);
    let source = wellformed::program(&mut Bytes(&mut u)).source;
    // The warnings the generator may draw (`wellformed::ALLOWED_WARNINGS`,
    // which a test keeps in step with the compiler's warnings).
    let allowed_warning = |d: &mrsl::Diagnostic| wellformed::ALLOWED_WARNINGS.contains(&d.code);
    let mut diagnostics = mrsl::check(&source);
    diagnostics.retain(|d| !allowed_warning(d));
    // E0701 (over the size budget) alone is a refusal by design that the
    // generator cannot foresee: its node budget does not see how calls and
    // derivative operands multiply once inlined (findings F17-F19). Such an
    // input is skipped; the corpus cases err/0081-0083 keep the diagnostic tested.
    if !diagnostics.is_empty() && diagnostics.iter().all(|d| d.code == "E0701") {
        return;
    }
    assert!(
        diagnostics.is_empty(),
        "a generated program has diagnostics:\n{source}\n{}",
        mrsl::render_all(&diagnostics, "generated.mrsl", &source)
    );
    match mrsl::compile(&source, &options) {
        Ok(program) => assert!(program.warnings.iter().all(allowed_warning), "a generated program warns:\n{source}"),
        Err(diagnostics) => panic!(
            "a generated program does not compile:\n{source}\n{}",
            mrsl::render_all(&diagnostics, "generated.mrsl", &source)
        ),
    }
});
