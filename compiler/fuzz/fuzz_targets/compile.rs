//! The whole pipeline over arbitrary text: never panics, and a program that
//! passes the checks yields kernels naga accepts. An internal error (E9000,
//! `Severity::Bug`: a kernel naga rejected) is a finding, and so is a panic.
//! Each execution builds the kernels of one mode, chosen by a hash of the
//! input (see `kernels.rs`): a hash rather than one of the bytes, so that
//! the text the compiler sees is the input unchanged, and so that any
//! mutation may move a program to another kernel kind.
#![no_main]

mod kernels;

use libfuzzer_sys::fuzz_target;
use mrsl::Severity;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    // FNV-1a over the bytes.
    let hash = data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    let options = kernels::options((hash % kernels::CHOICES as u64) as usize);
    if let Err(diagnostics) = mrsl::compile(source, &options) {
        if diagnostics.iter().any(|d| d.severity == Severity::Bug) {
            panic!("internal compiler error:\n{}", mrsl::render_all(&diagnostics, "fuzz.mrsl", source));
        }
        let _ = mrsl::render_all(&diagnostics, "fuzz.mrsl", source);
    }
});
