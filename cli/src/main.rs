//! `mrslc`: the command-line driver of the mrsl compiler.

use anyhow::{Result, anyhow, bail};
use clap::{Parser, Subcommand, ValueEnum};
use codespan_reporting::term::termcolor::{ColorChoice, StandardStream};
use mrsl::{Diagnostic, KernelKind, KernelRef, Options};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod ablation;
mod args;
mod bench;
mod fmt;
mod frames;
mod gbuffer;
mod legend;
mod lsp;
mod output;
mod rates;
mod render;
mod report;
mod scene_check;
mod serve;
mod setup;
mod suite;
mod timing;
mod why;

#[derive(Parser)]
#[command(name = "mrslc", version, about = "Compiler for mrsl, a multi-rate shading language", long_about = None)]
struct Cli {
    /// When to colour diagnostics.
    #[arg(long, value_enum, default_value_t = Color::Auto, global = true)]
    color: Color,
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum Color {
    Auto,
    Always,
    Never,
}

#[derive(Subcommand)]
enum Command {
    /// Check a program and print its diagnostics; exit code 1 if it has errors.
    Check {
        /// The .mrsl program.
        file: PathBuf,
        /// Also bind the program to this scene as `render` would, without
        /// rendering: a channel the scene lacks or holds with another type,
        /// or a uniform nothing sets, is an error (E0801-E0803).
        #[arg(long)]
        scene: Option<String>,
        /// Set a uniform, as for `render` (with --scene).
        #[arg(long = "set", value_parser = args::parse_set, requires = "scene")]
        sets: Vec<(String, Vec<f64>)>,
    },
    /// Format programs in the canonical layout, in place (only files that change are written).
    ///
    /// Folders are searched for .mrsl files. With --check nothing is written: each
    /// file that would change is listed with its first changed line, and the exit
    /// code is 1 if any would. A file that does not parse is reported and left as
    /// it is (exit code 2).
    Fmt {
        /// The .mrsl programs, or folders of them.
        files: Vec<PathBuf>,
        /// Write nothing; list the files that are not formatted and exit 1 if any are.
        #[arg(long)]
        check: bool,
        /// Format the program on standard input to standard output.
        #[arg(long, conflicts_with_all = ["files", "check"])]
        stdin: bool,
    },
    /// Compile a program to WGSL kernels and a layout description.
    ///
    /// Writes the kernels of the modes asked for (all by default: 17
    /// kernels), named <name>.KIND.bB.wgsl for the kinds that exist per
    /// block size (tile, coarse and fine at 2 and 4, dynamic_coarse at 2,
    /// dynamic_fine at 4, multi_coarse at 4 and 2, multi_resolve at 4,
    /// multi_fine at 2) and <name>.KIND.wgsl for the others (reference,
    /// hierarchical, checkerboard, rate_coarse, rate_fine), and
    /// <name>.layout.json, which holds every binding and the plan of each
    /// mode, into the output directory.
    Compile {
        /// The .mrsl program.
        file: PathBuf,
        /// Output directory (created if missing).
        #[arg(short, long, default_value = ".")]
        out_dir: PathBuf,
        /// Print one artifact to standard output instead of writing files.
        #[arg(long, value_enum)]
        emit: Option<Emit>,
        /// Modes to compile for, comma-separated (reference, coarse2x2, coarse4x4, dynamic,
        /// hierarchical, checkerboard, rate-image, multi-rate), or all.
        #[arg(long, alias = "modes", value_parser = args::parse_modes, default_value = "all")]
        mode: args::ModeList,
        /// With --emit coarse, fine or tile: the block size of the kernel printed.
        #[arg(short, long = "block", value_parser = ["2", "4"], default_value = "4")]
        block: String,
        /// Read the G-buffer channels through read-only storage bindings (faster on
        /// lavapipe): the engine's textures must have exactly the layout's formats and
        /// STORAGE_BINDING, and the device must allow the layout's storage textures per
        /// stage (one more per channel), past WebGPU's default 4 (docs/runtime.md).
        #[arg(long)]
        storage_channels: bool,
        /// Pack the hierarchical kernel's per-pixel records four words to a texel of an
        /// rgba32uint read-write storage texture (faster on lavapipe): not in core WebGPU,
        /// the device needs read-write storage access to rgba32uint (wgpu's
        /// TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES where the adapter has it).
        #[arg(long)]
        packed_records: bool,
    },
    /// Render a program over a scene with the wgpu runtime (lavapipe works).
    ///
    /// With no arguments: the built-in demo program over the demo scene at
    /// 960x540 in coarse 4x4 mode, writing demo.coarse4x4.png, heatmaps and
    /// demo.stats.json into out/.
    Render(Render),
    /// Benchmark the modes: sweep refinement thresholds, measure shaded
    /// fraction, GPU and wall time and quality against the reference, and run
    /// the dynamic-threshold controller along a camera path.
    ///
    /// With no arguments: examples/sponza_lights.mrsl (built in) over Sponza
    /// at 1920x1080, every mode; writes bench.md, bench.csv, controller.csv,
    /// quality_vs_time.sponza.png and controller.png into out/
    /// (docs/evaluation.md explains every figure).
    Bench(Bench),
    /// Export a scene's G-buffer, and with a program everything else it binds
    /// as `render` binds it, for another runtime (docs/gbuffer-format.md).
    ///
    /// Writes DIR/gbuffer.json (format mrsl-gbuffer/1: the channels, the
    /// uniforms the scene and --set set, the textures with their mip levels,
    /// the samplers) and one file of raw texels per channel and mip level,
    /// rows tightly packed, in the texture's format.
    Gbuffer(Gbuffer),
    /// Serve the playground on a local HTTP server (its API: docs/serve.md).
    ///
    /// Prints `playground: http://HOST:PORT/` once it listens, and runs
    /// until stopped.
    Serve {
        /// The address to listen on (the server has no authentication: keep it local).
        #[arg(long, default_value = "127.0.0.1")]
        host: String,
        /// The port (0: any free port).
        #[arg(long, default_value_t = 8421)]
        port: u16,
    },
    /// Serve the language server protocol over standard input and output, for
    /// editors: diagnostics as you type, hover with each effect's rate, cost
    /// and interface slot, definition, references, completion, symbols, inlay
    /// hints and quick fixes (README, "Editor setup").
    Lsp {
        /// Accepted for clients that pass it: standard input and output is the only transport.
        #[arg(long, hide = true)]
        stdio: bool,
    },
}

#[derive(clap::Args)]
struct Gbuffer {
    /// The .mrsl program whose uniforms, textures and samplers to export (default: none, the G-buffer alone).
    program: Option<PathBuf>,
    /// Scene, as for `render`.
    #[arg(long, default_value = "demo")]
    scene: String,
    /// Image size, WIDTHxHEIGHT (default: the scene file's, else 960x540; at most 3840x2160 pixels).
    #[arg(long, value_parser = args::parse_size)]
    size: Option<(u32, u32)>,
    /// Output directory (created if missing).
    #[arg(short = 'o', long = "out")]
    out_dir: PathBuf,
    /// Set a uniform: NAME=VALUE or NAME=X,Y,Z (repeatable), after the scene's.
    #[arg(long = "set", value_parser = args::parse_set)]
    sets: Vec<(String, Vec<f64>)>,
}

#[derive(clap::Args)]
struct Bench {
    /// The .mrsl program (default: the built-in Sponza lights-and-shadows workload).
    program: Option<PathBuf>,
    /// Scene(s), as for `render` (repeatable; default: sponza, and with
    /// --suite the suite: sponza, dungeon, outdoor, small, generated).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Image size, WIDTHxHEIGHT (default 1920x1080; repeatable with --suite).
    #[arg(long = "size", value_parser = args::parse_size)]
    sizes: Vec<(u32, u32)>,
    /// Modes, comma-separated (reference, coarse2x2, coarse4x4, dynamic, hierarchical, checkerboard, rate-image,
    /// multi-rate), or all.
    #[arg(long, alias = "mode", value_parser = args::parse_modes, default_value = "all")]
    modes: args::ModeList,
    /// The block and dynamic modes' knob: a float uniform of the program.
    #[arg(long, default_value = "light_tolerance")]
    knob: String,
    /// The knob's values (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0])]
    values: Vec<f64>,
    /// The hierarchical mode's similarity thresholds (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [1e-6, 1e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2])]
    similarities: Vec<f64>,
    /// Timed runs per point (after one warm-up), each paired with a reference
    /// run; the median of the per-pair ratios is reported.
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Output directory (created if missing).
    #[arg(short, long = "out", alias = "out-dir", default_value = "out")]
    out_dir: PathBuf,
    /// Frames of the dynamic-threshold camera path (0 skips it).
    #[arg(long, default_value_t = 24)]
    path_frames: usize,
    /// The controller's target shaded fraction.
    #[arg(long, default_value_t = 0.5)]
    target_fraction: f64,
    /// Instead of the sweep: time the adaptive kernel of the mode given by
    /// --modes (coarse2x2, coarse4x4 or hierarchical; coarse4x4 unless
    /// given; for the block modes their coarse pass too) with one part
    /// removed at a time, paired with the full kernel,
    /// on the first scene (writes ablation.md).
    #[arg(long, conflicts_with = "suite")]
    ablation: bool,
    /// With --ablation of a block mode: the plan whose kernels are edited and timed, gpu (the tile
    /// kernel) or cpu (the coarse and fine kernels); default: the rendering device's own.
    #[arg(long, value_enum, requires = "ablation")]
    plan: Option<PlanDevice>,
    /// Instead of the sweep: every mode at its defaults over the scene suite
    /// (or the --scene list) at each --size, paired with the reference:
    /// speedup, quality, forced and nothing-refined times (writes suite.md
    /// and suite.json).
    #[arg(long)]
    suite: bool,
}

#[derive(clap::Args)]
struct Render {
    /// The .mrsl program (default: the built-in demo program).
    program: Option<PathBuf>,
    /// Scene: demo, gradient, steps, sinusoid, sponza, dungeon, or a .toml scene file (docs/scenes.md).
    #[arg(long, default_value = "demo")]
    scene: String,
    /// Modes, comma-separated (reference, coarse2x2, coarse4x4, dynamic, hierarchical, checkerboard, rate-image,
    /// multi-rate), or all.
    #[arg(long, alias = "modes", value_parser = args::parse_modes, default_value = "coarse4x4")]
    mode: args::ModeList,
    /// Image size, WIDTHxHEIGHT (default: the scene file's, else 960x540).
    #[arg(long, value_parser = args::parse_size)]
    size: Option<(u32, u32)>,
    /// Set a uniform: NAME=VALUE or NAME=X,Y,Z (repeatable).
    #[arg(long = "set", value_parser = args::parse_set)]
    sets: Vec<(String, Vec<f64>)>,
    /// Directory of the files written (created if missing), except those named by -o and --heatmap
    /// (default: the directory of -o's file when -o is given, else `out`).
    #[arg(long = "out")]
    out_dir: Option<PathBuf>,
    /// Output PNG (default: OUT/PROGRAM.MODE.png).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Heatmap PNG of where coarse effects were evaluated per pixel.
    #[arg(long)]
    heatmap: Option<PathBuf>,
    /// Print per-effect statistics.
    #[arg(long)]
    stats: bool,
    /// Force every refine predicate (the output must equal the reference).
    #[arg(long)]
    force_refine: bool,
    /// Also render the reference and report RMSE, PSNR, MSSIM and FLIP of each mode
    /// against it, writing PROGRAM.MODE.error.png.
    #[arg(long)]
    compare: bool,
    /// Hierarchical mode: largest variance of four neighbours that is still interpolated.
    #[arg(long, default_value_t = mrsl_runtime::DispatchOptions::DEFAULT_SIMILARITY)]
    similarity: f32,
    /// Rate-image mode: the rate source's sensitivity preset (VALAR's t: 0.25, 0.5, 0.75).
    #[arg(long, value_enum, default_value_t = RatePreset::Balanced)]
    rate_preset: RatePreset,
    /// Rate-image mode: one rate for every tile (1x1, 1x2, 2x1, 2x2, 2x4, 4x2, 4x4) instead of
    /// the content-adaptive rate source.
    #[arg(long, value_parser = parse_rate)]
    uniform_rate: Option<mrsl_abi::ShadingRate>,
    /// Rate-image mode: pixels per side of a shading-rate tile.
    #[arg(long, default_value_t = mrsl_abi::shading_rate::DEFAULT_RATE_TILE, value_parser = parse_rate_tile)]
    rate_tile: u32,
    /// The block modes' plan: gpu (one tile kernel) or cpu (a coarse and a fine kernel); default: the
    /// one for the kind of device rendering (both give the same image).
    #[arg(long, value_enum)]
    plan: Option<PlanDevice>,
    /// Rate-image mode: the Weber–Fechner variant of the rate source (more conservative in the dark).
    #[arg(long)]
    weber_fechner: bool,
    /// Rate-image mode with --frames: decide without the motion vectors (no motion terms, no reprojection).
    #[arg(long)]
    no_motion: bool,
    /// Also write each output of each mode as raw texels, OUT/PROGRAM.MODE.OUTPUT.bin:
    /// rows tightly packed, little-endian, in the output's format (rgba32float: 16
    /// bytes a pixel), the values the PNG was made from.
    #[arg(long, conflicts_with = "frames")]
    raw: bool,
    /// Render N frames along the scene's camera path (Sponza's walk, or a scene file's
    /// camera_path), writing PROGRAM.MODE.fNNN.png, the rate-image mode's rates per
    /// frame and PROGRAM.frames.json; the rate-image mode takes its rates from the
    /// previous frame and its motion vectors.
    #[arg(long, value_parser = frames::parse_frames)]
    frames: Option<usize>,
}

/// `--rate-tile`: one of the tile sizes the rate-image mode supports.
fn parse_rate_tile(text: &str) -> Result<u32, String> {
    let sizes = mrsl_abi::shading_rate::RATE_TILE_SIZES;
    text.parse::<u32>()
        .ok()
        .filter(|t| sizes.contains(t))
        .ok_or_else(|| format!("`{text}` is not a supported tile size (expected {sizes:?})"))
}

/// `--uniform-rate`: one of the seven rates by name.
fn parse_rate(text: &str) -> Result<mrsl_abi::ShadingRate, String> {
    mrsl_abi::ShadingRate::ALL.into_iter().find(|r| r.name() == text).ok_or_else(|| {
        let names: Vec<&str> = mrsl_abi::ShadingRate::ALL.iter().map(|r| r.name()).collect();
        format!("`{text}` is not a shading rate (expected one of {})", names.join(", "))
    })
}

/// The rate source's presets (`mrsl_runtime::rate_source::Preset`).
#[derive(Clone, Copy, ValueEnum, PartialEq, Debug)]
enum RatePreset {
    Quality,
    Balanced,
    Performance,
}

impl RatePreset {
    fn runtime(self) -> mrsl_runtime::rate_source::Preset {
        use mrsl_runtime::rate_source::Preset;
        match self {
            RatePreset::Quality => Preset::Quality,
            RatePreset::Balanced => Preset::Balanced,
            RatePreset::Performance => Preset::Performance,
        }
    }
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Emit {
    Coarse,
    Fine,
    Tile,
    Reference,
    Layout,
}

/// Where `render` writes the files -o and --heatmap do not name: `--out`,
/// else beside -o's file (so `-o /tmp/x.png` writes nothing into the working
/// directory), else `out`.
fn render_out_dir(out: Option<&std::path::Path>, output: Option<&std::path::Path>) -> PathBuf {
    match (out, output.map(|o| o.parent())) {
        (Some(dir), _) => dir.to_path_buf(),
        (None, Some(Some(dir))) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        (None, Some(_)) => PathBuf::from("."),
        (None, None) => PathBuf::from("out"),
    }
}

fn main() -> ExitCode {
    // Before anything can start a thread or load Vulkan (see the function).
    // SAFETY: no other thread exists yet: nothing has run but `main`'s start.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    let cli = Cli::parse();
    // The kit does not search for Sponza by itself (see mrsl_lab::fixtures).
    mrsl_lab::fixtures::locate_sponza();
    match run(&cli) {
        Ok(code) => code,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: &Cli) -> Result<ExitCode> {
    match &cli.command {
        Command::Check { file, scene, sets } => check(cli.color, file, scene.as_deref(), sets),
        Command::Fmt { files, check, stdin } => {
            fmt::fmt(cli.color, &fmt::FmtArgs { files, check: *check, stdin: *stdin })
        }
        Command::Render(r) => {
            let args = r.args();
            Ok(written(match args.frames {
                Some(n) => render::open(&args).and_then(|mut session| frames::render_frames(&mut session, &args, n)),
                None => render::render(&args),
            }))
        }
        Command::Bench(b) => bench(b),
        Command::Compile { file, out_dir, emit, mode, block, storage_channels, packed_records } => {
            let options = Options {
                storage_channels: *storage_channels,
                packed_records: *packed_records,
                ..Options::for_modes(&mode.0)
            };
            compile(cli.color, file, out_dir, *emit, block, options)
        }
        Command::Gbuffer(g) => Ok(written(gbuffer_command(g))),
        Command::Serve { host, port } => serve::serve(host, *port).map(|()| ExitCode::SUCCESS),
        Command::Lsp { stdio: _ } => lsp::serve().map(|()| ExitCode::SUCCESS),
    }
}

/// `mrslc check`: the diagnostics; exit 1 with errors.
fn check(color: Color, file: &Path, scene: Option<&str>, sets: &[(String, Vec<f64>)]) -> Result<ExitCode> {
    let (name, source) = read(file)?;
    let mut diagnostics = mrsl::check(&source);
    if let Some(scene) = scene.filter(|_| !diagnostics.iter().any(|d| d.is_error())) {
        let (bound, warnings) = scene_check::on_scene(&source, scene, sets)?;
        for warning in warnings {
            eprintln!("warning: {warning}");
        }
        diagnostics.extend(bound);
    }
    report(color, &diagnostics, &name, &source);
    let errors = diagnostics.iter().filter(|d| d.is_error()).count();
    let warnings = diagnostics.len() - errors;
    if errors > 0 {
        eprintln!("{name}: {errors} error{}, {warnings} warning{}", plural(errors), plural(warnings));
        Ok(ExitCode::from(1))
    } else {
        let on = scene.map(|s| format!(" on scene `{s}`")).unwrap_or_default();
        eprintln!("{name}: ok{on} ({warnings} warning{})", plural(warnings));
        Ok(ExitCode::SUCCESS)
    }
}

impl Render {
    /// The arguments as `render` takes them.
    fn args(&self) -> args::RenderArgs {
        args::RenderArgs {
            program: self.program.clone(),
            scene: self.scene.clone(),
            modes: self.mode.0.clone(),
            size: self.size,
            sets: self.sets.clone(),
            output: self.output.clone(),
            heatmap: self.heatmap.clone(),
            out_dir: render_out_dir(self.out_dir.as_deref(), self.output.as_deref()),
            stats: self.stats,
            force_refine: self.force_refine,
            compare: self.compare,
            raw: self.raw,
            similarity: self.similarity,
            uniform_rate: self.uniform_rate,
            rates: mrsl_runtime::rate_source::RateOptions {
                tile: self.rate_tile,
                weber_fechner: self.weber_fechner,
                ..mrsl_runtime::rate_source::RateOptions::preset(self.rate_preset.runtime())
            },
            motion: !self.no_motion,
            frames: self.frames,
            plan: self.plan.map(PlanDevice::abi),
        }
    }
}

/// `--plan`: which of the block modes' plans runs.
#[derive(Clone, Copy, clap::ValueEnum)]
enum PlanDevice {
    Gpu,
    Cpu,
}

impl PlanDevice {
    fn abi(self) -> mrsl_abi::Device {
        match self {
            PlanDevice::Gpu => mrsl_abi::Device::Gpu,
            PlanDevice::Cpu => mrsl_abi::Device::Cpu,
        }
    }
}

/// `mrslc gbuffer`: the export's files into the output directory; returns their paths.
fn gbuffer_command(g: &Gbuffer) -> Result<Vec<PathBuf>> {
    let program = match &g.program {
        Some(path) => Some(setup::compile_program(Some(path), ("", ""), &[])?.1),
        None => None,
    };
    let name = g.program.as_ref().and_then(|p| p.file_name()).map(|n| n.to_string_lossy().into_owned());
    let program = program.as_ref().zip(name.as_deref()).map(|(program, name)| gbuffer::ProgramRef { name, program });
    let gpu = mrsl_lab::gpu::Gpu::new()?;
    let export = gbuffer::export(&gpu, &g.scene, g.size, program, &g.sets)?;
    for warning in &export.manifest.warnings {
        eprintln!("warning: {warning}");
    }
    std::fs::create_dir_all(&g.out_dir).map_err(|e| anyhow!("cannot create {}: {e}", g.out_dir.display()))?;
    let mut paths = vec![];
    for (file, bytes) in export.into_files()? {
        let path = g.out_dir.join(file);
        output::write(&path, bytes)?;
        paths.push(path);
    }
    Ok(paths)
}

/// `mrslc bench`: the sweep, or with `--ablation` the ablation.
fn bench(b: &Bench) -> Result<ExitCode> {
    let modes = b.modes.0.clone();
    if b.suite {
        if modes != mrsl_runtime::Mode::ALL {
            bail!("--suite runs every mode: leave out --modes");
        }
        let args = suite::SuiteArgs {
            program: b.program.clone(),
            scenes: if b.scenes.is_empty() { suite::SUITE.map(String::from).to_vec() } else { b.scenes.clone() },
            sizes: if b.sizes.is_empty() { vec![(1920, 1080)] } else { b.sizes.clone() },
            runs: b.runs,
            out_dir: b.out_dir.clone(),
        };
        return Ok(written(suite::suite(&args)));
    }
    let size = match b.sizes.as_slice() {
        [] => (1920, 1080),
        [size] => *size,
        _ => bail!("one --size at a time, except with --suite"),
    };
    let scenes = if b.scenes.is_empty() { vec!["sponza".to_string()] } else { b.scenes.clone() };
    if b.ablation {
        let mode = match modes.as_slice() {
            [mode] => *mode,
            _ if modes == mrsl_runtime::Mode::ALL => mrsl_runtime::Mode::Coarse4x4,
            _ => bail!("--ablation takes one mode in --modes (coarse2x2, coarse4x4 or hierarchical)"),
        };
        let args = ablation::AblationArgs {
            program: b.program.clone(),
            scene: scenes[0].clone(),
            size,
            mode,
            runs: b.runs,
            out_dir: b.out_dir.clone(),
            plan: b.plan.map(PlanDevice::abi),
        };
        return Ok(written(ablation::ablation(&args)));
    }
    if !(b.target_fraction > 0.0 && b.target_fraction <= 1.0) {
        bail!("--target-fraction must be in (0, 1], not {}", b.target_fraction);
    }
    let args = bench::BenchArgs {
        program: b.program.clone(),
        scenes,
        size,
        modes,
        knob: b.knob.clone(),
        values: b.values.clone(),
        similarities: b.similarities.clone(),
        runs: b.runs,
        out_dir: b.out_dir.clone(),
        path_frames: b.path_frames,
        target_fraction: b.target_fraction,
    };
    Ok(written(bench::bench(&args)))
}

/// `mrslc compile`: the kernels and the layout into `out_dir`, or one of
/// them to standard output (`--emit`).
fn compile(
    color: Color,
    file: &Path,
    out_dir: &Path,
    emit: Option<Emit>,
    block: &str,
    options: Options,
) -> Result<ExitCode> {
    let (name, source) = read(file)?;
    let options = Options { file_name: name.clone(), ..options };
    let program = match mrsl::compile(&source, &options) {
        Ok(p) => p,
        Err(diagnostics) => {
            report(color, &diagnostics, &name, &source);
            return Ok(ExitCode::from(1));
        }
    };
    report(color, &program.warnings, &name, &source);
    if let Some(emit) = emit {
        let block: u32 = block.parse().expect("clap restricts block sizes");
        let kernel = |kind: KernelKind| {
            program.kernel(kind, block).map(|k| k.wgsl.clone()).ok_or_else(|| {
                let what = KernelRef::new(kind, kind.per_block_size().then_some(block));
                anyhow!("{name} was compiled without its {what} kernel: add a mode that runs it with --mode")
            })
        };
        let text = match emit {
            Emit::Layout => program.layout.to_json(),
            Emit::Coarse => kernel(KernelKind::Coarse)?,
            Emit::Fine => kernel(KernelKind::Fine)?,
            Emit::Tile => kernel(KernelKind::Tile)?,
            Emit::Reference => kernel(KernelKind::Reference)?,
        };
        std::io::stdout().write_all(text.as_bytes())?;
        return Ok(ExitCode::SUCCESS);
    }
    std::fs::create_dir_all(out_dir).map_err(|e| anyhow!("cannot create {}: {e}", out_dir.display()))?;
    let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("program");
    let written = program
        .compiled
        .write_dir(out_dir, stem)
        .map_err(|(path, e)| anyhow!("cannot write {}: {e}", path.display()))?;
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The exit of a command that writes files: lists them at the end (exit
/// 0), or prints why it failed (exit 1).
fn written(result: Result<Vec<PathBuf>>) -> ExitCode {
    match result {
        Ok(paths) => {
            for p in &paths {
                eprintln!("wrote {}", p.display());
            }
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("{message}");
            ExitCode::from(1)
        }
    }
}

fn read(file: &Path) -> Result<(String, String)> {
    Ok((file.display().to_string(), read_source(file)?))
}

/// Reads a program. A file that is not UTF-8 is refused with the place of
/// its first bad byte: "FILE: not valid UTF-8 at byte N (line L, column C)".
pub(crate) fn read_source(file: &Path) -> Result<String> {
    let bytes = std::fs::read(file).map_err(|e| anyhow!("cannot read {}: {e}", file.display()))?;
    String::from_utf8(bytes).map_err(|e| anyhow!(not_utf8(&file.display().to_string(), e.as_bytes(), e.utf8_error())))
}

/// The message for a file whose bytes are not UTF-8; the line and the column
/// (in characters, from 1) are those of the first bad byte.
fn not_utf8(name: &str, bytes: &[u8], error: std::str::Utf8Error) -> String {
    let offset = error.valid_up_to();
    let valid = std::str::from_utf8(&bytes[..offset]).expect("valid up to the error");
    let line = valid.matches('\n').count() + 1;
    let column = valid.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    format!("{name}: not valid UTF-8 at byte {offset} (line {line}, column {column})")
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// Prints diagnostics to stderr: coloured on a terminal, plain otherwise.
fn report(color: Color, diagnostics: &[Diagnostic], name: &str, source: &str) {
    if diagnostics.is_empty() {
        return;
    }
    let colored = match color {
        Color::Always => true,
        Color::Never => false,
        Color::Auto => std::io::stderr().is_terminal(),
    };
    if colored {
        let mut stream = StandardStream::stderr(ColorChoice::Always);
        let _ = mrsl::emit_colored(&mut stream, diagnostics, name, source);
    } else {
        eprint!("{}", mrsl::render_all(diagnostics, name, source));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn render_writes_beside_the_output_unless_told() {
        use std::path::Path;
        assert_eq!(render_out_dir(None, None), PathBuf::from("out"));
        assert_eq!(render_out_dir(None, Some(Path::new("/tmp/r/a.png"))), PathBuf::from("/tmp/r"));
        assert_eq!(render_out_dir(None, Some(Path::new("a.png"))), PathBuf::from("."));
        assert_eq!(render_out_dir(Some(Path::new("d")), Some(Path::new("/tmp/r/a.png"))), PathBuf::from("d"));
    }

    #[test]
    fn a_file_that_is_not_utf8_is_refused_with_the_place_of_its_first_bad_byte() {
        let bytes: &[u8] = b"in float3 normal;\nfine out float4 c\xe9 = float4(normal, 1.0);\n";
        let error = String::from_utf8(bytes.to_vec()).unwrap_err().utf8_error();
        assert_eq!(not_utf8("a.mrsl", bytes, error), "a.mrsl: not valid UTF-8 at byte 35 (line 2, column 18)");
        // Columns count characters, not bytes.
        let mut bytes = "// é\n// λλ ".as_bytes().to_vec();
        bytes.push(0xFF);
        let error = std::str::from_utf8(&bytes).unwrap_err();
        assert_eq!(not_utf8("b.mrsl", &bytes, error), "b.mrsl: not valid UTF-8 at byte 14 (line 2, column 7)");
    }

    #[test]
    fn render_takes_frames_as_a_count_and_defaults_to_a_still_frame() {
        let frames = |args: &[&str]| -> Result<Option<usize>, String> {
            let argv = ["mrslc", "render", "examples/sponza_lights.mrsl", "--scene", "sponza"];
            let cli = Cli::try_parse_from(argv.iter().chain(args)).map_err(|e| e.to_string())?;
            match cli.command {
                Command::Render(r) => Ok(r.frames),
                _ => Err("not render".into()),
            }
        };
        assert_eq!(frames(&[]), Ok(None), "without --frames: a still frame");
        assert_eq!(frames(&["--frames", "8"]), Ok(Some(8)));
        assert_eq!(frames(&["--frames=1", "--mode", "rate-image", "--compare"]), Ok(Some(1)));
        for bad in ["0", "-1", "two", "1.5"] {
            let e = frames(&[&format!("--frames={bad}")]).unwrap_err();
            assert!(e.contains("--frames") && e.contains("from 1 to 1000"), "{bad}: {e}");
        }
    }

    #[test]
    fn read_source_reports_invalid_utf8_and_keeps_a_byte_order_mark() {
        let dir = std::env::temp_dir().join(format!("mrslc-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.mrsl");
        std::fs::write(&bad, b"in float3 n\xff;\n").unwrap();
        let message = read_source(&bad).unwrap_err().to_string();
        assert!(message.ends_with(": not valid UTF-8 at byte 11 (line 1, column 12)"), "{message}");
        let bom = dir.join("bom.mrsl");
        std::fs::write(&bom, "\u{FEFF}in float3 n;\n").unwrap();
        assert_eq!(read_source(&bom).unwrap(), "\u{FEFF}in float3 n;\n");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `mrslc compile -o DIR` writes the plan of every mode into the layout,
    /// and it reads back as the compiler's; `--mode` narrows it (and the
    /// kernels) to the modes named, and `--emit` of a kernel not compiled
    /// says so instead of printing nothing.
    #[test]
    fn compile_writes_the_plan_of_the_modes_asked_for() {
        let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/demo.mrsl");
        let dir = std::env::temp_dir().join(format!("mrslc-compile-{}", std::process::id()));
        let compile = |extra: &[&str]| {
            let _ = std::fs::remove_dir_all(&dir);
            let argv = ["mrslc", "compile", demo, "-o", dir.to_str().unwrap()];
            let cli = Cli::try_parse_from(argv.iter().chain(extra)).unwrap();
            assert_eq!(run(&cli).unwrap(), ExitCode::SUCCESS);
            mrsl_runtime::CompiledProgram::read_dir(&dir, None).unwrap()
        };
        let source = std::fs::read_to_string(demo).unwrap();
        let all = compile(&[]);
        // As many as `compile --help` says.
        assert_eq!(all.kernels.len(), Options::default().kernels().len());
        let help = Cli::command().find_subcommand("compile").unwrap().get_long_about().unwrap().to_string();
        assert!(help.contains(&format!("all by default: {} kernels", all.kernels.len())), "{help}");
        let expected = mrsl::compile(&source, &Options { file_name: demo.into(), ..Options::default() }).unwrap();
        assert_eq!(all.layout.plan, expected.layout.plan);
        // The block modes have a plan for GPUs and one for CPU devices.
        assert_eq!(all.layout.plan.modes.len(), mrsl::Mode::ALL.len() + 2);
        let two = compile(&["--mode", "coarse4x4,hierarchical"]);
        let modes: Vec<mrsl::Mode> = two.layout.plan.modes.iter().map(|m| m.mode).collect();
        assert_eq!(modes, [mrsl::Mode::Coarse4x4, mrsl::Mode::Coarse4x4, mrsl::Mode::Hierarchical]);
        assert_eq!(two.kernels.len(), 4, "coarse b4, fine b4, tile b4, hierarchical");
        std::fs::remove_dir_all(&dir).unwrap();
        let argv = ["mrslc", "compile", demo, "--mode", "coarse4x4", "--emit", "fine", "-b", "2"];
        let message = run(&Cli::try_parse_from(argv).unwrap()).unwrap_err().to_string();
        assert!(message.contains("without its 2x2 fine kernel"), "{message}");
    }

    #[test]
    fn rate_options_parse_or_say_what_is_expected() {
        assert_eq!(parse_rate("2x4"), Ok(mrsl_abi::ShadingRate::R2x4));
        let message = parse_rate("4x1").unwrap_err();
        assert!(message.contains("1x1, 1x2, 2x1, 2x2, 2x4, 4x2, 4x4"), "{message}");
        assert_eq!(parse_rate_tile("16"), Ok(16));
        assert!(parse_rate_tile("12").unwrap_err().contains("[8, 16]"));
        let cli = Cli::try_parse_from(["mrslc", "render", "--mode", "rate-image", "--uniform-rate", "4x2"]).unwrap();
        let Command::Render(r) = cli.command else { panic!("render") };
        assert_eq!(
            (r.uniform_rate, r.rate_tile, r.rate_preset),
            (Some(mrsl_abi::ShadingRate::R4x2), 8, RatePreset::Balanced)
        );
    }
}
