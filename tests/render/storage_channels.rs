//! G-buffer channels read through read-only storage bindings
//! (`mrsl::Options::storage_channels`): the same images and statistics as
//! sampled channels in every mode, forced refinement still equal to the
//! reference, and the bindings they need checked with typed errors.

use crate::{adaptive_modes, run};
use mrsl_abi::ChannelAccess;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use mrsl_runtime::{Bindings, DispatchOptions, Error, Mode, Shader};

/// The demo: a surface key, a normal key, a background rule and the albedo,
/// every kind of channel load the kernels make.
const DEMO: &str = include_str!("../../examples/demo.mrsl");

fn compile(storage_channels: bool) -> mrsl::Program {
    mrsl::compile(DEMO, &mrsl::Options { storage_channels, ..Default::default() }).unwrap()
}

/// A device that grants the storage textures the storage-channel kernels
/// bind (the shared device has WebGPU's default limit, 4).
fn storage_device(program: &mrsl::Program) -> Gpu {
    let wanted = program.layout.storage_textures_per_stage();
    let gpu = Gpu::with_storage_textures(wanted).unwrap();
    let granted = gpu.device.limits().max_storage_textures_per_shader_stage;
    assert!(granted >= wanted, "the adapter grants {granted} storage textures per stage, the test needs {wanted}");
    gpu
}

/// Every mode renders the same pixels and statistics (timings aside) with
/// storage channels as with sampled ones: the kernels read the same texels,
/// only through another binding; and forced refinement equals the reference
/// bit for bit. An odd size, so that partial blocks and tiles are read too.
pub fn storage_channels_render_what_sampled_channels_render(_shared: &Gpu) {
    let (sampled, storage) = (compile(false), compile(true));
    assert!(storage.layout.channels.iter().all(|c| c.access == ChannelAccess::Storage));
    assert!(sampled.layout.channels.iter().all(|c| c.access == ChannelAccess::Sampled));
    let gpu = storage_device(&storage);
    let gbuffer = Scene::Demo.render(45, 29);
    for mode in Mode::ALL {
        let a = run(&gpu, &sampled, &gbuffer, mode, false).unwrap_or_else(|e| panic!("{mode}, sampled: {e}"));
        let b = run(&gpu, &storage, &gbuffer, mode, false).unwrap_or_else(|e| panic!("{mode}, storage: {e}"));
        assert!(a.pixels == b.pixels, "{mode}: storage channels change the image");
        assert_eq!(a.stats.effects, b.stats.effects, "{mode}: storage channels change the statistics");
        assert_eq!(a.stats.coarse_samples, b.stats.coarse_samples, "{mode}");
        assert_eq!(a.stats.work_lists, b.stats.work_lists, "{mode}");
        assert_eq!(a.stats.background_pixels, b.stats.background_pixels, "{mode}");
    }
    let reference = run(&gpu, &storage, &gbuffer, Mode::Reference, false).unwrap();
    for mode in adaptive_modes() {
        let forced = run(&gpu, &storage, &gbuffer, mode, true).unwrap_or_else(|e| panic!("{mode}, forced: {e}"));
        assert!(forced.pixels == reference.pixels, "{mode}: forced refinement differs from the reference");
    }
}

/// A storage channel takes exactly the layout's format and needs
/// `STORAGE_BINDING`: a texture a sampled channel would accept is refused
/// with the error naming what is wrong, before anything is recorded.
pub fn storage_channels_check_their_format_and_usage(_shared: &Gpu) {
    let program = compile(true);
    let gpu = storage_device(&program);
    let size = (16, 8);
    let channels = Scene::Demo.render(size.0, size.1).upload(&gpu);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    let output = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let mut bindings = Bindings { size, ..Default::default() };
    bindings.outputs.insert("color".into(), &output);
    for (name, texture) in &channels {
        bindings.channels.insert(name.clone(), texture);
    }
    let mut dispatch = |bindings: &Bindings| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, DispatchOptions::new(Mode::Coarse4x4))
    };
    assert_eq!(dispatch(&bindings), Ok(()));
    // Rgba16Float holds a float3 for a sampled binding, not for a storage binding of Rgba32Float.
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING;
    let half = gpu.texture_2d("normal", size, wgpu::TextureFormat::Rgba16Float, usage);
    bindings.channels.insert("normal".into(), &half);
    assert_eq!(
        dispatch(&bindings),
        Err(Error::ChannelStorageFormat {
            channel: "normal".into(),
            expected: wgpu::TextureFormat::Rgba32Float,
            found: wgpu::TextureFormat::Rgba16Float,
        })
    );
    // The layout's format, without STORAGE_BINDING.
    let sampled_only =
        gpu.texture_2d("normal", size, wgpu::TextureFormat::Rgba32Float, wgpu::TextureUsages::TEXTURE_BINDING);
    bindings.channels.insert("normal".into(), &sampled_only);
    assert_eq!(dispatch(&bindings), Err(Error::ChannelUsage { channel: "normal".into(), missing: "STORAGE_BINDING" }));
}
