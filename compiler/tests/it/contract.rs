//! The compiler–runtime contract round-trips: what `mrslc compile -o DIR`
//! writes (kernels and `STEM.layout.json`) reads back as the very program
//! the compiler produced, and a layout of another format version or with an
//! unknown format name is refused instead of being guessed at.

use mrsl::{CompiledProgram, Layout, Options};
use std::path::PathBuf;

fn examples() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut out: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mrsl"))
        .map(|p| (p.file_stem().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&p).unwrap()))
        .collect();
    out.sort();
    out
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrsl-contract-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn compiled_programs_read_back_from_their_files_unchanged() {
    let examples = examples();
    assert!(examples.len() >= 6);
    for (stem, source) in &examples {
        let program = mrsl::compile(source, &Options::default()).unwrap();
        let dir = temp_dir(stem);
        let written = program.compiled.write_dir(&dir, stem).unwrap();
        assert_eq!(written.len(), program.kernels.len() + 1, "{stem}: a file per kernel and the layout");
        // The layout alone, from its JSON text.
        let json = std::fs::read_to_string(dir.join(format!("{stem}.layout.json"))).unwrap();
        assert_eq!(Layout::from_json(&json).unwrap(), program.layout, "{stem}: layout JSON round trip");
        // The whole program, with the stem found or named.
        assert_eq!(CompiledProgram::read_dir(&dir, None).unwrap(), program.compiled, "{stem}");
        assert_eq!(CompiledProgram::read_dir(&dir, Some(stem)).unwrap(), program.compiled, "{stem}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn foreign_or_broken_layouts_are_refused() {
    let program = mrsl::compile(&examples()[0].1, &Options::default()).unwrap();
    let json = program.layout.to_json();
    let other_version = json.replacen(mrsl_abi::LAYOUT_FORMAT, "mrsl-layout/2", 1);
    let message = Layout::from_json(&other_version).unwrap_err();
    assert!(message.contains("mrsl-layout/2") && message.contains(mrsl_abi::LAYOUT_FORMAT), "{message}");
    // A format the runtime could only guess at is an error, not rgba32float.
    let first_format = program.layout.channels[0].format.name();
    let bad_format = json.replacen(&format!("\"format\": \"{first_format}\""), "\"format\": \"bgra8unorm\"", 1);
    assert_ne!(bad_format, json);
    assert!(Layout::from_json(&bad_format).unwrap_err().contains("bgra8unorm"));
    let bad_type = json.replacen("\"type\": \"float3\"", "\"type\": \"vec3\"", 1);
    assert_ne!(bad_type, json);
    assert!(Layout::from_json(&bad_type).unwrap_err().contains("vec3"));

    // A directory without a program, and one with two, say so.
    let dir = temp_dir("empty");
    let err = CompiledProgram::read_dir(&dir, None).unwrap_err();
    assert!(err.to_string().contains("mrslc compile"), "{err}");
    program.compiled.write_dir(&dir, "a").unwrap();
    program.compiled.write_dir(&dir, "b").unwrap();
    let err = CompiledProgram::read_dir(&dir, None).unwrap_err();
    assert!(err.to_string().contains("a, b"), "{err}");
    std::fs::write(dir.join("c.layout.json"), "{}").unwrap();
    let err = CompiledProgram::read_dir(&dir, Some("c")).unwrap_err();
    assert!(err.to_string().contains("no `format` field"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The stage group (group 2) each kernel declares is exactly the one every
/// pass of the plan that runs it lists (`Pass::bindings`), which is what the
/// runtime builds its bind group layouts from: same binding numbers, same
/// storage access, same storage-texture formats. Every compiled kernel runs
/// in some pass.
#[test]
fn kernels_declare_the_stage_bindings_of_the_contract() {
    use mrsl_abi::{BindingType as StageResource, GROUP_STAGE, KernelRef, TextureFormat};
    let prefix = format!("@group({GROUP_STAGE}) @binding(");
    let packed = Options { packed_records: true, ..Options::default() };
    for ((stem, source), options) in
        examples().into_iter().flat_map(|e| [(e.clone(), Options::default()), (e, packed.clone())])
    {
        let program = mrsl::compile(&source, &options).unwrap();
        for kernel in &program.kernels {
            let mut declared: Vec<(u32, StageResource)> = kernel
                .wgsl
                .lines()
                .filter_map(|line| line.strip_prefix(&prefix))
                .map(|rest| {
                    let (binding, decl) = rest.split_once(") ").unwrap();
                    let resource = if decl.starts_with("var<storage, read>") {
                        StageResource::Buffer { read_only: true }
                    } else if decl.starts_with("var<storage, read_write>") {
                        StageResource::Buffer { read_only: false }
                    } else if decl.contains("texture_2d<u32>") {
                        StageResource::UintTexture
                    } else if decl.contains("texture_2d_array<u32>") {
                        StageResource::RecordTexture
                    } else if decl.contains("texture_storage_2d_array<rgba32uint, write>") {
                        StageResource::RecordStorageTexture
                    } else if decl.contains("texture_storage_2d_array<r32uint, read_write>") {
                        StageResource::WordTexture
                    } else if decl.contains("texture_storage_2d_array<rgba32uint, read_write>") {
                        StageResource::PackedWordTexture
                    } else {
                        let format = decl.split("texture_storage_2d<").nth(1).unwrap().split(',').next().unwrap();
                        StageResource::StorageTexture { format: format.parse::<TextureFormat>().unwrap() }
                    };
                    (binding.parse().unwrap(), resource)
                })
                .collect();
            declared.sort_by_key(|(binding, _)| *binding);
            let kernel_ref = KernelRef::new(kernel.kind, kernel.block_size);
            let passes: Vec<_> =
                program.layout.plan.modes.iter().flat_map(|m| m.passes()).filter(|p| p.kernel == kernel_ref).collect();
            assert!(!passes.is_empty(), "{stem}: no pass runs the {kernel_ref} kernel");
            for pass in passes {
                let contract: Vec<(u32, StageResource)> = pass.bindings.iter().map(|b| (b.binding, b.ty)).collect();
                assert_eq!(declared, contract, "{stem}: {kernel_ref} kernel in `{}`", pass.label);
            }
        }
    }
}

/// Every kernel's main entry point declares the workgroup size of the
/// contract (`KernelKind::workgroup_size`), which the dispatch geometry
/// assumes: a tile of 8x8 pixels per workgroup, one pixel per lane, or in
/// the block fine kernels `FINE_PIXELS_PER_LANE` pixels of one block per lane.
#[test]
fn main_entry_points_declare_the_workgroup_size_of_the_contract() {
    let packed = Options { packed_records: true, ..Options::default() };
    for ((stem, source), options) in
        examples().into_iter().flat_map(|e| [(e.clone(), Options::default()), (e, packed.clone())])
    {
        let program = mrsl::compile(&source, &options).unwrap();
        for kernel in &program.kernels {
            let entry = format!("fn {}(", kernel.kind.main_entry_point());
            let lines: Vec<&str> = kernel.wgsl.lines().collect();
            let at = lines.iter().position(|l| l.starts_with(&entry)).unwrap_or_else(|| panic!("{stem}: {entry}"));
            let [x, y, z] = kernel.kind.workgroup_size();
            assert_eq!(
                lines[at - 1],
                format!("@compute @workgroup_size({x}, {y}, {z})"),
                "{stem}: {} kernel ({:?})",
                kernel.kind,
                kernel.block_size
            );
        }
    }
}

/// The layout's cost model counts what one evaluation executes: a loop's
/// body once per iteration of its static trip count, a texture read as 4,
/// and a derivative as its operand evaluated again at the neighbours.
#[test]
fn the_cost_model_counts_loop_trips_texture_reads_and_neighbour_evaluations() {
    let ops = |body: &str| {
        let source = format!(
            "in float3 normal;\nuniform texture2d t;\nuniform sampler s;\ncoarse effect float e {{\n    float acc = 0.0;\n{body}\n    e = acc;\n}}\nfine out float4 color = float4(e);\n"
        );
        let program = mrsl::compile(&source, &Options::default()).unwrap_or_else(|d| panic!("{d:?}"));
        program.layout.effects.iter().find(|x| x.name == "e").unwrap().operations.unwrap()
    };
    let none = ops("");
    let once = ops("    acc += normal.x;");
    let step = once - none;
    assert!(step > 0);
    // Eight trips of the same statement, plus the loop's own condition and step per trip.
    let looped = ops("    for (int i = 0; i < 8; i++) { acc += normal.x; }");
    assert!(looped >= none + 8 * step && looped <= none + 8 * (step + 8), "{none} {step} {looped}");
    let sixteen = ops("    for (int i = 0; i < 16; i++) { acc += normal.x; }");
    assert_eq!(
        sixteen - none,
        2 * (looped - none) - (ops("    for (int i = 0; i < 0; i++) { acc += normal.x; }") - none)
    );
    // A texture read adds its weight over the same call shape without a texture.
    let loaded = ops("    acc += sample_level(t, s, normal.xy, 0.0).x;");
    let plain = ops("    acc += max(normal.x, normal.y);");
    assert!(loaded > plain, "{loaded} {plain}");
    // A derivative evaluates its operand twice more per difference.
    let derivative = ops("    acc += ddx(normal.x * normal.y);");
    assert!(derivative > once + 4, "{derivative} {once}");
}

/// `value_operations` counts what a per-pixel kernel executes: the value
/// without the statements that only decide the refine flag. A predicate on
/// a derivative re-evaluates its operand at the neighbours, so it costs in
/// `operations` and not in `value_operations`; an effect that cannot refine
/// counts the same in both.
#[test]
fn the_cost_model_counts_the_value_alone_for_per_pixel_evaluations() {
    let source = "in float3 normal;\n\
        coarse effect float heavy {\n    float acc = 0.0;\n    for (int i = 0; i < 16; i++) { acc += sin(normal.x * float(i)); }\n    heavy = acc;\n}\n\
        coarse effect float shade {\n    shade = heavy * 0.5;\n    if (fwidth(heavy) > 0.1) refine;\n}\n\
        fine out float4 color = float4(shade);\n";
    let program = mrsl::compile(source, &Options::default()).unwrap_or_else(|d| panic!("{d:?}"));
    let costs = |name: &str| {
        let e = program.layout.effects.iter().find(|x| x.name == name).unwrap();
        (e.operations.unwrap(), e.value_operations.unwrap())
    };
    let (heavy, heavy_value) = costs("heavy");
    assert_eq!(heavy, heavy_value, "`heavy` cannot refine");
    let (shade, shade_value) = costs("shade");
    assert!(shade_value < 10, "the value is a product: {shade_value}");
    // The predicate evaluates `heavy` at four neighbours (two per difference).
    assert!(shade >= shade_value + 4 * heavy, "{shade} {shade_value} {heavy}");
}

/// The refine mask's bit k is coarse effect `stats.counters[k]`, which
/// follows the dependency order, not the declaration order of
/// `Layout::effects` (and `Stats::effects`); `Layout::refine_mask_bit` and
/// `Layout::decode_refine_mask` name the bits so that engines need not know.
#[test]
fn refine_mask_bits_are_decoded_by_effect_name() {
    use mrsl_abi::{BACKGROUND_MARK, RefineMaskTexel};
    let source = "in float3 normal;\n\
                  coarse effect float shade = lit * 0.5;\n\
                  coarse effect float lit = saturate(normal.y);\n\
                  coarse effect float rim = 1.0 - saturate(normal.z);\n\
                  coarse effect float unused = normal.x;\n\
                  fine out float4 color = float4(shade, lit, rim, 1.0);\n";
    let program = mrsl::compile(source, &Options::for_modes(&[mrsl::Mode::Coarse4x4])).unwrap();
    let layout = &program.layout;
    let declared: Vec<&str> = ["shade", "lit", "rim"].into();
    assert_ne!(layout.stats.counters, declared, "the test wants the two orders to differ");
    for (k, name) in layout.stats.counters.iter().enumerate() {
        assert_eq!(layout.refine_mask_bit(name), Some(k as u32), "{name}");
    }
    // Only live coarse effects have a bit.
    for name in ["unused", "color", "normal", "nope"] {
        assert_eq!(layout.refine_mask_bit(name), None, "{name}");
    }
    let bit = |name| 1u32 << layout.refine_mask_bit(name).unwrap();
    // Bits beyond the program's coarse effects are ignored.
    let texel = [bit("rim") | bit("shade") | 1 << 20, bit("lit")];
    assert_eq!(
        layout.decode_refine_mask(texel),
        RefineMaskTexel::Shaded { per_pixel: vec!["shade", "rim"], from_2x2: vec!["lit"] }
    );
    assert_eq!(layout.decode_refine_mask([0, 0]), RefineMaskTexel::Shaded { per_pixel: vec![], from_2x2: vec![] });
    assert_eq!(layout.decode_refine_mask(BACKGROUND_MARK), RefineMaskTexel::Background);
}
