//! `mrslc` as a user runs it: the binary over real programs on the machine's
//! GPU (lavapipe in CI), checking the files it writes and what it says.
//! Without an adapter the tests are reported as skipped (ignored), with the
//! reason printed; with `CI=true` a missing adapter is a failure.

use libtest_mimic::{Arguments, Trial};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Three outputs and a coarse effect: the hierarchical and checkerboard
/// kernels bind five storage textures, one more than WebGPU's default
/// limit, so a device at the default limits cannot run those two modes.
const FIVE_STORAGE_TEXTURES: &str = "in float3 normal;\ncoarse effect float d = saturate(normal.y);\n\
    fine out float4 a = float4(d);\nfine out float4 b = float4(d * 0.5);\nfine out float4 c = float4(normal, 1.0);\n";

const TESTS: &[(&str, fn())] = &[
    ("render_all_skips_only_the_modes_the_device_cannot_run", render_all_skips_only_the_modes_the_device_cannot_run),
    ("heatmaps_mark_background_pixels_grey", heatmaps_mark_background_pixels_grey),
    ("gpu_bench_script_writes_the_suite_report", gpu_bench_script_writes_the_suite_report),
];

fn main() {
    let args = Arguments::from_args();
    let gpu = gpu_available();
    let trials = TESTS
        .iter()
        .map(|&(name, test)| match &gpu {
            Ok(()) => Trial::test(name, move || {
                test();
                Ok(())
            }),
            Err(_) => Trial::test(name, || Ok(())).with_ignored_flag(true),
        })
        .collect();
    libtest_mimic::run(&args, trials).exit();
}

/// Whether `mrslc` will find an adapter (as it looks for one). Prints why
/// the tests are skipped when it will not; panics under `CI=true`.
fn gpu_available() -> Result<(), String> {
    // SAFETY: no other thread exists yet.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    match mrsl_lab::gpu::Gpu::new() {
        Ok(gpu) => {
            println!("mrslc tests on {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
            Ok(())
        }
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => panic!("CI=true but no GPU adapter: {e}"),
        Err(e) => {
            println!("SKIPPING {} mrslc tests (reported as ignored below): no GPU adapter ({e})", TESTS.len());
            Err(e.to_string())
        }
    }
}

/// A fresh directory for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrslc-test-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `mrslc ARGS` to completion.
fn mrslc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mrslc")).args(args).output().expect("mrslc runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// `--mode all` renders every mode the device runs and names each it skips
/// with the runtime's reason; the same mode asked for alone is an error.
fn render_all_skips_only_the_modes_the_device_cannot_run() {
    let dir = scratch("skips");
    let program = dir.join("three.mrsl");
    std::fs::write(&program, FIVE_STORAGE_TEXTURES).unwrap();
    let (program, out) = (program.to_str().unwrap(), dir.to_str().unwrap());
    let all = mrslc(&["render", program, "--mode", "all", "--size", "24x16", "--out", out]);
    let said = stderr(&all);
    assert!(all.status.success(), "{said}");
    for skipped in ["hierarchical", "checkerboard"] {
        // The reason is the device's, over several lines.
        let start =
            said.find(&format!("skipped {skipped}:")).unwrap_or_else(|| panic!("no `skipped {skipped}:` in:\n{said}"));
        let reason = said[start..].split("\nskipped ").next().unwrap();
        assert!(reason.contains("cannot run") && reason.contains("StorageTextures"), "{reason}");
    }
    let runs = read_json(&dir.join("three.stats.json"));
    let modes: Vec<&str> = runs.as_array().unwrap().iter().map(|r| r["mode"].as_str().unwrap()).collect();
    assert_eq!(modes, ["reference", "coarse2x2", "coarse4x4", "dynamic", "rate-image"]);
    for mode in &modes {
        assert!(dir.join(format!("three.{mode}.png")).is_file(), "{mode}'s image");
    }
    assert!(!dir.join("three.hierarchical.png").exists());

    let alone = mrslc(&["render", program, "--mode", "hierarchical", "--size", "24x16", "--out", out]);
    let said = stderr(&alone);
    assert!(!alone.status.success(), "{said}");
    assert!(said.contains("mode `hierarchical` is not supported by this program"), "{said}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The heatmap of the demo (whose sky is background) is grey exactly at
/// the background pixels the statistics count.
fn heatmaps_mark_background_pixels_grey() {
    const GREY: [u8; 3] = [150, 150, 150];
    let dir = scratch("background");
    let out = dir.to_str().unwrap();
    let (w, h) = (64u32, 36u32);
    let size = format!("{w}x{h}");
    let run = mrslc(&["render", "--size", &size, "--out", out]);
    assert!(run.status.success(), "{}", stderr(&run));
    let stats = read_json(&dir.join("demo.stats.json"));
    let background = stats[0]["background_pixels"].as_u64().unwrap();
    assert!(background > 0, "the demo's sky is background: {stats}");
    let heatmap = image::open(dir.join("demo.coarse4x4.heatmap.png")).unwrap().to_rgb8();
    let grey = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).filter(|&(x, y)| heatmap.get_pixel(x, y).0 == GREY);
    assert_eq!(grey.count() as u64, background);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `scripts/gpu-bench.sh OUTDIR` at a small size (with this build's mrslc,
/// not a release build): one markdown and one JSON file, every mode over
/// Sponza with finite paired figures, the block modes' floors, and a scene
/// whose file is missing listed as not measured rather than failing the run.
fn gpu_bench_script_writes_the_suite_report() {
    let dir = scratch("gpu-bench");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/gpu-bench.sh");
    let missing = dir.join("missing.toml");
    let run = Command::new("sh")
        .arg(script)
        .arg(&dir)
        .args(["--size", "48x27", "--runs", "1", "--scene", "sponza", "--scene"])
        .arg(&missing)
        .env("MRSLC", env!("CARGO_BIN_EXE_mrslc"))
        .output()
        .expect("the script runs");
    let said = stderr(&run);
    assert!(run.status.success(), "{said}");
    let mut files: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    files.sort();
    assert_eq!(files, ["suite.json", "suite.md"]);
    let suite = read_json(&dir.join("suite.json"));
    assert_eq!(suite["format"], "mrsl-suite/1");
    assert!(suite["device"]["name"].as_str().is_some_and(|n| !n.is_empty()));
    let scenes = suite["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1, "{suite}");
    assert_eq!((scenes[0]["scene"].as_str(), scenes[0]["width"].as_u64()), (Some("sponza"), Some(48)));
    let modes = scenes[0]["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 6, "every adaptive mode");
    for m in modes {
        let figure = |key: &str| m[key].as_f64().unwrap_or_else(|| panic!("{key} of {m}"));
        for key in ["speedup", "time_ratio", "forced_ratio", "wall_ms"] {
            assert!(figure(key).is_finite() && figure(key) > 0.0, "{key} of {m}");
        }
        let mssim = m["metrics"]["mssim"].as_f64().unwrap();
        assert!(mssim > 0.5 && mssim <= 1.0, "{m}");
        // The floor is measured for the modes whose adaptive work one kernel edit removes.
        let floored = matches!(m["mode"].as_str(), Some("coarse2x2" | "coarse4x4" | "hierarchical"));
        assert_eq!(m["floor_ratio"].is_f64(), floored, "{m}");
    }
    let skipped = suite["skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 1);
    assert!(skipped[0]["reason"].as_str().unwrap().contains("missing.toml"), "{skipped:?}");
    let md = std::fs::read_to_string(dir.join("suite.md")).unwrap();
    for heading in ["## 48x27", "### sponza (48x27)", "| geometric mean speedup |", "## Not measured"] {
        assert!(md.contains(heading), "{heading} in:\n{md}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
