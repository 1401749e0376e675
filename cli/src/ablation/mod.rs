//! `mrslc bench --ablation`: where a mode's time goes.
//!
//! The kernel that does a mode's adaptive work (the fine kernel of coarse
//! 2x2 or 4x4, [`block`]; the hierarchical kernel, [`hierarchical`]) is
//! rebuilt with one part removed at a time (for the block modes the coarse
//! pass too, with the fine pass emptied: [`coarse`]), by editing the generated WGSL
//! line by line, and
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

use crate::setup::{DeviceProgram, Resources, WORKLOAD_PROGRAM, bind_scene, compile_for_device};
use crate::timing::{median, time_run};
use anyhow::{Context, Result, anyhow, bail};

mod block;
mod coarse;
mod hierarchical;

pub use block::refining_nothing;
pub use hierarchical::shading_nothing;
use indicatif::{ProgressBar, ProgressStyle};
use mrsl_abi::{CompiledProgram, Device, KernelKind};
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
    /// The block modes' plan to edit and time (`None`: the device's own).
    pub plan: Option<Device>,
}

/// An edit of the kernel's lines (`None` when the kernel has none of
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

/// What an ablation edits: the fine kernel of a block size, or the
/// hierarchical kernel.
#[derive(Clone, Copy)]
enum Target {
    Block(u32),
    Hierarchical,
}

impl Target {
    fn of(mode: Mode) -> Result<Target> {
        Ok(match mode {
            Mode::Coarse2x2 => Target::Block(2),
            Mode::Coarse4x4 => Target::Block(4),
            Mode::Hierarchical => Target::Hierarchical,
            other => bail!("--ablation takes coarse2x2, coarse4x4 or hierarchical, not {other}"),
        })
    }

    /// The kernel the variants edit, as `(kind, block size)`, in the mode's
    /// plan on `device`: for the block modes the fine kernel (CPU devices)
    /// or the tile kernel (GPUs), whose pixels are the fine kernel's code.
    fn kernel(self, device: Device) -> (KernelKind, Option<u32>) {
        match (self, device) {
            (Target::Block(block), Device::Cpu) => (KernelKind::Fine, Some(block)),
            (Target::Block(block), Device::Gpu) => (KernelKind::Tile, Some(block)),
            (Target::Hierarchical, _) => (KernelKind::Hierarchical, None),
        }
    }

    fn variants(self) -> &'static [Variant] {
        match self {
            Target::Block(_) => &block::VARIANTS,
            Target::Hierarchical => &hierarchical::VARIANTS,
        }
    }

    /// What the report calls the edited kernel.
    fn what(self) -> &'static str {
        match self {
            Target::Block(_) => "fine kernel (or tile kernel)",
            Target::Hierarchical => "hierarchical kernel",
        }
    }

    /// The edited kernel with its mode: "the coarse4x4 fine kernel", "the
    /// coarse4x4 tile kernel", "the hierarchical kernel" (whose name already
    /// says its mode).
    fn title(self, mode: impl std::fmt::Display, device: Device) -> String {
        match self {
            Target::Block(_) => format!("{mode} {} kernel ({} plan)", self.kernel(device).0.name(), device.name()),
            Target::Hierarchical => self.what().to_string(),
        }
    }
}

/// `program` with its `target` kernel replaced by `wgsl`.
fn with_kernel(program: &CompiledProgram, (kind, block): (KernelKind, Option<u32>), wgsl: &str) -> CompiledProgram {
    let mut p = program.clone();
    for k in p.kernels.iter_mut().filter(|k| k.kind == kind && k.block_size == block) {
        k.wgsl = wgsl.to_string();
    }
    p
}

/// A variant's kernel, or `None` when one of its edits has nothing to edit.
fn apply(variant: &Variant, wgsl: &str) -> Option<String> {
    apply_edits(variant.edits, wgsl)
}

/// `wgsl` with `edits` applied in turn, or `None` when one of them has
/// nothing to edit.
fn apply_edits(edits: &[Edit], wgsl: &str) -> Option<String> {
    edits.iter().try_fold(wgsl.to_string(), |w, edit| edit(&w))
}

/// The full kernel, the compacted one (block modes) and the variants that apply, each
/// as a whole program: (name, what it removes, program).
type Programs = Vec<(&'static str, &'static str, CompiledProgram)>;

/// Runs the ablation; returns the files written.
pub fn ablation(args: &AblationArgs) -> Result<Vec<PathBuf>> {
    let target = Target::of(args.mode)?;
    let modes = [Mode::Reference, args.mode];
    let DeviceProgram { name, program, gpu, .. } =
        compile_for_device(args.program.as_deref(), ("sponza_lights.mrsl", WORKLOAD_PROGRAM), &modes)?;
    let device = args.plan.unwrap_or(match gpu.adapter_info.device_type {
        wgpu::DeviceType::Cpu => Device::Cpu,
        _ => Device::Gpu,
    });
    let (programs, skipped) = variants(args, &name, &program, target, device)?;
    let device_name = format!("{} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    eprintln!(
        "ablation: {name}, {}, on {device_name}, {}x{}",
        target.title(args.mode, device),
        args.size.0,
        args.size.1
    );
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
        time_run(
            &gpu,
            &mut shaders[k],
            &bindings,
            DispatchOptions { device: Some(device), ..DispatchOptions::new(mode) },
        )
    })?;
    let background_tiles = match target {
        Target::Block(_) if program.layout.background_counters().is_some() => {
            background_tile_share(&gpu, &mut shaders[0], &bindings, args.mode)?
        }
        _ => None,
    };
    let report = Report { programs: &programs, skipped: &skipped, times: &times, background_tiles };
    let md = markdown(args, (target, device), &name, &device_name, &report);
    std::fs::create_dir_all(&args.out_dir).map_err(|e| anyhow!("cannot create {}: {e}", args.out_dir.display()))?;
    let path = args.out_dir.join("ablation.md");
    crate::output::write(&path, &md)?;
    println!("{md}");
    Ok(vec![path])
}

/// The full program, for a block mode the same compiled with the fine pass
/// compacted (`Options::compact`), and one program per variant whose edits
/// apply; the names of those whose edits do not.
fn variants(
    args: &AblationArgs,
    name: &str,
    program: &mrsl::Program,
    target: Target,
    device: Device,
) -> Result<(Programs, Vec<&'static str>)> {
    let full: &CompiledProgram = program;
    let (kind, block) = target.kernel(device);
    let kernel = full.kernels.iter().find(|k| k.kind == kind && k.block_size == block);
    let kernel = kernel.with_context(|| format!("the program has no {}", target.what()))?;
    let mut programs: Programs = vec![("full", "nothing", full.clone())];
    let mut skipped = vec![];
    // The compaction and the coarse pass's variants edit the coarse and fine
    // kernels, which the block modes run on CPU devices alone.
    let two_pass = matches!(target, Target::Block(_)) && device == Device::Cpu;
    if matches!(target, Target::Block(_)) && !two_pass {
        skipped.push("compacted (added)");
        skipped.extend(coarse::VARIANTS.iter().map(|v| v.name));
    }
    if two_pass {
        let source = match &args.program {
            Some(path) => crate::read_source(path)?,
            None => WORKLOAD_PROGRAM.to_string(),
        };
        let modes = [Mode::Reference, args.mode];
        // The channels bound as the full kernel binds them.
        let storage_channels = full.layout.channels.iter().any(|c| c.access == mrsl_abi::ChannelAccess::Storage);
        let options = mrsl::Options {
            compact: true,
            storage_channels,
            file_name: name.to_string(),
            ..mrsl::Options::for_modes(&modes)
        };
        let compacted = mrsl::compile(&source, &options).map_err(|d| anyhow!(mrsl::render_all(&d, name, &source)))?;
        programs.push((
            "compacted (added)",
            "nothing; adds the workgroup compaction: refined pixels re-evaluate together on consecutive lanes",
            compacted.compiled.clone(),
        ));
    }
    for v in target.variants() {
        match apply(v, &kernel.wgsl) {
            Some(wgsl) => programs.push((v.name, v.removes, with_kernel(full, (kind, block), &wgsl))),
            None => skipped.push(v.name),
        }
    }
    if let (Target::Block(block), true) = (target, two_pass) {
        // The coarse pass's variants: its kernel edited, the fine pass emptied.
        let coarse = full.kernel(KernelKind::Coarse, block).context("the program has no coarse kernel")?;
        for v in &coarse::VARIANTS {
            match v.apply(&coarse.wgsl, &kernel.wgsl) {
                Some((c, f)) => {
                    let p =
                        with_kernel(&with_kernel(full, (KernelKind::Coarse, Some(block)), &c), (kind, Some(block)), &f);
                    programs.push((v.name, v.removes, p));
                }
                None => skipped.push(v.name),
            }
        }
    }
    Ok((programs, skipped))
}

/// The share of the image's pixels in tiles of the fine pass
/// ([`mrsl_abi::geometry::TILE`] pixels a side) whose every pixel the
/// program's background rule marks, from the refine mask of one run of the
/// full kernel: the pixels a fine pass dispatched only over the other tiles
/// would leave to a background kernel (for a program with a background
/// rule). `None` without a refine mask.
fn background_tile_share(gpu: &Gpu, shader: &mut Shader, bindings: &Bindings, mode: Mode) -> Result<Option<f64>> {
    time_run(gpu, shader, bindings, DispatchOptions::new(mode))?;
    let Some(mask) = shader.refine_mask() else { return Ok(None) };
    let size = (mask.width(), mask.height());
    let texels: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(mask)?);
    Ok(Some(share_in_background_tiles(&texels, size, mrsl_abi::geometry::TILE)))
}

/// The share of a `size` refine mask's pixels (`texels`, row by row) in
/// `tile`-pixel tiles (the last ones cut at the image's edge) whose every
/// pixel holds the background mark.
fn share_in_background_tiles(texels: &[[u32; 2]], (w, h): (u32, u32), tile: u32) -> f64 {
    let mut in_background_tiles = 0u64;
    for y0 in (0..h).step_by(tile as usize) {
        for x0 in (0..w).step_by(tile as usize) {
            let pixels = || (y0..(y0 + tile).min(h)).flat_map(move |y| (x0..(x0 + tile).min(w)).map(move |x| (x, y)));
            if pixels().all(|(x, y)| texels[(y * w + x) as usize] == mrsl_abi::BACKGROUND_MARK) {
                in_background_tiles += pixels().count() as u64;
            }
        }
    }
    in_background_tiles as f64 / (f64::from(w) * f64::from(h))
}

/// What [`markdown`] reports: the programs timed, the variants left out,
/// the times per entry (the reference, then `programs`) and, for the block
/// modes, [`background_tile_share`].
struct Report<'a> {
    programs: &'a Programs,
    skipped: &'a [&'static str],
    times: &'a [Vec<f64>],
    background_tiles: Option<f64>,
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

/// The ablation report: per entry of the times (the reference, then the
/// programs), its median time and its median ratio to the full kernel's
/// time in the same round; and the background tiles' share.
fn markdown(
    args: &AblationArgs,
    (target, device): (Target, Device),
    name: &str,
    device_name: &str,
    report: &Report,
) -> String {
    let (programs, skipped, times) = (report.programs, report.skipped, report.times);
    let rounds = times[1].len();
    let ratio = |at: usize| median((0..rounds).map(|r| times[at][r] / times[1][r]).collect());
    let full_ms = median(times[1].clone());
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Ablation of the {}\n\nProgram `{name}`, scene {}, {}x{}, device {device_name}; {rounds} interleaved \
         rounds (the order rotates each round); `x full` is the median over the rounds of the variant's time / the full \
         kernel's time in the same round. Full kernel: {full_ms:.1} ms (median).\n",
        target.title(args.mode, device),
        args.scene,
        args.size.0,
        args.size.1
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
    if let Some(share) = report.background_tiles {
        let tile = mrsl_abi::geometry::TILE;
        let _ = writeln!(
            md,
            "\nPixels in {tile}x{tile} tiles wholly background (every pixel marked in the full kernel's refine mask): \
             {:.1}%.",
            100.0 * share
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::share_in_background_tiles;
    use mrsl_abi::BACKGROUND_MARK;

    /// A 5x3 mask in 2-pixel tiles: the tiles wholly background count,
    /// cut ones at the edges included; one drawn pixel spoils its tile.
    #[test]
    fn pixels_count_only_in_tiles_wholly_background() {
        let (w, h) = (5u32, 3u32);
        // Drawn: pixel (1, 0), in the first tile; everything else background.
        let texels: Vec<[u32; 2]> = (0..w * h).map(|i| if i == 1 { [0, 0] } else { BACKGROUND_MARK }).collect();
        // Tiles: rows 0-1 x columns 0-1 (drawn), 2-3, 4; row 2 x the same three.
        let background = 4 + 2 + 2 + 2 + 1;
        let share = share_in_background_tiles(&texels, (w, h), 2);
        assert_eq!(share, f64::from(background) / f64::from(w * h));
        assert_eq!(share_in_background_tiles(&[[0, 0]; 15], (w, h), 2), 0.0);
        assert_eq!(share_in_background_tiles(&[BACKGROUND_MARK; 15], (w, h), 8), 1.0);
    }
}
