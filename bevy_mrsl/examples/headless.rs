//! Renders a Bevy 0.19 scene headless with bevy_mrsl: the per-pixel
//! reference, an adaptive mode and that mode with refinement forced, each
//! written as a PNG, with the adaptive image's quality against the
//! reference and the statistics bevy_mrsl reports.
//!
//! The scene is built in (`--scene spheres`), or the lab's dungeon
//! (`--scene dungeon`, fetched by `scripts/fetch-dungeon.sh`), or any glTF
//! file with its lights (`--gltf PATH --eye X,Y,Z --target X,Y,Z`).
//!
//! With `--bench ROUNDS` it writes nothing and times the mrsl pass instead
//! (see `common/bench.rs`): frame times without bevy_mrsl, in the reference
//! and in the mode, interleaved, statistics off.
//!
//! ```sh
//! cargo run --release -p bevy_mrsl --example headless -- [--mode coarse4x4] [--size 640x360] [--out out/bevy]
//! cargo run --release -p bevy_mrsl --example headless -- --bench 9 --size 1280x720
//! ```

mod common;

use bevy_mrsl::Mode;
use common::Capture;
use std::path::PathBuf;

struct Args {
    mode: Mode,
    size: (u32, u32),
    out: PathBuf,
    bench: Option<usize>,
    scene: common::Scene,
}

fn parse() -> Result<Args, String> {
    let mut args = Args {
        mode: Mode::Coarse4x4,
        size: (640, 360),
        out: PathBuf::from("out/bevy"),
        bench: None,
        scene: common::Scene::Spheres,
    };
    let mut gltf: Option<PathBuf> = None;
    let (mut eye, mut target, mut fov) = (None, None, 60.0);
    let mut rest = std::env::args().skip(1);
    while let Some(flag) = rest.next() {
        let mut value = || rest.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--mode" => args.mode = value()?.parse().map_err(|e| format!("--mode: {e}"))?,
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or_else(|| format!("--size {v}: expected WIDTHxHEIGHT"))?;
                let parse = |s: &str| s.parse::<u32>().ok().filter(|n| (1..=8192).contains(n));
                args.size = match (parse(w), parse(h)) {
                    (Some(w), Some(h)) => (w, h),
                    _ => return Err(format!("--size {v}: width and height are 1 to 8192")),
                };
            }
            "--out" => args.out = PathBuf::from(value()?),
            "--scene" => {
                args.scene = match value()?.as_str() {
                    "spheres" => common::Scene::Spheres,
                    "dungeon" => dungeon()?,
                    other => return Err(format!("--scene {other}: `spheres` or `dungeon` (or --gltf PATH)")),
                }
            }
            "--gltf" => gltf = Some(PathBuf::from(value()?)),
            "--eye" => eye = Some(vector(&flag, &value()?)?),
            "--target" => target = Some(vector(&flag, &value()?)?),
            "--fov" => fov = value()?.parse().map_err(|e| format!("--fov: {e}"))?,
            "--bench" => {
                let v = value()?;
                let rounds = v.parse().ok().filter(|n| (1..=1000).contains(n));
                args.bench = Some(rounds.ok_or_else(|| format!("--bench {v}: a number of rounds, 1 to 1000"))?);
            }
            "--help" | "-h" => {
                println!(
                    "usage: headless [--mode MODE] [--size WxH] [--out DIR] [--bench ROUNDS] [--scene spheres|dungeon]\n\
                     \x20      [--gltf PATH --eye X,Y,Z --target X,Y,Z [--fov DEGREES]]\nmodes: {}",
                    mode_names()
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument `{other}` (see --help)")),
        }
    }
    if let Some(path) = gltf {
        let (Some(eye), Some(target)) = (eye, target) else {
            return Err("--gltf needs the camera: --eye X,Y,Z --target X,Y,Z [--fov DEGREES]".into());
        };
        args.scene = common::Scene::Gltf { path, eye, target, fov_y_degrees: fov };
    }
    if args.mode == Mode::Reference {
        return Err("--mode: name an adaptive mode; the reference is always rendered".into());
    }
    Ok(args)
}

/// The lab's textured dungeon (`scripts/fetch-dungeon.sh`) from its default camera.
fn dungeon() -> Result<common::Scene, String> {
    let path = mrsl_lab::fixtures::dungeon_path().map_err(|e| e.to_string())?;
    let camera = mrsl_lab::scene::Scene::dungeon_camera();
    let v = bevy::math::Vec3::from_array;
    Ok(common::Scene::Gltf { path, eye: v(camera.eye), target: v(camera.target), fov_y_degrees: camera.fov_y_degrees })
}

fn vector(flag: &str, value: &str) -> Result<bevy::math::Vec3, String> {
    let parts: Vec<f32> = value
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{flag} {value}: {e}"))?;
    match parts[..] {
        [x, y, z] => Ok(bevy::math::Vec3::new(x, y, z)),
        _ => Err(format!("{flag} {value}: expected X,Y,Z")),
    }
}

fn mode_names() -> String {
    Mode::ALL.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
}

fn main() {
    if let Err(error) = run() {
        eprintln!("error: {error}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args = parse()?;
    // SAFETY: before Bevy starts any thread.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    if let Some(rounds) = args.bench {
        return bench(&args, rounds);
    }
    let capture =
        |name: &str, mode, force_refine, composite| Capture { name: name.into(), mode, force_refine, composite };
    let captures = vec![
        capture("reference", Mode::Reference, false, false),
        capture(args.mode.name(), args.mode, false, true),
        capture(&format!("{}-forced", args.mode.name()), args.mode, true, false),
    ];
    let (width, height) = args.size;
    let images = common::render(args.size, &args.scene, captures)?;
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let reference = &images[0].pixels;
    for image in &images {
        let path = args.out.join(format!("{}.png", image.capture.name));
        let rgba: Vec<u8> = image
            .pixels
            .iter()
            .flat_map(|p| [0, 1, 2].map(|c| mrsl_lab::color::linear_to_srgb8(p[c])).into_iter().chain([255]))
            .collect();
        image::save_buffer(&path, &rgba, width, height, image::ExtendedColorType::Rgba8)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        if let Some(composite) = &image.composite {
            let path = args.out.join(format!("{}-composite.png", image.capture.name));
            image::save_buffer(&path, composite.as_flattened(), width, height, image::ExtendedColorType::Rgba8)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            println!("wrote {} (the camera's image: the output over Bevy's)", path.display());
        }
        let quality = mrsl_lab::metrics::compare(&image.pixels, reference, width, height).map_err(|e| e.to_string())?;
        let shaded = image.stats.as_ref().map(|s| format!(", shaded {:.3}", s.shaded_fraction)).unwrap_or_default();
        println!(
            "wrote {} ({}: PSNR {:.2} dB, MSSIM {:.4} against the reference{shaded})",
            path.display(),
            image.capture.name,
            quality.psnr,
            quality.mssim
        );
    }
    Ok(())
}

/// Frames per timed block.
const BENCH_FRAMES: u32 = 30;

fn bench(args: &Args, rounds: usize) -> Result<(), String> {
    let (width, height) = args.size;
    eprintln!(
        "timing {rounds} rounds of {BENCH_FRAMES} frames without mrsl, in the reference and in {} at {width}x{height}",
        args.mode.name()
    );
    let times = common::bench::bench(args.size, &args.scene, args.mode, rounds, BENCH_FRAMES)?;
    let ms = |v: &[f64]| common::bench::median(v.to_vec());
    println!(
        "frame time (median of {} blocks): without mrsl {:.2} ms, reference {:.2} ms, {} {:.2} ms",
        times.rounds(),
        ms(&times.off),
        ms(&times.reference),
        args.mode.name(),
        ms(&times.adaptive)
    );
    println!(
        "the mrsl pass: reference {:.2} ms, {} {:.2} ms",
        ms(&times.reference) - ms(&times.off),
        args.mode.name(),
        ms(&times.adaptive) - ms(&times.off)
    );
    println!(
        "speedup over the reference (median of per-round ratios): the pass {:.2}x, the frame {:.2}x",
        times.pass_speedup(),
        times.frame_speedup()
    );
    Ok(())
}
