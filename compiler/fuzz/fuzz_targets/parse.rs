//! The parser over arbitrary text: never panics; a syntax error is an error
//! diagnostic with ordered spans, and it renders.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    if let Err(diagnostic) = mrsl::internals::parse(source) {
        assert!(diagnostic.is_error(), "a syntax diagnostic is an error");
        for label in &diagnostic.labels {
            assert!(label.span.start <= label.span.end, "reversed span");
        }
        let _ = mrsl::render_all(&[diagnostic], "fuzz.mrsl", source);
    }
});
