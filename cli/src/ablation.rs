//! `mrslc bench --ablation`: where a block mode's time goes.
//!
//! The fine kernel of a block mode (coarse 2x2 or 4x4) is rebuilt with one
//! part removed at a time, by editing the generated WGSL line by line, and
//! each variant is timed against the full kernel and the reference in
//! interleaved rounds (the order rotates every round). A variant's figure is
//! the median over the rounds of its time divided by the full kernel's time
//! in the same round, so the shared machine's slow moments weigh on both.
//!
//! The edits match the lines the code generator writes (its templates in
//! `compiler/src/codegen/templates/`); a variant whose lines the program's
//! kernel does not have (a program without keys has no key tests) is left
//! out and says so. The variants only drop work: their images are wrong by
//! design and are never compared.

use crate::setup::{Resources, WORKLOAD_PROGRAM, bind_scene, compile_program};
use crate::timing::{median, time_run};
use anyhow::{Context, Result, anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};
use mrsl_abi::{CompiledProgram, KernelKind};
use mrsl_lab::gpu::Gpu;
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::fmt::Write as _;
use std::path::PathBuf;

pub struct AblationArgs {
    pub program: Option<PathBuf>,
    pub scene: String,
    pub size: (u32, u32),
    pub mode: Mode,
    pub runs: usize,
    pub out_dir: PathBuf,
}

/// An edit of the fine kernel's lines (`None` when the kernel has none of
/// the lines it edits).
type Edit = fn(&str) -> Option<String>;

/// One variant: a name, what it removes, and the edits that make it.
struct Variant {
    name: &'static str,
    removes: &'static str,
    edits: &'static [Edit],
}

/// Applies `f` to every line; `None` when it changed none.
fn edit_lines(wgsl: &str, f: impl Fn(&str) -> Option<String>) -> Option<String> {
    let mut changed = false;
    let mut out = String::with_capacity(wgsl.len());
    for line in wgsl.lines() {
        match f(line) {
            Some(new) => {
                changed = true;
                out.push_str(&new);
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    changed.then_some(out)
}

/// The indentation of `line`.
fn indent(line: &str) -> &str {
    &line[..line.len() - line.trim_start().len()]
}

/// The statistics atomics, their barrier and the refine-mask store: the
/// blocks a dispatch with `DispatchOptions::statistics` off skips, removed
/// from the text (the full kernel and the other variants run with them).
fn no_instrumentation(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        (l.trim_start() == "if (mrsl_ctl.statistics != 0u) {").then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// No coarse effect is evaluated per pixel: every one is resampled (and
/// in the compacted kernel, no pixel is listed for evaluation).
fn nothing_refined(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("if (mrsl_is_refined(mrsl_b, ") && t.contains("mrsl_cq[") {
            return Some(String::new());
        }
        if let Some((todo, _)) = t.strip_prefix("var mrsl_todo_").and_then(|r| r.split_once(" = ")) {
            // The block fine kernel's loops over a lane's refined pixels.
            return Some(format!("{}var mrsl_todo_{todo} = 0u;", indent(l)));
        }
        (t.starts_with("if (mrsl_is_refined(mrsl_b, ") && t.ends_with(")) {"))
            .then(|| format!("{}if (false) {{", indent(l)))
    })
}

/// No coarse effect is evaluated per pixel, but the evaluation branches stay
/// in the kernel behind a per-pixel condition only the run time knows to be
/// false (no pixel has a negative position): what a branch that no lane
/// takes still costs where a SIMD machine cannot tell it is untaken.
fn nothing_refined_at_run_time(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if let Some((todo, pixels)) = t.strip_prefix("var mrsl_todo_").and_then(|r| r.split_once(" = ")) {
            let pixels = pixels.strip_suffix(';')?;
            return Some(format!("{}var mrsl_todo_{todo} = ({pixels}) & select(0u, 3u, mrsl_first.x < 0);", indent(l)));
        }
        let cond = t.strip_prefix("if (mrsl_is_refined(mrsl_b, ")?.strip_suffix(")) {")?;
        Some(format!("{}if (mrsl_is_refined(mrsl_b, {cond}) && mrsl_pos.x < 0) {{", indent(l)))
    })
}

/// The key loads and comparisons of the resolve: every corner on each
/// pixel's side of every key (`side_<key>` all true), or
/// in the kernels that refine a whole block at an edge, `disc_<key>` false.
fn no_key_tests(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        if let Some(name) = t.strip_prefix("let side_").and_then(|r| r.split(' ').next()) {
            return Some(format!("{}let side_{name} = vec4<bool>(true);", indent(l)));
        }
        let name = t.strip_prefix("let disc_")?.split(' ').next()?;
        Some(format!("{}let disc_{name} = false;", indent(l)))
    })
}

/// The corners' refine-flag words of the resolve (read as zero).
fn no_flag_reads(w: &str) -> Option<String> {
    edit_lines(w, |l| {
        let t = l.trim_start();
        let (lhs, rhs) = t.strip_prefix("let f")?.split_once(" = ")?;
        // Read from the buffer, or from the lane's preloaded corners (`c.w<word>`).
        let read = rhs.starts_with("mrsl_interface[") || rhs.starts_with("c.w");
        (read && lhs.contains('_')).then(|| format!("{}let f{lhs} = 0u;", indent(l)))
    })
}

/// The resampling of the coarse effects (they read zero): each resampling
/// function of the preloaded corners returns its type's zero value, and
/// elsewhere the calls are dropped.
fn no_resampling(w: &str) -> Option<String> {
    let returned = std::cell::RefCell::new(None::<String>);
    edit_lines(w, |l| {
        let t = l.trim_start();
        if t.starts_with("fn mrsl_resample_") && t.contains("c: MrslCorners") {
            *returned.borrow_mut() = t.rsplit_once("-> ").map(|(_, ty)| ty.trim_end_matches(" {").to_string());
            return None;
        }
        if t.starts_with("return ")
            && let Some(ty) = returned.borrow_mut().take()
        {
            return Some(format!("{}return {ty}();", indent(l)));
        }
        let resamples = t.ends_with("(mrsl_b);") || t.ends_with("(mrsl_b, mrsl_c);");
        (t.contains(" = mrsl_resample_") && resamples && !t.starts_with("let ")).then(String::new)
    })
}

/// Everything the fine pass does per pixel.
fn no_fine_work(w: &str) -> Option<String> {
    edit_lines(w, |l| match l.trim_start() {
        // The guard of each pixel (a block fine kernel's lane has several).
        t if t.starts_with("if (all(") && t.ends_with(" < mrsl_grid())) {") => {
            Some(format!("{}if (false && {}", indent(l), &t["if (".len()..]))
        }
        "let mrsl_in = all(mrsl_pos < mrsl_grid());" => Some(format!("{}let mrsl_in = false;", indent(l))),
        // The block fine kernel's pixels (`mrsl_in<k>`): nothing is stored,
        // so nothing is computed.
        t if t.starts_with("let mrsl_in") && t.ends_with(" < mrsl_grid());") => {
            let name = t["let ".len()..].split(' ').next()?;
            Some(format!("{}let {name} = false;", indent(l)))
        }
        _ => None,
    })
}

/// The variants. Removing the key tests or the flag reads from the full
/// kernel would also change what is refined, so those parts are measured
/// within the fixed cost (nothing refined), where they decide nothing.
const VARIANTS: [Variant; 7] = [
    Variant {
        name: "no instrumentation",
        removes: "the statistics atomics, their barrier and the refine-mask store (`DispatchOptions::statistics` off)",
        edits: &[no_instrumentation],
    },
    Variant {
        name: "nothing refined (fixed cost)",
        removes: "the per-pixel re-evaluation of refined coarse effects: every pixel resolves and resamples",
        edits: &[nothing_refined],
    },
    Variant {
        name: "nothing refined at run time",
        removes: "the same re-evaluations, but their branches stay, untaken by a per-pixel test: what a SIMD machine runs of a branch no lane takes",
        edits: &[nothing_refined_at_run_time],
    },
    Variant {
        name: "fixed cost, no key tests",
        removes: "also the discontinuity-key loads and comparisons of the resolve",
        edits: &[nothing_refined, no_key_tests],
    },
    Variant {
        name: "fixed cost, no flag reads",
        removes: "also the corners' refine-flag words of the resolve",
        edits: &[nothing_refined, no_flag_reads],
    },
    Variant {
        name: "fixed cost, no resampling",
        removes: "also the resampling of the coarse effects (they read zero)",
        edits: &[nothing_refined, no_resampling],
    },
    Variant {
        name: "no fine pass work",
        removes: "everything the fine pass does per pixel (left: the coarse pass and the launches)",
        edits: &[no_fine_work],
    },
];

/// A variant's fine kernel, or `None` when one of its edits has nothing to edit.
fn apply(variant: &Variant, wgsl: &str) -> Option<String> {
    variant.edits.iter().try_fold(wgsl.to_string(), |w, edit| edit(&w))
}

/// `program` with the block fine kernel of size `block` refining nothing
/// ([`nothing_refined`]): the block mode's fixed cost, which `bench --suite`
/// reports as its floor. `None` when the kernel has nothing to edit.
pub fn refining_nothing(program: &CompiledProgram, block: u32) -> Option<CompiledProgram> {
    let fine = program.kernel(KernelKind::Fine, block)?;
    let wgsl = nothing_refined(&fine.wgsl)?;
    let mut p = program.clone();
    for k in p.kernels.iter_mut().filter(|k| k.kind == KernelKind::Fine && k.block_size == Some(block)) {
        k.wgsl = wgsl.clone();
    }
    Some(p)
}

/// The full kernel, the compacted one and the variants that apply, each
/// as a whole program: (name, what it removes, program).
type Programs = Vec<(&'static str, &'static str, CompiledProgram)>;

/// Runs the ablation; returns the files written.
pub fn ablation(args: &AblationArgs) -> Result<Vec<PathBuf>> {
    let block = match args.mode {
        Mode::Coarse2x2 => 2,
        Mode::Coarse4x4 => 4,
        other => bail!("--ablation takes a block mode (coarse2x2 or coarse4x4), not {other}"),
    };
    let modes = [Mode::Reference, args.mode];
    let (name, program) = compile_program(args.program.as_deref(), ("sponza_lights.mrsl", WORKLOAD_PROGRAM), &modes)?;
    let (programs, skipped) = variants(args, &name, &program, block)?;
    let gpu = Gpu::new()?;
    let device_name = format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    eprintln!("ablation: {name}, {} fine kernel, on {device_name}, {}x{}", args.mode, args.size.0, args.size.1);
    let mut scene = bind_scene(&gpu, &args.scene, Some(args.size))?;
    let mut shaders = vec![];
    let mut textures = vec![];
    for (k, (_, _, p)) in programs.iter().enumerate() {
        let mut shader = Shader::new(&gpu.device, p)?;
        let prepared = scene.prepare(&gpu, &mut shader).map_err(|e| anyhow!("{}: {e}", args.scene))?;
        // The variants declare the uniforms of the first: its warnings are theirs, printed once.
        textures = if k == 0 { prepared.warn() } else { prepared.textures };
        shaders.push(shader);
    }
    let resources = Resources::new(&gpu, &program, scene.size, textures, mrsl_abi::shading_rate::DEFAULT_RATE_TILE)?;
    let bindings: Bindings = resources.bindings(&program, &scene.channels);
    // Entry 0 is the reference (run with the full program's shader), then
    // the full kernel, then the variants.
    let runs: Vec<(usize, Mode)> =
        std::iter::once((0, Mode::Reference)).chain((0..programs.len()).map(|k| (k, args.mode))).collect();
    let times = time_rounds(args.runs.max(1), &runs, |k, mode| {
        time_run(&gpu, &mut shaders[k], &bindings, DispatchOptions::new(mode))
    })?;
    let md = markdown(args, &name, &device_name, &programs, &skipped, &times);
    std::fs::create_dir_all(&args.out_dir).map_err(|e| anyhow!("cannot create {}: {e}", args.out_dir.display()))?;
    let path = args.out_dir.join("ablation.md");
    crate::output::write(&path, &md)?;
    println!("{md}");
    Ok(vec![path])
}

/// The full program, the same compiled with the fine pass compacted
/// (`Options::compact`), and one program per variant whose edits apply;
/// the names of those whose edits do not.
fn variants(
    args: &AblationArgs,
    name: &str,
    program: &mrsl::Program,
    block: u32,
) -> Result<(Programs, Vec<&'static str>)> {
    let full: &CompiledProgram = program;
    let fine = full.kernel(KernelKind::Fine, block).context("the program has no fine kernel")?;
    let mut programs: Programs = vec![("full", "nothing", full.clone())];
    let source = match &args.program {
        Some(path) => crate::read_source(path)?,
        None => WORKLOAD_PROGRAM.to_string(),
    };
    let modes = [Mode::Reference, args.mode];
    let options = mrsl::Options { compact: true, file_name: name.to_string(), ..mrsl::Options::for_modes(&modes) };
    let compacted = mrsl::compile(&source, &options).map_err(|d| anyhow!(mrsl::render_all(&d, name, &source)))?;
    programs.push((
        "compacted (added)",
        "nothing; adds the workgroup compaction: refined pixels re-evaluate together on consecutive lanes",
        compacted.compiled.clone(),
    ));
    let mut skipped = vec![];
    for v in &VARIANTS {
        match apply(v, &fine.wgsl) {
            Some(wgsl) => {
                let mut p = full.clone();
                for k in p.kernels.iter_mut().filter(|k| k.kind == KernelKind::Fine && k.block_size == Some(block)) {
                    k.wgsl = wgsl.clone();
                }
                programs.push((v.name, v.removes, p));
            }
            None => skipped.push(v.name),
        }
    }
    Ok((programs, skipped))
}

/// Times every entry of `runs` once to warm up, then in `rounds`
/// interleaved rounds whose order rotates each round; the times per entry.
fn time_rounds(
    rounds: usize,
    runs: &[(usize, Mode)],
    mut time: impl FnMut(usize, Mode) -> Result<f64>,
) -> Result<Vec<Vec<f64>>> {
    for &(k, mode) in runs {
        time(k, mode)?;
    }
    let bar = ProgressBar::new(rounds as u64).with_style(
        ProgressStyle::with_template("ablation [{bar:30}] {pos}/{len} rounds ({elapsed})")?.progress_chars("=> "),
    );
    let mut times: Vec<Vec<f64>> = vec![vec![]; runs.len()];
    for round in 0..rounds {
        for j in 0..runs.len() {
            let at = (j + round) % runs.len();
            let (k, mode) = runs[at];
            times[at].push(time(k, mode)?);
        }
        if bar.is_hidden() {
            eprintln!("ablation: round {}/{rounds}", round + 1);
        }
        bar.inc(1);
    }
    bar.finish();
    Ok(times)
}

/// The ablation report: per entry of `times` (the reference, then
/// `programs`), its median time and its median ratio to the full kernel's
/// time in the same round.
fn markdown(
    args: &AblationArgs,
    name: &str,
    device_name: &str,
    programs: &Programs,
    skipped: &[&str],
    times: &[Vec<f64>],
) -> String {
    let rounds = times[1].len();
    let ratio = |at: usize| median((0..rounds).map(|r| times[at][r] / times[1][r]).collect());
    let full_ms = median(times[1].clone());
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Ablation of the {} fine pass\n\nProgram `{name}`, scene {}, {}x{}, device {device_name}; {rounds} interleaved \
         rounds (the order rotates each round); `x full` is the median over the rounds of the variant's time / the full \
         kernel's time in the same round. Full kernel: {full_ms:.1} ms (median).\n",
        args.mode, args.scene, args.size.0, args.size.1
    );
    let _ = writeln!(md, "| variant | removes | median ms | x full | saved |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    let _ = writeln!(
        md,
        "| reference | (the per-pixel reference mode) | {:.1} | {:.3} | |",
        median(times[0].clone()),
        ratio(0)
    );
    for (k, (variant, removes, _)) in programs.iter().enumerate() {
        let at = k + 1;
        let r = ratio(at);
        let saved = if k == 0 { String::new() } else { format!("{:.1}%", 100.0 * (1.0 - r)) };
        let _ = writeln!(md, "| {variant} | {removes} | {:.1} | {r:.3} | {saved} |", median(times[at].clone()));
    }
    if !skipped.is_empty() {
        let _ = writeln!(md, "\nNot applicable to this program's kernel: {}.", skipped.join(", "));
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every variant edits the kernel the code generator writes for the
    /// workload, so a template change that breaks an edit fails here.
    #[test]
    fn every_variant_edits_the_workload_kernel() {
        let program = mrsl::compile(WORKLOAD_PROGRAM, &mrsl::Options::default()).unwrap();
        for block in [2, 4] {
            let fine = &program.kernel(KernelKind::Fine, block).unwrap().wgsl;
            for v in &VARIANTS {
                let edited = apply(v, fine).unwrap_or_else(|| panic!("{}: no line to edit", v.name));
                assert_ne!(&edited, fine, "{}", v.name);
                mrsl::validate_wgsl(&edited).unwrap_or_else(|e| panic!("{} (block {block}): {e}", v.name));
            }
            // The compacted kernel takes the edits that apply to it too.
            let compacted =
                mrsl::compile(WORKLOAD_PROGRAM, &mrsl::Options { compact: true, ..Default::default() }).unwrap();
            let fine = &compacted.kernel(KernelKind::Fine, block).unwrap().wgsl;
            let unlisted = nothing_refined(fine).expect("the compacted kernel lists pixels");
            assert!(!unlisted.contains("atomicAdd(&mrsl_cq_n["), "nothing refined still lists pixels");
            for edit in [nothing_refined, no_fine_work, no_instrumentation] {
                let edited = edit(fine).expect("the compacted kernel has the lines");
                mrsl::validate_wgsl(&edited).unwrap();
            }
        }
    }
}
