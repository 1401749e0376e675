//! Render tests: compiled programs executed by the runtime on a GPU adapter
//! (lavapipe in CI), with pixel values checked against the reference kernel
//! of the same program.
//!
//! The harness is libtest-mimic rather than `#[test]`, so that a machine
//! without an adapter reports the GPU tests as skipped — listed as
//! `ignored` and counted in the summary, after a line saying why — instead
//! of passing them silently. With `CI=true` a missing adapter is a failure.

mod harness;

mod errors;
mod modes;
mod sponza;

pub use harness::*;
use libtest_mimic::{Arguments, Trial};

/// A test that needs a device.
type GpuTest = (&'static str, fn(&mrsl_lab::gpu::Gpu));

/// Tests that need a device.
const GPU_TESTS: &[GpuTest] = &[
    ("errors::binding_mismatches_are_typed_errors", errors::binding_mismatches_are_typed_errors),
    ("errors::extra_channels_are_ignored", errors::extra_channels_are_ignored),
    ("errors::modes_without_kernels_are_unsupported", errors::modes_without_kernels_are_unsupported),
    ("errors::precompiled_and_load_time_kernels_render_alike", errors::precompiled_and_load_time_kernels_render_alike),
    (
        "modes::forced_refinement_equals_reference_for_every_example",
        modes::forced_refinement_equals_reference_for_every_example,
    ),
    (
        "modes::gradient_is_reconstructed_at_one_sixteenth_of_the_cost",
        modes::gradient_is_reconstructed_at_one_sixteenth_of_the_cost,
    ),
    ("modes::derivative_chains_render_in_every_mode", modes::derivative_chains_render_in_every_mode),
    ("modes::steps_keep_their_edges", modes::steps_keep_their_edges),
    ("modes::silhouettes_are_never_blended", modes::silhouettes_are_never_blended),
    ("modes::odd_sizes_cover_every_pixel", modes::odd_sizes_cover_every_pixel),
    (
        "modes::shaded_fraction_falls_from_reference_to_coarse4x4",
        modes::shaded_fraction_falls_from_reference_to_coarse4x4,
    ),
    ("modes::hand_made_gbuffer_reads_back", modes::hand_made_gbuffer_reads_back),
    ("modes::sinusoids_at_many_angles_and_frequencies", modes::sinusoids_at_many_angles_and_frequencies),
    (
        "modes::hierarchical_interpolates_a_gradient_from_level_zero",
        modes::hierarchical_interpolates_a_gradient_from_level_zero,
    ),
    ("modes::hierarchical_work_lists_keep_lanes_full", modes::hierarchical_work_lists_keep_lanes_full),
    (
        "modes::checkerboard_reconstructs_a_gradient_at_half_rate",
        modes::checkerboard_reconstructs_a_gradient_at_half_rate,
    ),
    (
        "sponza::sponza_coarse_modes_stay_close_to_the_reference",
        sponza::sponza_coarse_modes_stay_close_to_the_reference,
    ),
    ("sponza::rasterised_quads_match_the_analytic_gbuffer", sponza::rasterised_quads_match_the_analytic_gbuffer),
    ("sponza::sponza_lights_workload_matches_its_reference", sponza::sponza_lights_workload_matches_its_reference),
    ("sponza::scene_files_parse_and_name_their_mistakes", sponza::scene_files_parse_and_name_their_mistakes),
];

/// Tests that run on the CPU only.
const CPU_TESTS: &[(&str, fn())] = &[
    ("errors::unknown_modes_are_named", errors::unknown_modes_are_named),
    ("errors::compiled_kernels_are_those_of_the_modes", errors::compiled_kernels_are_those_of_the_modes),
    ("sponza::sponza_loads_with_its_35_materials", sponza::sponza_loads_with_its_35_materials),
    ("sponza::obj_written_to_a_temp_dir_loads", sponza::obj_written_to_a_temp_dir_loads),
    ("sponza::gltf_and_glb_written_to_a_temp_dir_load", sponza::gltf_and_glb_written_to_a_temp_dir_load),
    ("sponza::bad_mesh_files_are_typed_errors", sponza::bad_mesh_files_are_typed_errors),
];

fn main() {
    let args = Arguments::from_args();
    let gpu = harness::gpu(GPU_TESTS.len());
    let mut trials: Vec<Trial> = GPU_TESTS
        .iter()
        .map(|&(name, test)| match gpu {
            Some(gpu) => Trial::test(name, move || {
                test(gpu);
                Ok(())
            }),
            None => Trial::test(name, || Ok(())).with_ignored_flag(true),
        })
        .collect();
    trials.extend(CPU_TESTS.iter().map(|&(name, test)| {
        Trial::test(name, move || {
            test();
            Ok(())
        })
    }));
    libtest_mimic::run(&args, trials).exit();
}
