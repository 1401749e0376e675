//! The hierarchical kernel's records packed four words to a texel
//! (`mrsl::Options::packed_records`): the same images, statistics and work
//! lists as a texel per word, forced refinement still equal to the
//! reference, and a device without read-write `Rgba32Uint` storage refused
//! with a typed error that names the feature.

use crate::modes::examples;
use crate::run;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use mrsl_runtime::{Error, Mode, Shader};

fn compile(source: &str, packed_records: bool) -> mrsl::Program {
    let options = mrsl::Options { packed_records, ..mrsl::Options::for_modes(&[Mode::Reference, Mode::Hierarchical]) };
    mrsl::compile(source, &options).unwrap()
}

/// A device that runs packed records (lavapipe does; the shared device is
/// made without the feature they need).
fn packing_device() -> Gpu {
    let gpu = Gpu::with_packed_records(wgpu::Limits::default().max_storage_textures_per_shader_stage).unwrap();
    assert!(gpu.packs_records, "{} allows no read-write storage access to Rgba32Uint", gpu.adapter_info.name);
    gpu
}

/// Every example renders the same pixels, statistics and work lists with
/// packed records as with a texel per word (the kernels store and load the
/// same words, only grouped into texels), and forced refinement equals the
/// reference bit for bit. Two odd sizes, so that lattices end mid-tile.
pub fn packed_records_render_what_word_records_render(_shared: &Gpu) {
    let gpu = packing_device();
    for (w, h) in [(75, 43), (37, 61)] {
        let gbuffer = Scene::Demo.render(w, h);
        for (name, source) in examples() {
            let (words, packed) = (compile(&source, false), compile(&source, true));
            assert!(packed.layout.hierarchical.packed && !words.layout.hierarchical.packed);
            let a = run(&gpu, &words, &gbuffer, Mode::Hierarchical, false).unwrap();
            let b = run(&gpu, &packed, &gbuffer, Mode::Hierarchical, false).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(a.pixels == b.pixels, "{name} at {w}x{h}: packed records change the image");
            assert_eq!(a.stats.effects, b.stats.effects, "{name} at {w}x{h}: packed records change the statistics");
            assert_eq!(a.stats.work_lists, b.stats.work_lists, "{name} at {w}x{h}");
            assert_eq!(a.stats.background_pixels, b.stats.background_pixels, "{name} at {w}x{h}");
            let reference = run(&gpu, &packed, &gbuffer, Mode::Reference, false).unwrap();
            let forced = run(&gpu, &packed, &gbuffer, Mode::Hierarchical, true).unwrap();
            assert!(
                forced.pixels == reference.pixels,
                "{name} at {w}x{h}: forced refinement differs from the reference"
            );
        }
    }
}

/// On a device made without `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES` the
/// hierarchical mode of a packed program is unsupported, with a reason that
/// names the option and the feature, before anything is bound; the
/// program's other modes still run.
pub fn packed_records_without_the_feature_are_refused(shared: &Gpu) {
    assert!(!shared.device.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES));
    let program = compile(include_str!("../../examples/demo.mrsl"), true);
    let shader = Shader::new(&shared.device, &program).unwrap();
    assert_eq!(shader.supports(Mode::Reference), Ok(()));
    match shader.supports(Mode::Hierarchical) {
        Err(Error::UnsupportedMode(mode, reason)) => {
            assert_eq!(mode, "hierarchical");
            assert!(reason.contains("packed_records"), "{reason}");
            assert!(reason.contains("TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES"), "{reason}");
        }
        other => panic!("a packed program's hierarchical mode ran on a device without the feature: {other:?}"),
    }
}
