//! The lexer over arbitrary text: never panics, and every token and error
//! span lies inside the source, on character boundaries, in increasing order.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mrsl::internals::Lexer;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    let mut last_end = 0;
    for item in Lexer::new(source) {
        let (start, end) = match &item {
            Ok((start, token, end)) => {
                let _ = token.to_string();
                (*start, *end)
            }
            Err(e) => (e.start, e.end),
        };
        assert!(last_end <= start && start <= end && end <= source.len(), "span {start}..{end} after {last_end}");
        assert!(
            source.is_char_boundary(start) && source.is_char_boundary(end),
            "span {start}..{end} splits a character"
        );
        last_end = end;
    }
});
