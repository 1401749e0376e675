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
    ("workload_bounds_script_refines_less_in_each_variant", workload_bounds_script_refines_less_in_each_variant),
    ("ablation_times_every_variant_on_the_device", ablation_times_every_variant_on_the_device),
    (
        "gbuffer_exports_the_channels_and_what_the_program_binds",
        gbuffer_exports_the_channels_and_what_the_program_binds,
    ),
    (
        "gbuffer_exports_the_rig_and_the_shadow_map_of_a_mesh_scene",
        gbuffer_exports_the_rig_and_the_shadow_map_of_a_mesh_scene,
    ),
    ("render_raw_writes_the_texels_the_png_was_made_from", render_raw_writes_the_texels_the_png_was_made_from),
    ("every_mode_renders_alone", every_mode_renders_alone),
    ("the_demo_lights_a_program_written_for_the_rig", the_demo_lights_a_program_written_for_the_rig),
    ("scene_channels_are_checked_at_their_declarations", scene_channels_are_checked_at_their_declarations),
    (
        "gbuffer_exports_a_scene_files_images_with_every_mip_level",
        gbuffer_exports_a_scene_files_images_with_every_mip_level,
    ),
];

/// Each mode renders asked for alone (the rate-image mode's rates settle
/// from a first frame of the reference, whose kernel it compiles too): the
/// built-in demo, each mode's image and statistics written.
fn every_mode_renders_alone() {
    let dir = scratch("alone");
    let out = dir.to_str().unwrap();
    for mode in mrsl_abi::Mode::ALL {
        let name = mode.to_string();
        let run = mrslc(&["render", "--mode", &name, "--size", "24x16", "--out", out]);
        assert!(run.status.success(), "{name} alone:\n{}", stderr(&run));
        assert!(dir.join(format!("demo.{name}.png")).is_file(), "{name}'s image");
        let runs = read_json(&dir.join("demo.stats.json"));
        let modes: Vec<&str> = runs.as_array().unwrap().iter().map(|r| r["mode"].as_str().unwrap()).collect();
        assert_eq!(modes, [name.as_str()], "the statistics of the mode asked for, alone");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A channel the scene lacks, or declared with a scalar type its texture
/// cannot give, is an error at the program's `in` declaration before
/// anything renders or is written: with the scene's channels and a "did you
/// mean", or the declaration to write instead; a uniform without a value,
/// at its `uniform` declaration with the `--set` to pass. `check --scene`
/// reports the same without rendering.
fn scene_channels_are_checked_at_their_declarations() {
    let dir = scratch("channels");
    let cases = [
        (
            "typo.mrsl",
            "in float3 abledo;\n",
            "abledo",
            &["error[E0801]", "typo.mrsl:1:11", "did you mean `albedo`?", "material (uint)"][..],
        ),
        (
            "kind.mrsl",
            "in float material;\n",
            "float3(material)",
            &["error[E0802]", "kind.mrsl:1:10", "help: declare `in uint material;`"][..],
        ),
    ];
    for (file, declaration, read, expected) in cases {
        let program = dir.join(file);
        let source = format!(
            "{declaration}in float3 normal;\ncoarse effect float3 lit = {read} * max(normal.y, 0.0);\nfine out float4 color = float4(lit, 1.0);\n"
        );
        std::fs::write(&program, source).unwrap();
        let out = dir.join("out");
        let run = mrslc(&["render", program.to_str().unwrap(), "--size", "24x16", "--out", out.to_str().unwrap()]);
        let said = stderr(&run);
        assert!(!run.status.success(), "{file}: {said}");
        for text in expected {
            assert!(said.contains(text), "{file}: no `{text}` in:\n{said}");
        }
        assert!(!out.exists(), "{file}: nothing is written when the program cannot be bound");
        // `check --scene` says the same without rendering.
        let checked = mrslc(&["check", program.to_str().unwrap(), "--scene", "demo"]);
        let said = stderr(&checked);
        assert_eq!(checked.status.code(), Some(1), "{file}: {said}");
        for text in expected {
            assert!(said.contains(text), "{file}, check --scene: no `{text}` in:\n{said}");
        }
    }
    // A uniform without a default (an array takes none) that neither the scene nor --set gives.
    let program = dir.join("unset.mrsl");
    let source = "in float3 normal;\nuniform float4 tint[2];\ncoarse effect float3 lit = tint[0].rgb * max(normal.y, 0.0);\n\
        fine out float4 color = float4(lit, 1.0);\n";
    std::fs::write(&program, source).unwrap();
    let out = dir.join("out");
    let run = mrslc(&["render", program.to_str().unwrap(), "--size", "24x16", "--out", out.to_str().unwrap()]);
    let said = stderr(&run);
    assert!(!run.status.success(), "{said}");
    for text in ["error[E0803]", "unset.mrsl:2:16", "--set tint=V1,V2,...` (8 numbers for a float4[2])"] {
        assert!(said.contains(text), "no `{text}` in:\n{said}");
    }
    assert!(!out.exists(), "nothing is written when a uniform has no value");
    let set = ["--set", "tint=1,0.5,0.25,1,0,0,0,0"];
    let checked = mrslc(&["check", program.to_str().unwrap(), "--scene", "demo"]);
    assert!(checked.status.code() == Some(1) && stderr(&checked).contains("error[E0803]"), "{}", stderr(&checked));
    let checked = mrslc(&["check", program.to_str().unwrap(), "--scene", "demo", set[0], set[1]]);
    assert!(checked.status.success() && stderr(&checked).contains("ok on scene `demo`"), "{}", stderr(&checked));
    let run = mrslc(&[
        "render",
        program.to_str().unwrap(),
        "--size",
        "24x16",
        "--out",
        out.to_str().unwrap(),
        set[0],
        set[1],
    ]);
    assert!(run.status.success(), "with --set: {}", stderr(&run));
    // The same values as the array's default, `= { ... }`: no --set needed,
    // and the image is the one --set gave.
    let defaulted = dir.join("defaulted.mrsl");
    let source = source.replace("tint[2];", "tint[2] = { float4(1.0, 0.5, 0.25, 1.0), float4(0.0) };");
    std::fs::write(&defaulted, source).unwrap();
    let run = mrslc(&["render", defaulted.to_str().unwrap(), "--size", "24x16", "--out", out.to_str().unwrap()]);
    assert!(run.status.success(), "with a default: {}", stderr(&run));
    let read = |stem: &str| std::fs::read(out.join(format!("{stem}.coarse4x4.png"))).unwrap();
    assert!(read("defaulted") == read("unset"), "the default renders as the values set");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A many-light program written for the mesh scenes' rig (uniform arrays
/// without defaults) renders on the built-in demo the first time: the demo
/// carries a light rig too.
fn the_demo_lights_a_program_written_for_the_rig() {
    let dir = scratch("rig");
    let program = dir.join("lights.mrsl");
    let source = "in float3 position;\nin float3 normal;\nuniform float4 light_pos[8];\nuniform float4 light_color[8];\n\
        uniform int light_count;\ncoarse effect float3 lights {\n    float3 sum = float3(0.0);\n\
        for (int i = 0; i < 8; i++) {\n        if (i >= light_count) break;\n        float3 d = light_pos[i].xyz - position;\n\
        sum += light_color[i].rgb * max(dot(normalize(normal), normalize(d)), 0.0) * saturate(1.0 - length(d) / light_pos[i].w);\n\
        }\n    lights = sum;\n}\nfine out float4 color = float4(lights, 1.0);\n";
    std::fs::write(&program, source).unwrap();
    let out = dir.to_str().unwrap();
    let run = mrslc(&["render", program.to_str().unwrap(), "--size", "48x27", "--mode", "reference", "--out", out]);
    assert!(run.status.success(), "{}", stderr(&run));
    let image = image::open(dir.join("lights.reference.png")).unwrap().to_rgb8();
    let lit = image.pixels().filter(|p| p.0.iter().any(|&c| c > 16)).count();
    assert!(lit > image.pixels().len() / 4, "the rig lights the demo: {lit} lit pixels of {}", image.pixels().len());
    std::fs::remove_dir_all(&dir).unwrap();
}

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
    assert_eq!(modes, ["reference", "coarse2x2", "coarse4x4", "dynamic", "rate-image", "multi-rate"]);
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
    assert_eq!(suite["format"], "mrsl-suite/2");
    assert!(suite["device"]["name"].as_str().is_some_and(|n| !n.is_empty()));
    let scenes = suite["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1, "{suite}");
    assert_eq!((scenes[0]["scene"].as_str(), scenes[0]["width"].as_u64()), (Some("sponza"), Some(48)));
    let modes = scenes[0]["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 9, "every adaptive mode, and the block modes' other plan");
    let others: Vec<&str> =
        modes.iter().filter(|m| !m["other_plan"].is_null()).map(|m| m["mode"].as_str().unwrap()).collect();
    assert_eq!(others, ["coarse2x2", "coarse4x4"]);
    for m in modes {
        let figure = |key: &str| m[key].as_f64().unwrap_or_else(|| panic!("{key} of {m}"));
        for key in ["speedup", "time_ratio", "forced_ratio", "wall_ms", "reference_ms"] {
            assert!(figure(key).is_finite() && figure(key) > 0.0, "{key} of {m}");
        }
        let dispatches = m["figures"]["dispatches"].as_u64().unwrap();
        assert!(dispatches >= 1, "{m}");
        assert!(m["figures"]["global_bytes_per_pixel"].as_f64().is_some_and(|b| b > 0.0), "{m}");
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

/// `scripts/workload-bounds.sh OUTDIR` at a small size over Sponza (with
/// this build's mrslc): a row per mode and variant with a finite speed and
/// quality, and each variant evaluating less of the coarse work than the
/// defaults (so its uniforms and the keys it removes still exist in the
/// workload: a renamed predicate uniform fails the render, a key no longer
/// spelled as the script expects fails the script).
fn workload_bounds_script_refines_less_in_each_variant() {
    let dir = scratch("workload-bounds");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/workload-bounds.sh");
    let run = Command::new("sh")
        .arg(script)
        .arg(&dir)
        .args(["--scene", "sponza", "--size", "48x27", "--rounds", "1"])
        .env("MRSLC", env!("CARGO_BIN_EXE_mrslc"))
        .output()
        .expect("the script runs");
    assert!(run.status.success(), "{}", stderr(&run));
    let md = std::fs::read_to_string(dir.join("bounds.md")).unwrap();
    // | scene | mode | variant | speed per round | median | MSSIM | coarse work evaluated |
    let rows: Vec<Vec<&str>> = md
        .lines()
        .filter(|l| l.starts_with("| sponza |"))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 6, "two modes, three variants:\n{md}");
    let number = |cell: &str| -> f64 { cell.trim_end_matches(['x', '%']).parse().unwrap_or_else(|_| panic!("{cell}")) };
    for row in &rows {
        assert!(number(row[4]) > 0.0 && number(row[4]).is_finite(), "{row:?}");
        assert!(number(row[5]) > 0.0 && number(row[5]) <= 1.0, "{row:?}");
    }
    for mode in ["coarse4x4", "hierarchical"] {
        let coarse = |variant: &str| {
            let row =
                rows.iter().find(|r| r[1] == mode && r[2] == variant).unwrap_or_else(|| panic!("{mode} {variant}"));
            number(row[6])
        };
        assert!(coarse("predicates-off") <= coarse("defaults"), "{mode}:\n{md}");
        assert!(coarse("nothing-refined") < coarse("defaults"), "{mode}:\n{md}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `bench --ablation` at a small size, for the block modes' fine and coarse
/// passes (their CPU plan), their tile kernel (their GPU plan) and the
/// hierarchical kernel: every variant of the workload's kernels builds a
/// pipeline on the device and is timed (the unit tests only check that naga
/// accepts them), and none is left out as not applicable but those of the
/// other plan's kernels.
fn ablation_times_every_variant_on_the_device() {
    let dir = scratch("ablation");
    let tile_only = "tile: no samples, tile: no neighbour values, tile: no pixels";
    let fine_only = "compacted (added), coarse pass, no predicates";
    for (name, mode, plan, at_least, left_out) in [
        ("coarse4x4", "coarse4x4", "cpu", 24, Some(tile_only)),
        ("tile", "coarse4x4", "gpu", 15, Some(fine_only)),
        ("hierarchical", "hierarchical", "", 14, None),
    ] {
        let out = dir.join(name);
        let args = ["bench", "--ablation", "--modes", mode, "--scene", "sponza", "--size", "48x27", "--runs", "1"];
        let plan: &[&str] = if plan.is_empty() { &[] } else { &["--plan", plan] };
        let run = mrslc(&[&args[..], plan, &["-o", out.to_str().unwrap()]].concat());
        assert!(run.status.success(), "{mode}: {}", stderr(&run));
        let md = std::fs::read_to_string(out.join("ablation.md")).unwrap();
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| variant")).collect();
        assert!(rows.len() >= at_least, "{mode}: {} rows in\n{md}", rows.len());
        for row in &rows {
            let ms: f64 = row.split('|').nth(3).unwrap().trim().parse().unwrap_or_else(|_| panic!("{row}"));
            assert!(ms.is_finite() && ms > 0.0, "{mode}: {row}");
        }
        let not_applicable = md.lines().find_map(|l| l.strip_prefix("Not applicable to this program's kernel: "));
        match left_out {
            None => assert!(not_applicable.is_none(), "{name}: every variant applies to the workload:\n{md}"),
            Some(start) => assert!(
                not_applicable.is_some_and(|l| l.starts_with(start)),
                "{name}: only the other plan's variants are left out:\n{md}"
            ),
        }
    }
    let coarse = std::fs::read_to_string(dir.join("coarse4x4/ablation.md")).unwrap();
    for variant in ["| coarse pass, no predicates |", "| launches |"] {
        assert!(coarse.contains(variant), "{variant} in:\n{coarse}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Bytes per texel of the formats an export holds.
fn texel_bytes(format: &str) -> usize {
    match format {
        "rgba32float" | "rgba32uint" | "rgba32sint" => 16,
        "rg32float" | "rg32uint" | "rg32sint" => 8,
        "r32float" | "r32uint" | "r32sint" | "rgba8unorm" | "rgba8unorm-srgb" | "rg16float" => 4,
        other => panic!("unexpected format {other}"),
    }
}

/// `mrslc gbuffer`: the demo scene's channels are the lab's G-buffer (the
/// CPU one, padded to the texture formats), the textures the program
/// binds are the checker with its size and format, `--set` is listed with
/// its value, the sampler is described; a size past the limit is refused
/// and writes nothing.
fn gbuffer_exports_the_channels_and_what_the_program_binds() {
    let dir = scratch("gbuffer");
    let out = dir.join("export");
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/textured_materials.mrsl");
    let (w, h) = (40usize, 24usize);
    let run = mrslc(&["gbuffer", program, "--size", "40x24", "-o", out.to_str().unwrap(), "--set", "ambient=0.5"]);
    let said = stderr(&run);
    assert!(run.status.success(), "{said}");
    assert!(
        said.trim_end().ends_with(&format!("wrote {}", out.join("texture.roughness_map.0.bin").display())),
        "{said}"
    );
    let m = read_json(&out.join("gbuffer.json"));
    assert_eq!(m["format"], "mrsl-gbuffer/1");
    assert_eq!((m["scene"].as_str(), m["program"].as_str()), (Some("demo"), Some("textured_materials.mrsl")));
    assert_eq!(m["size"], serde_json::json!([40, 24]));
    let cpu = mrsl_lab::scene::Scene::Demo.render(w as u32, h as u32);
    let channels = m["channels"].as_array().unwrap();
    assert_eq!(channels.len(), cpu.channels.len());
    for c in channels {
        let (name, format) = (c["name"].as_str().unwrap(), c["format"].as_str().unwrap());
        let bytes = std::fs::read(out.join(c["file"].as_str().unwrap())).unwrap();
        assert_eq!(bytes.len(), w * h * texel_bytes(format), "{name}");
        let expected: Vec<u8> = match cpu.channel(name).unwrap_or_else(|| panic!("{name} is a channel of the demo")) {
            mrsl_lab::gbuffer::ChannelData::Uint(values) => bytemuck::cast_slice(values).to_vec(),
            mrsl_lab::gbuffer::ChannelData::Float { components, data } => {
                let stride = texel_bytes(format) / 4;
                let padded =
                    data.chunks(*components as usize).flat_map(|p| (0..stride).map(|k| *p.get(k).unwrap_or(&0.0)));
                padded.flat_map(f32::to_le_bytes).collect()
            }
        };
        assert!(bytes == expected, "{name}: the file is not the lab's G-buffer");
    }
    assert_eq!(m["uniforms"], serde_json::json!([{ "name": "ambient", "type": "float", "values": [0.5] }]));
    let textures = m["textures"].as_array().unwrap();
    let names: Vec<&str> = textures.iter().map(|t| t["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["albedo_map", "roughness_map"]);
    for t in textures {
        assert_eq!((t["format"].as_str(), &t["size"]), (Some("rgba8unorm-srgb"), &serde_json::json!([64, 64])));
        let mip = &t["mips"][0];
        assert_eq!(std::fs::read(out.join(mip["file"].as_str().unwrap())).unwrap().len(), 64 * 64 * 4);
    }
    let sampler = serde_json::json!([{ "name": "linear", "address_mode": "repeat", "mag_filter": "linear",
                                       "min_filter": "linear", "mipmap_filter": "linear" }]);
    assert_eq!(m["samplers"], sampler);
    let warnings = m["warnings"].as_array().unwrap();
    assert!(warnings.iter().any(|w| w.as_str().unwrap().contains("`albedo_map` gets a procedural 64x64 checker")));

    let big = dir.join("big");
    let run = mrslc(&["gbuffer", "--size", "4000x3000", "-o", big.to_str().unwrap()]);
    let said = stderr(&run);
    assert!(!run.status.success(), "{said}");
    assert!(said.contains("an export is at most 8294400 pixels") && said.contains("4000x3000"), "{said}");
    assert!(!big.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Over Sponza, the rig's uniforms (as the runtime holds them) and the
/// shadow map, whose one level is listed with its size.
fn gbuffer_exports_the_rig_and_the_shadow_map_of_a_mesh_scene() {
    let dir = scratch("gbuffer-sponza");
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/sponza_lights.mrsl");
    let run = mrslc(&["gbuffer", program, "--scene", "sponza", "--size", "32x18", "-o", dir.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let m = read_json(&dir.join("gbuffer.json"));
    let uniform = |name: &str| m["uniforms"].as_array().unwrap().iter().find(|u| u["name"] == name).cloned();
    let count = uniform("light_count").expect("the rig sets light_count");
    assert_eq!(count["type"], "int");
    let lights = count["values"][0].as_f64().unwrap();
    assert!(lights >= 1.0, "{count}");
    let positions = uniform("light_pos").expect("the rig sets light_pos");
    assert_eq!(positions["values"].as_array().unwrap().len() % 4, 0);
    assert_eq!(uniform("sun_view_proj").unwrap()["values"].as_array().unwrap().len(), 16);
    let shadow = &m["textures"][0];
    assert_eq!((shadow["name"].as_str(), shadow["format"].as_str()), (Some("shadow_map"), Some("rg16float")));
    let [sw, sh] = [0, 1].map(|k| shadow["size"][k].as_u64().unwrap() as usize);
    assert_eq!(shadow["mips"].as_array().unwrap().len(), 1);
    let bytes = std::fs::read(dir.join(shadow["mips"][0]["file"].as_str().unwrap())).unwrap();
    assert_eq!(bytes.len(), sw * sh * 4);
    assert!(bytes.iter().any(|&b| b != 0), "the shadow map holds distances");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `render --raw`: each output's texels, whose sRGB encoding is the PNG;
/// with `--force-refine` the rate-image mode at a uniform 2x2 rate writes
/// the reference's bytes exactly.
fn render_raw_writes_the_texels_the_png_was_made_from() {
    let dir = scratch("raw");
    let out = dir.to_str().unwrap();
    let (w, h) = (40usize, 24usize);
    let args = ["render", "--size", "40x24", "--mode", "reference,rate-image", "--uniform-rate", "2x2"];
    let run = mrslc(&[&args[..], &["--force-refine", "--raw", "--out", out]].concat());
    let said = stderr(&run);
    assert!(run.status.success(), "{said}");
    let mut raws = vec![];
    for mode in ["reference", "rate-image"] {
        let raw = dir.join(format!("demo.{mode}.color.bin"));
        assert!(said.contains(&format!("wrote {}", raw.display())), "{said}");
        let bytes = std::fs::read(&raw).unwrap();
        assert_eq!(bytes.len(), w * h * 16, "rgba32float");
        let png = image::open(dir.join(format!("demo.{mode}.png"))).unwrap().to_rgb8();
        let pixels: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        for (k, p) in pixels.iter().enumerate() {
            let expected = [0, 1, 2].map(|c| mrsl_lab::color::linear_to_srgb8(p[c]));
            assert_eq!(png.get_pixel((k % w) as u32, (k / w) as u32).0, expected, "{mode}, pixel {k}");
        }
        raws.push(bytes);
    }
    assert!(raws[0] == raws[1], "forced refinement is the reference, bit for bit");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene file's images, with every level of their mip chains (8x4 down
/// to 1x1), in the format each is bound as; the scene file's size applies
/// without `--size`, and the mesh scene's `camera_pos` is listed.
fn gbuffer_exports_a_scene_files_images_with_every_mip_level() {
    let dir = scratch("gbuffer-images");
    let quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(dir.join("quad.obj"), quad).unwrap();
    image::RgbImage::from_pixel(8, 4, image::Rgb([200, 120, 40])).save(dir.join("albedo.png")).unwrap();
    image::RgbImage::from_pixel(8, 4, image::Rgb([90, 90, 90])).save(dir.join("rough.png")).unwrap();
    let scene = dir.join("quad.toml");
    let text = "mesh = \"quad.obj\"\nsize = [24, 16]\n[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = 45\n\
                [uniforms]\nalbedo_map = \"albedo.png\"\nroughness_map = { image = \"rough.png\", srgb = false }\n";
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("export");
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/textured_materials.mrsl");
    let run = mrslc(&["gbuffer", program, "--scene", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let m = read_json(&out.join("gbuffer.json"));
    assert_eq!(m["size"], serde_json::json!([24, 16]), "the scene file's size");
    let camera = m["uniforms"].as_array().unwrap().iter().find(|u| u["name"] == "camera_pos").cloned();
    assert_eq!(camera.expect("the mesh scene sets camera_pos")["values"], serde_json::json!([0.0, 0.0, 3.0]));
    for (name, format, texel) in
        [("albedo_map", "rgba8unorm-srgb", [200, 120, 40, 255]), ("roughness_map", "rgba8unorm", [90, 90, 90, 255])]
    {
        let t = m["textures"].as_array().unwrap().iter().find(|t| t["name"] == name).unwrap().clone();
        assert_eq!((t["format"].as_str(), &t["size"]), (Some(format), &serde_json::json!([8, 4])), "{name}");
        let mips = t["mips"].as_array().unwrap();
        let sizes: Vec<&serde_json::Value> = mips.iter().map(|m| &m["size"]).collect();
        assert_eq!(
            sizes,
            [
                &serde_json::json!([8, 4]),
                &serde_json::json!([4, 2]),
                &serde_json::json!([2, 1]),
                &serde_json::json!([1, 1])
            ]
        );
        for (level, mip) in mips.iter().enumerate() {
            assert_eq!(mip["file"], format!("texture.{name}.{level}.bin"));
            let bytes = std::fs::read(out.join(mip["file"].as_str().unwrap())).unwrap();
            let [w, h] = [0, 1].map(|k| mip["size"][k].as_u64().unwrap() as usize);
            assert_eq!(bytes.len(), w * h * 4, "{name} level {level}");
            assert!(bytes.chunks(4).all(|t| t == texel), "{name} level {level}: {bytes:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
