//! Bad bindings give the typed error that names what is wrong, never a panic.

use crate::{compile, run};
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::{ChannelData, GBuffer, Scene};
use mrsl_runtime::{Bindings, CompiledProgram, DispatchOptions, Error, Mode, Shader};

const PROGRAM: &str = "
in float3 normal;
@key in uint material;
uniform float4 lights[4];
uniform float gain = 1.0;
coarse effect float d = saturate(dot(normal, lights[0].xyz)) * gain;
fine out float4 color = float4(d);
";

fn dispatch(gpu: &Gpu, shader: &mut Shader, bindings: &Bindings) -> Result<(), Error> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, DispatchOptions::new(Mode::Coarse4x4))
}

pub fn binding_mismatches_are_typed_errors(gpu: &Gpu) {
    let program = compile(PROGRAM);
    let gbuffer = Scene::Demo.render(16, 8);
    let channels = gbuffer.upload(gpu);
    let get = |name: &str| &channels.iter().find(|(n, _)| n == name).unwrap().1;
    let output = gpu.output_texture("color", (16, 8), wgpu::TextureFormat::Rgba32Float);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    let mut bindings = Bindings { size: (16, 8), ..Default::default() };
    bindings.outputs.insert("color".into(), &output);

    // Missing channel.
    assert_eq!(dispatch(gpu, &mut shader, &bindings), Err(Error::MissingChannel("normal".into())));
    // Wrong format: a uint texture where the program reads float3.
    bindings.channels.insert("normal".into(), get("material"));
    bindings.channels.insert("material".into(), get("material"));
    assert!(
        matches!(dispatch(gpu, &mut shader, &bindings), Err(Error::ChannelFormat { ref channel, .. }) if channel == "normal")
    );
    // A float2 texture cannot hold a float3 channel either.
    bindings.channels.insert("normal".into(), get("uv"));
    assert!(
        matches!(dispatch(gpu, &mut shader, &bindings), Err(Error::ChannelFormat { ref channel, .. }) if channel == "normal")
    );
    // Size mismatch.
    let small = Scene::Demo.render(8, 8).upload(gpu);
    bindings.channels.insert("normal".into(), &small.iter().find(|(n, _)| n == "normal").unwrap().1);
    assert!(matches!(
        dispatch(gpu, &mut shader, &bindings),
        Err(Error::SizeMismatch { ref name, found_width: 8, width: 16, .. }) if name == "normal"
    ));
    bindings.channels.insert("normal".into(), get("normal"));
    // A uniform with no default that was never set.
    assert_eq!(dispatch(gpu, &mut shader, &bindings), Err(Error::MissingUniform("lights".into())));
    // Setting uniforms: unknown names and wrong component counts.
    assert_eq!(shader.set_uniform("nope", &[1.0]), Err(Error::UnknownUniform("nope".into())));
    assert!(matches!(
        shader.set_uniform("lights", &[1.0; 3]),
        Err(Error::UniformComponents { expected: 16, found: 3, .. })
    ));
    shader.set_uniform("lights", &[0.5; 16]).unwrap();
    // Values the type does not hold, and typed setters of another type.
    assert!(matches!(
        shader.set_uniform("gain", &[f64::INFINITY]),
        Err(Error::UniformValue { index: 0, reason: "is not a finite number", .. })
    ));
    assert!(matches!(shader.set_uniform_u32("gain", &[1]), Err(Error::UniformType { given: "u32", .. })));
    shader.set_uniform_f32("gain", &[1.0]).unwrap();
    // Output of the wrong format.
    let wrong = gpu.output_texture("color", (16, 8), wgpu::TextureFormat::Rgba8Unorm);
    bindings.outputs.insert("color".into(), &wrong);
    assert!(
        matches!(dispatch(gpu, &mut shader, &bindings), Err(Error::OutputFormat { ref name, .. }) if name == "color")
    );
    bindings.outputs.insert("color".into(), &output);
    // Empty target.
    bindings.size = (0, 8);
    assert!(matches!(dispatch(gpu, &mut shader, &bindings), Err(Error::BadSize { .. })));
    // A target wider than the per-pixel record texture can be (8192 texels
    // a side), checked before any texture is looked at.
    bindings.size = (16384, 16384);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    match shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(Mode::Hierarchical)) {
        Err(Error::BadSize { reason, .. }) => {
            assert!(reason.contains("per-pixel record texture") && reason.contains("8192x8192"), "{reason}")
        }
        other => panic!("expected a size error, got {other:?}"),
    }
    // The same check without recording, per mode: the hierarchical mode
    // cannot make its records at that size; another mode can still render.
    assert!(matches!(shader.supports_size(Mode::Hierarchical, (16384, 16384)), Err(Error::BadSize { .. })));
    assert!(matches!(shader.supports_size(Mode::Hierarchical, (16, 8)), Ok(())));
    // A target whose 2x2 sample grid is wider than a texture side the runtime
    // relies on (8192): the record texture could not be made.
    bindings.size = (16384, 8);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    match shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(Mode::Coarse2x2)) {
        Err(Error::BadSize { reason, .. }) => {
            assert!(reason.contains("record texture") && reason.contains("8193x5"), "{reason}")
        }
        other => panic!("expected a size error, got {other:?}"),
    }
    bindings.size = (16, 8);
    // And with everything right, it runs.
    dispatch(gpu, &mut shader, &bindings).unwrap();
}

/// What an engine's own textures get wrong, found before anything is
/// recorded, each a typed error naming the binding and saying what to do:
/// a channel or output without the usage its binding needs, a channel
/// format of the right kind but not the right count (a 3-component format
/// for a `float3`), a depth format as a channel, an array or multisampled
/// texture, an output format that an `@format` would declare.
pub fn engine_textures_are_checked_before_recording(gpu: &Gpu) {
    let program = compile(PROGRAM);
    let size = (16, 8);
    let gbuffer = Scene::Demo.render(size.0, size.1);
    let channels = gbuffer.upload(gpu);
    let get = |name: &str| &channels.iter().find(|(n, _)| n == name).unwrap().1;
    let output = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    shader.set_uniform("lights", &[0.5; 16]).unwrap();
    let mut bindings = Bindings { size, ..Default::default() };
    bindings.channels.insert("material".into(), get("material"));
    bindings.outputs.insert("color".into(), &output);
    let texture = |format, usage| gpu.texture_2d("engine", size, format, usage);
    let sampled = wgpu::TextureUsages::TEXTURE_BINDING;
    let error = |bindings: &Bindings, shader: &mut Shader| match dispatch(gpu, shader, bindings) {
        Err(e) => (e.to_string(), e),
        Ok(()) => panic!("expected an error"),
    };

    // A G-buffer texture created without TEXTURE_BINDING (the trial's first finding).
    let unsampled = texture(wgpu::TextureFormat::Rgba32Float, wgpu::TextureUsages::COPY_DST);
    bindings.channels.insert("normal".into(), &unsampled);
    let (text, e) = error(&bindings, &mut shader);
    assert_eq!(e, Error::ChannelUsage { channel: "normal".into(), missing: "TEXTURE_BINDING" });
    assert!(text.contains("`normal`") && text.contains("add it to the texture's usage"), "{text}");
    // A 3-component format for a float3: the message says exactly 4 are needed.
    let packed = texture(wgpu::TextureFormat::Rg11b10Ufloat, sampled);
    bindings.channels.insert("normal".into(), &packed);
    let (text, e) = error(&bindings, &mut shader);
    assert!(matches!(e, Error::ChannelFormat { ref channel, .. } if channel == "normal"), "{e:?}");
    assert!(text.contains("exactly 4 components") && text.contains("bind Rgba32Float"), "{text}");
    // A depth format: not accepted as a channel, and what to do instead.
    let depth = texture(wgpu::TextureFormat::Depth32Float, sampled);
    bindings.channels.insert("normal".into(), &depth);
    let (text, e) = error(&bindings, &mut shader);
    assert!(matches!(e, Error::ChannelDepthFormat { ref channel, .. } if channel == "normal"), "{e:?}");
    assert!(text.contains("not accepted as a channel") && text.contains("@depth(inverse_view_projection)"), "{text}");
    // A texture array of two layers.
    let layered = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("layered"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 2 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: sampled,
        view_formats: &[],
    });
    bindings.channels.insert("normal".into(), &layered);
    let (text, e) = error(&bindings, &mut shader);
    assert!(matches!(e, Error::TextureShape { ref name, .. } if name == "normal"), "{e:?}");
    assert!(text.contains("2 layers"), "{text}");
    bindings.channels.insert("normal".into(), get("normal"));

    // An output the language could declare in this format: the hint says how.
    let half = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba16Float);
    bindings.outputs.insert("color".into(), &half);
    let (text, e) = error(&bindings, &mut shader);
    assert!(matches!(e, Error::OutputFormat { ref name, .. } if name == "color"), "{e:?}");
    assert!(text.contains("`@format(rgba16float) fine out float4 color`"), "{text}");
    // An output without STORAGE_BINDING.
    let unwritable = texture(wgpu::TextureFormat::Rgba32Float, sampled | wgpu::TextureUsages::COPY_SRC);
    bindings.outputs.insert("color".into(), &unwritable);
    assert_eq!(error(&bindings, &mut shader).1, Error::OutputUsage("color".into()));
    bindings.outputs.insert("color".into(), &output);
    dispatch(gpu, &mut shader, &bindings).unwrap();

    // A sampled texture created without TEXTURE_BINDING.
    let textured = compile(
        "in float2 uv;\nuniform texture2d albedo_map;\nuniform sampler linear;\n\
         fine out float4 color = sample(albedo_map, linear, uv);",
    );
    let mut shader = Shader::new(&gpu.device, &textured).unwrap();
    let storage_only = texture(wgpu::TextureFormat::Rgba8Unorm, wgpu::TextureUsages::STORAGE_BINDING);
    let view = storage_only.create_view(&Default::default());
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor::default());
    let mut bindings = Bindings { size, ..Default::default() };
    bindings.channels.insert("uv".into(), get("uv"));
    bindings.textures.insert("albedo_map".into(), &view);
    bindings.samplers.insert("linear".into(), &sampler);
    bindings.outputs.insert("color".into(), &output);
    assert_eq!(error(&bindings, &mut shader).1, Error::TextureUsage("albedo_map".into()));
}

pub fn unknown_modes_are_named() {
    assert_eq!("coarse8x8".parse::<Mode>(), Err(mrsl_abi::UnknownMode("coarse8x8".into())));
    let error = Error::from("coarse8x8".parse::<Mode>().unwrap_err());
    assert_eq!(error, Error::UnknownMode(mrsl_abi::UnknownMode("coarse8x8".into())));
    assert!(error.to_string().contains("expected reference, coarse2x2"), "{error}");
    assert_eq!("coarse4x4".parse::<Mode>(), Ok(Mode::Coarse4x4));
}

/// A G-buffer channel the program does not declare is simply unused, and
/// the run helper reports missing bindings rather than panicking.
pub fn extra_channels_are_ignored(gpu: &Gpu) {
    let program = compile("in float depth;\nfine out float4 color = float4(depth);");
    let mut gbuffer = Scene::Gradient.render(8, 8);
    gbuffer.channels.push(("unused".into(), ChannelData::Uint(vec![0; 64])));
    run(gpu, &program, &gbuffer, Mode::Coarse2x2, false).unwrap();
    let empty = GBuffer { width: 8, height: 8, channels: vec![] };
    assert_eq!(run(gpu, &program, &empty, Mode::Reference, false).err(), Some(Error::MissingChannel("depth".into())));
}

/// Kernels read back from the files `mrslc compile` writes, and kernels the
/// runtime compiles at load time (its `compile` feature), render exactly the
/// image of the compiler's own program; a broken source is a typed error
/// carrying the rendered diagnostics.
pub fn precompiled_and_load_time_kernels_render_alike(gpu: &Gpu) {
    let source = include_str!("../../examples/demo.mrsl");
    let program = compile(source);
    let gbuffer = Scene::Demo.render(64, 40);
    let dir = std::env::temp_dir().join(format!("mrsl-render-precompiled-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    program.compiled.write_dir(&dir, "demo").unwrap();
    let from_files = CompiledProgram::read_dir(&dir, None).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let at_load = mrsl_runtime::compile(source, "demo.mrsl").unwrap();
    for mode in [Mode::Reference, Mode::Dynamic, Mode::Hierarchical] {
        let expected = run(gpu, &program, &gbuffer, mode, false).unwrap().pixels;
        assert!(run(gpu, &from_files, &gbuffer, mode, false).unwrap().pixels == expected, "{mode}: from files");
        assert!(run(gpu, &at_load, &gbuffer, mode, false).unwrap().pixels == expected, "{mode}: compiled at load");
    }
    match mrsl_runtime::compile("fine out float4 color = float4(nope);", "bad.mrsl") {
        Err(Error::Compile(text)) => assert!(text.contains("E0100") && text.contains("bad.mrsl"), "{text}"),
        other => panic!("expected a compile error, got {:?}", other.map(|_| ())),
    }
}

/// A mode whose kernels were not compiled is a typed error, not a panic.
pub fn modes_without_kernels_are_unsupported(gpu: &Gpu) {
    let source = "in float depth;\ncoarse effect float d = depth * 2.0;\nfine out float4 color = float4(d);";
    let options = mrsl::Options::for_modes(&[Mode::Reference, Mode::Coarse4x4, Mode::Checkerboard, Mode::RateImage]);
    let program = mrsl::compile(source, &options).unwrap();
    let gbuffer = Scene::Gradient.render(8, 8);
    for mode in [Mode::Hierarchical, Mode::Dynamic, Mode::Coarse2x2] {
        assert!(
            matches!(run(gpu, &program, &gbuffer, mode, false), Err(Error::UnsupportedMode(ref m, _)) if m == mode.name()),
            "{mode}"
        );
    }
    run(gpu, &program, &gbuffer, Mode::Coarse4x4, false).unwrap();
}

/// A kernel the device cannot run refuses only the modes that need it: with
/// three outputs and a coarse effect, the hierarchical and checkerboard
/// kernels bind five storage textures (outputs, rate image, per-pixel
/// records), one more than WebGPU's default limit, while the block modes
/// bind four and render.
pub fn modes_beyond_the_device_limits_are_unsupported(gpu: &Gpu) {
    let source = "in float3 normal;\ncoarse effect float d = saturate(normal.y);\n\
                  fine out float4 a = float4(d);\nfine out float4 b = float4(d * 0.5);\n\
                  fine out float4 c = float4(normal, 1.0);\n";
    let program = mrsl::compile(source, &Default::default()).unwrap();
    let gbuffer = Scene::Gradient.render(8, 8);
    assert_eq!(gpu.device.limits().max_storage_textures_per_shader_stage, 4, "the test assumes the default limit");
    for mode in [Mode::Hierarchical, Mode::Checkerboard] {
        match run(gpu, &program, &gbuffer, mode, false) {
            Err(Error::UnsupportedMode(m, reason)) => {
                assert_eq!(m, mode.name());
                assert!(reason.contains("cannot run") && reason.contains("StorageTextures"), "{reason}");
            }
            Err(other) => panic!("{mode}: expected UnsupportedMode, got {other:?}"),
            Ok(_) => panic!("{mode}: expected UnsupportedMode, and it rendered"),
        }
    }
    for mode in [Mode::Reference, Mode::Coarse4x4, Mode::Dynamic, Mode::RateImage] {
        run(gpu, &program, &gbuffer, mode, false).unwrap_or_else(|e| panic!("{mode}: {e}"));
    }
}

/// `mrsl_runtime::compile_modes` generates exactly the kernels its modes
/// dispatch (the union of their `Mode::kernels`), for every set of modes;
/// `compile` those of all eight.
pub fn compiled_kernels_are_those_of_the_modes() {
    let source = "in float3 normal;\ncoarse effect float d = normal.y;\nfine out float4 color = float4(d);\n";
    let kernels = |program: &CompiledProgram| {
        let mut kernels: Vec<(mrsl::KernelKind, Option<u32>)> =
            program.kernels.iter().map(|k| (k.kind, k.block_size)).collect();
        kernels.sort();
        kernels
    };
    for subset in 1u32..1 << Mode::ALL.len() {
        let modes: Vec<Mode> =
            Mode::ALL.iter().enumerate().filter(|(k, _)| subset >> k & 1 == 1).map(|(_, m)| *m).collect();
        let mut wanted: Vec<(mrsl::KernelKind, Option<u32>)> =
            modes.iter().flat_map(|m| m.kernels().iter().map(|k| (k.kind, k.block))).collect();
        wanted.sort();
        wanted.dedup();
        let program = mrsl_runtime::compile_modes(source, "modes.mrsl", &modes).unwrap();
        assert_eq!(kernels(&program), wanted, "{modes:?}");
    }
    let all = mrsl_runtime::compile(source, "modes.mrsl").unwrap();
    assert_eq!(kernels(&all).len(), 17);
}
