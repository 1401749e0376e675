//! Every check over arbitrary text: never panics, never reports an internal
//! error (`check` generates no code, so it has no reason to), and every
//! diagnostic renders.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mrsl::Severity;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    let diagnostics = mrsl::check(source);
    assert!(!diagnostics.iter().any(|d| d.severity == Severity::Bug), "internal error from check");
    let _ = mrsl::render_all(&diagnostics, "fuzz.mrsl", source);
});
