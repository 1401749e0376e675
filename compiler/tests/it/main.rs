//! The compiler's integration tests, in one binary (see tests/README.md).

mod corpus;
mod examples;
mod fuzz;
mod interface;

/// Compiles with default options, panicking with rendered diagnostics on failure.
#[track_caller]
pub fn compile_ok(source: &str) -> mrsl::Program {
    match mrsl::compile(source, &mrsl::Options::default()) {
        Ok(p) => p,
        Err(d) => panic!("expected the program to compile:\n{}", mrsl::render_all(&d, "test.mrsl", source)),
    }
}
