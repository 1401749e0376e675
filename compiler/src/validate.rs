//! naga validation, on a stack of its own, and the report of a kernel naga
//! rejects (E9000).
//!
//! Every kernel is parsed and validated by naga, as WebGPU requires. naga's
//! parser recurses once per level of nesting; `limits` keeps the generated
//! code within naga's limits, and [`STACK`] gives the recursion room, here
//! and for the compiler's own passes ([`with_stack`]), whatever the caller's
//! thread. A rejected kernel is a compiler bug; its report shows naga's
//! message and the generated lines where naga stopped
//! ([`generated_context`]), rather than naga's rendering, which shows a
//! deeply indented line as blank.

/// The stack the compiler and each naga validation run on, whatever the
/// caller's. The nesting limits (`limits`) bound how deep the compiler's
/// recursive passes and naga's parser go; what that takes depends on the
/// build. At the limits, a debug build needs about 3 MiB for the compiler's
/// passes and 12 MiB for naga (nested `for` loops around a deep
/// expression), more than the 2 MiB of a spawned thread or the 8 MiB of a
/// main thread; a release build needs a fraction. Untouched stack costs no
/// memory.
const STACK: usize = 64 << 20;

/// Runs `f` on a thread with a [`STACK`]-byte stack (on this thread if no
/// thread can be started), passing a panic on.
pub(crate) fn with_stack<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    let task = std::sync::Mutex::new(Some(f));
    let run = || {
        let f = task.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take();
        f.expect("the task runs once")()
    };
    std::thread::scope(|scope| {
        match std::thread::Builder::new().name("mrsl".into()).stack_size(STACK).spawn_scoped(scope, run) {
            Ok(handle) => handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            Err(_) => run(),
        }
    })
}

/// Why naga rejected a kernel.
pub(crate) struct NagaFailure {
    /// naga's own rendering, with the generated line.
    pub report: String,
    /// naga's message and notes, without the source.
    pub message: String,
    /// Where in the kernel, when naga says.
    pub offset: Option<usize>,
}

/// Parses and validates `wgsl`; on success, the bytes of workgroup memory it
/// declares ([`workgroup_bytes`]).
pub(crate) fn naga_validate(wgsl: &str) -> Result<u32, NagaFailure> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| {
        let mut message = e.message().to_string();
        for (_, label) in e.labels().filter(|(_, l)| !l.is_empty()) {
            message.push_str(&format!(" ({label})"));
        }
        for note in e.notes() {
            message.push_str(&format!("; {note}"));
        }
        NagaFailure {
            report: e.emit_to_string_with_path(wgsl, "generated.wgsl"),
            message,
            offset: e.location(wgsl).map(|l| l.offset as usize),
        }
    })?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| {
            let mut message = e.as_inner().to_string();
            let mut source = std::error::Error::source(e.as_inner());
            while let Some(cause) = source {
                message.push_str(&format!(": {cause}"));
                source = cause.source();
            }
            NagaFailure {
                report: e.emit_to_string_with_path(wgsl, "generated.wgsl"),
                message,
                offset: e.location(wgsl).map(|l| l.offset as usize),
            }
        })?;
    Ok(workgroup_bytes(&module))
}

/// The workgroup memory a module declares, as WebGPU counts it against
/// `maxComputeWorkgroupStorageSize`: each `var<workgroup>`'s size rounded up to 16 bytes.
fn workgroup_bytes(module: &naga::Module) -> u32 {
    let mut layouter = naga::proc::Layouter::default();
    if layouter.update(module.to_ctx()).is_err() {
        return 0;
    }
    module
        .global_variables
        .iter()
        .filter(|(_, g)| g.space == naga::AddressSpace::WorkGroup)
        .map(|(_, g)| layouter[g.ty].size.div_ceil(16) * 16)
        .sum()
}

/// Parses and validates each of `texts`, on at most as many threads as the
/// machine runs at once, each with a [`STACK`]-byte stack (or, if no thread
/// can be started, on this one). Not a thread per kernel: naga's module of
/// a large kernel takes tens of MB while it is validated, and seventeen at
/// once held about 1 GB at 1,000 effects on a 2-core machine, for no time
/// gained beyond its cores.
pub(crate) fn validate_all(texts: &[&str]) -> Vec<Result<u32, NagaFailure>> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(texts.len());
    let next = AtomicUsize::new(0);
    let verdicts: Vec<Mutex<Option<Result<u32, NagaFailure>>>> = texts.iter().map(|_| Mutex::new(None)).collect();
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(wgsl) = texts.get(k) else { break };
        let verdict =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| naga_validate(wgsl))).unwrap_or_else(|_| {
                let message = "naga panicked while validating".to_string();
                Err(NagaFailure { report: message.clone(), message, offset: None })
            });
        *verdicts[k].lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(verdict);
    };
    std::thread::scope(|scope| {
        let builder = || std::thread::Builder::new().name("mrsl-naga".into()).stack_size(STACK);
        let started = (0..workers).filter(|_| builder().spawn_scoped(scope, work).is_ok()).count();
        if started == 0 {
            work();
        }
    });
    verdicts
        .into_iter()
        .map(|v| v.into_inner().unwrap_or_else(|poisoned| poisoned.into_inner()).expect("every kernel is validated"))
        .collect()
}

/// The lines of `wgsl` around `offset` (or, without one, around the line that
/// nests deepest, where naga's recursion limit would strike), numbered, the
/// line itself marked, with deep indentation counted rather than shown.
pub(crate) fn generated_context(wgsl: &str, offset: Option<usize>) -> String {
    let lines: Vec<&str> = wgsl.lines().collect();
    let (line, column) = match offset {
        Some(offset) => {
            let offset = offset.min(wgsl.len());
            let before = &wgsl.as_bytes()[..offset];
            let line = before.iter().filter(|b| **b == b'\n').count();
            let start = before.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1);
            (line, offset - start)
        }
        None => deepest_line(&lines),
    };
    let mut out = format!("generated line {}, column {}:", line + 1, column + 1);
    let width = (line + 3).to_string().len();
    for (k, text) in lines.iter().enumerate().skip(line.saturating_sub(2)).take(5) {
        let indent = text.len() - text.trim_start().len();
        let body = text.trim_start();
        let shown_indent = if indent > 24 { format!("[{indent} columns of indentation] ") } else { " ".repeat(indent) };
        // Long lines: a window around the column on the marked line, the start elsewhere.
        const WINDOW: usize = 160;
        let from = if k == line { column.saturating_sub(indent).saturating_sub(WINDOW / 2) } else { 0 };
        let from = (0..=from.min(body.len())).rev().find(|&i| body.is_char_boundary(i)).unwrap_or(0);
        let to = (from + WINDOW).min(body.len());
        let to = (to..=body.len()).find(|&i| body.is_char_boundary(i)).unwrap_or(body.len());
        let head = if from > 0 { "…" } else { "" };
        let tail = if to < body.len() { "…" } else { "" };
        let mark = if k == line { '>' } else { ' ' };
        out.push_str(&format!("\n{mark} {:>width$} | {shown_indent}{head}{}{tail}", k + 1, &body[from..to]));
    }
    out
}

/// The line (0-based) where brackets and braces nest deepest, and the column there.
fn deepest_line(lines: &[&str]) -> (usize, usize) {
    let (mut depth, mut best) = (0i64, (i64::MIN, 0, 0));
    for (k, text) in lines.iter().enumerate() {
        for (column, c) in text.char_indices() {
            match c {
                '(' | '[' | '{' => depth += 1,
                ')' | ']' | '}' => depth -= 1,
                _ => {}
            }
            if depth > best.0 {
                best = (depth, k, column);
            }
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The note of an E9000 report, for a kernel naga rejects.
    fn note(wgsl: &str) -> String {
        let failure = with_stack(|| naga_validate(wgsl)).expect_err("naga rejects the kernel");
        format!("naga: {}\n{}", failure.message, generated_context(wgsl, failure.offset))
    }

    #[test]
    fn internal_errors_show_the_generated_line() {
        // Braces nested past WGSL's limit: naga names the brace, deep in indentation.
        let mut wgsl = "fn f() {\n".to_string();
        for k in 1..=128 {
            wgsl += &format!("{}{{\n", "    ".repeat(k));
        }
        for k in (0..=128).rev() {
            wgsl += &format!("{}}}\n", "    ".repeat(k));
        }
        let shown = note(&wgsl);
        assert!(shown.starts_with("naga: brace nesting limit reached"), "{shown}");
        assert!(shown.contains("generated line 128, column 509:"), "{shown}");
        assert!(shown.contains("> 128 | [508 columns of indentation] {"), "{shown}");
        assert!(shown.contains("  126 | [500 columns of indentation] {"), "{shown}");

        // Parentheses past naga's recursion limit: naga gives no place, the
        // note shows the line that nests deepest, cut around the deepest point.
        let deep = format!("{}1.0{}", "(".repeat(300), ")".repeat(300));
        let wgsl = format!("fn f() -> f32 {{\n    let x = 1.0;\n    return {deep};\n}}\n");
        let shown = note(&wgsl);
        assert!(shown.starts_with("naga: internal WGSL front end error; Parser recursion limit exceeded"), "{shown}");
        assert!(shown.contains("generated line 3, column 311:"), "{shown}");
        assert!(shown.contains("> 3 |     …((((("), "{shown}");
        assert!(shown.contains("1.0)))"), "{shown}");
        assert!(shown.contains("  2 |     let x = 1.0;"), "{shown}");
    }
}
