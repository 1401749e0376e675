//! Kernel sizes and pipeline-creation times of the derivative chain
//! (`mrsl::internals::derivative_chain`), or of the programs given, on the
//! first adapter wgpu finds (lavapipe on a machine without a GPU). The
//! figures in docs/eval/compile-performance.md come from this program:
//!
//! ```sh
//! cargo run --release -p mrslc --example pipelines                # chains of length 2 to 12
//! cargo run --release -p mrslc --example pipelines -- 2 4 6       # chosen lengths
//! cargo run --release -p mrslc --example pipelines -- prog.mrsl   # a program of your own
//! ```
//!
//! For each program it compiles the default kernels once, then builds the
//! pipelines of each kernel on its own (`Shader::new` over a program holding
//! that kernel alone: WGSL parsing by wgpu's naga, SPIR-V, and the driver's
//! compilation, which for lavapipe is LLVM) and prints one markdown row per
//! kernel: WGSL bytes and lines, and the time. Mesa's on-disk shader cache
//! is turned off, so every pipeline is compiled. Nothing here is asserted:
//! timings depend on the machine.

use mrsl_lab::gpu::Gpu;
use mrsl_runtime::{CompiledProgram, Shader};
use std::time::Instant;

fn main() {
    // Before any thread exists: every pipeline is compiled, none comes from the cache.
    unsafe { std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true") };
    // And no "XDG_RUNTIME_DIR is invalid" line from Mesa (see mrsl_lab::runtime_dir).
    // SAFETY: still before any thread exists.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut programs: Vec<(String, String)> = vec![];
    for arg in &args {
        match arg.parse::<usize>() {
            Ok(n) => programs.push((format!("chain {n}"), mrsl::internals::derivative_chain(n))),
            Err(_) => programs.push((arg.clone(), std::fs::read_to_string(arg).expect("reading the program"))),
        }
    }
    if programs.is_empty() {
        programs = (2..=12).map(|n| (format!("chain {n}"), mrsl::internals::derivative_chain(n))).collect();
    }
    let gpu = Gpu::new().expect("a GPU adapter (or lavapipe)");
    eprintln!("device: {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    println!("| program | operations (costliest effect) | compile (ms) | kernel | bytes | lines | pipelines (ms) |");
    println!("|---|---:|---:|---|---:|---:|---:|");
    for (name, source) in &programs {
        let operations = match mrsl::internals::inlined_operations(source) {
            Some((total, costliest)) => format!("{total} ({costliest})"),
            None => "-".to_string(),
        };
        let start = Instant::now();
        let program = match mrsl::compile(source, &mrsl::Options::default()) {
            Ok(program) => program,
            Err(diagnostics) => {
                println!("| {name} | {operations} | | does not compile: {} | | | |", diagnostics[0].code);
                continue;
            }
        };
        let compile_ms = start.elapsed().as_secs_f64() * 1e3;
        let mut total = 0.0;
        let (mut bytes, mut lines) = (0, 0);
        for kernel in &program.kernels {
            let alone = CompiledProgram::new(vec![kernel.clone()], program.layout.clone());
            let start = Instant::now();
            Shader::new(&gpu.device, &alone).expect("pipelines");
            let ms = start.elapsed().as_secs_f64() * 1e3;
            total += ms;
            bytes += kernel.wgsl.len();
            lines += kernel.wgsl.lines().count();
            println!(
                "| {name} | {operations} | {compile_ms:.1} | {} | {} | {} | {ms:.0} |",
                kernel.file_name("k").trim_start_matches("k.").trim_end_matches(".wgsl"),
                kernel.wgsl.len(),
                kernel.wgsl.lines().count()
            );
        }
        println!(
            "| **{name}** | {operations} | {compile_ms:.1} | all {} | {bytes} | {lines} | {total:.0} |",
            program.kernels.len()
        );
    }
}
