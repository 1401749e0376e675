//! The whole pipeline over arbitrary text, with one block size to keep each
//! run short: never panics, and a program that passes the checks yields
//! kernels naga accepts. An internal error (E9000, `Severity::Bug`: a kernel
//! naga rejected) is a finding, and so is a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mrsl::{Options, Severity};

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    let options = Options { block_sizes: vec![4], ..Options::default() };
    if let Err(diagnostics) = mrsl::compile(source, &options) {
        if diagnostics.iter().any(|d| d.severity == Severity::Bug) {
            panic!("internal compiler error:\n{}", mrsl::render_all(&diagnostics, "fuzz.mrsl", source));
        }
        let _ = mrsl::render_all(&diagnostics, "fuzz.mrsl", source);
    }
});
