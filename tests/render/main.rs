//! Render tests: compiled programs executed by the runtime on a GPU adapter
//! (lavapipe in CI), with pixel values checked against the reference kernel
//! of the same program.
//!
//! The harness is libtest-mimic rather than `#[test]`, so that a machine
//! without an adapter reports the GPU tests as skipped — listed as
//! `ignored` and counted in the summary, after a line saying why — instead
//! of passing them silently. With `CI=true` a missing adapter is a failure.

mod harness;

mod background;
mod binding;
mod engine_formats;
mod errors;
mod frames;
mod generated;
mod language;
mod lifted_derivatives;
mod modes;
mod packed_records;
mod rate_image;
mod rate_source;
mod second_driver;
mod sponza;
mod storage_channels;
mod suite_scenes;
mod textures;
mod views;

pub use harness::*;
use libtest_mimic::{Arguments, Trial};

/// A test that needs a device.
type GpuTest = (&'static str, fn(&mrsl_lab::gpu::Gpu));

/// Tests that need a device.
const GPU_TESTS: &[GpuTest] = &[
    (
        "background::background_pixels_are_never_shaded_or_refined",
        background::background_pixels_are_never_shaded_or_refined,
    ),
    ("background::background_tiles_read_their_own_channel", background::background_tiles_read_their_own_channel),
    (
        "background::surface_keys_refine_the_same_pixels_at_any_scale",
        background::surface_keys_refine_the_same_pixels_at_any_scale,
    ),
    ("binding::textured_materials_are_lit_over_a_mesh_scene", binding::textured_materials_are_lit_over_a_mesh_scene),
    ("binding::mismatches_without_defaults_are_typed_errors", binding::mismatches_without_defaults_are_typed_errors),
    (
        "engine_formats::depth_and_octahedral_normals_render_as_the_float_gbuffer",
        engine_formats::depth_and_octahedral_normals_render_as_the_float_gbuffer,
    ),
    (
        "engine_formats::bevy_deferred_gbuffer_renders_as_the_float_gbuffer",
        engine_formats::bevy_deferred_gbuffer_renders_as_the_float_gbuffer,
    ),
    (
        "engine_formats::the_engine_example_program_renders_over_engine_formats",
        engine_formats::the_engine_example_program_renders_over_engine_formats,
    ),
    (
        "engine_formats::decoded_channels_take_their_engine_formats",
        engine_formats::decoded_channels_take_their_engine_formats,
    ),
    ("errors::binding_mismatches_are_typed_errors", errors::binding_mismatches_are_typed_errors),
    (
        "generated::forced_refinement_equals_reference_for_generated_programs",
        generated::forced_refinement_equals_reference_for_generated_programs,
    ),
    (
        "packed_records::packed_records_render_what_word_records_render",
        packed_records::packed_records_render_what_word_records_render,
    ),
    (
        "packed_records::packed_records_without_the_feature_are_refused",
        packed_records::packed_records_without_the_feature_are_refused,
    ),
    (
        "storage_channels::storage_channels_render_what_sampled_channels_render",
        storage_channels::storage_channels_render_what_sampled_channels_render,
    ),
    (
        "storage_channels::storage_channels_check_their_format_and_usage",
        storage_channels::storage_channels_check_their_format_and_usage,
    ),
    ("errors::engine_textures_are_checked_before_recording", errors::engine_textures_are_checked_before_recording),
    (
        "frames::velocity_is_the_projection_difference_of_a_camera_move",
        frames::velocity_is_the_projection_difference_of_a_camera_move,
    ),
    ("frames::an_unmoved_camera_gives_zero_velocity", frames::an_unmoved_camera_gives_zero_velocity),
    (
        "frames::a_fast_pan_lowers_the_rates_through_the_velocity",
        frames::a_fast_pan_lowers_the_rates_through_the_velocity,
    ),
    ("errors::extra_channels_are_ignored", errors::extra_channels_are_ignored),
    ("errors::modes_without_kernels_are_unsupported", errors::modes_without_kernels_are_unsupported),
    ("errors::modes_beyond_the_device_limits_are_unsupported", errors::modes_beyond_the_device_limits_are_unsupported),
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
    (
        "lifted_derivatives::loop_built_derivatives_force_to_the_reference",
        lifted_derivatives::loop_built_derivatives_force_to_the_reference,
    ),
    (
        "lifted_derivatives::loop_built_predicates_refine_as_an_effect_of_their_own",
        lifted_derivatives::loop_built_predicates_refine_as_an_effect_of_their_own,
    ),
    ("modes::steps_keep_their_edges", modes::steps_keep_their_edges),
    ("modes::surface_derivatives_do_not_refine_at_keys", modes::surface_derivatives_do_not_refine_at_keys),
    (
        "modes::statistics_off_changes_nothing_but_the_instrumentation",
        modes::statistics_off_changes_nothing_but_the_instrumentation,
    ),
    ("modes::keys_refine_only_the_effects_that_read_them", modes::keys_refine_only_the_effects_that_read_them),
    ("modes::refine_masks_decode_to_the_counted_effects", modes::refine_masks_decode_to_the_counted_effects),
    ("modes::compacted_fine_pass_equals_the_plain_one", modes::compacted_fine_pass_equals_the_plain_one),
    ("modes::silhouettes_are_never_blended", modes::silhouettes_are_never_blended),
    ("modes::odd_sizes_cover_every_pixel", modes::odd_sizes_cover_every_pixel),
    (
        "modes::shaded_fraction_falls_from_reference_to_coarse4x4",
        modes::shaded_fraction_falls_from_reference_to_coarse4x4,
    ),
    ("modes::hand_made_gbuffer_reads_back", modes::hand_made_gbuffer_reads_back),
    ("modes::three_rates_shade_each_effect_at_its_own_rate", modes::three_rates_shade_each_effect_at_its_own_rate),
    (
        "modes::plain_programs_render_in_multi_rate_as_in_coarse2x2",
        modes::plain_programs_render_in_multi_rate_as_in_coarse2x2,
    ),
    ("modes::sinusoids_at_many_angles_and_frequencies", modes::sinusoids_at_many_angles_and_frequencies),
    (
        "modes::hierarchical_interpolates_a_gradient_from_level_zero",
        modes::hierarchical_interpolates_a_gradient_from_level_zero,
    ),
    (
        "modes::hierarchical_predicate_derivatives_from_level_neighbours",
        modes::hierarchical_predicate_derivatives_from_level_neighbours,
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
    ("textures::textured_quads_show_their_texels", textures::textured_quads_show_their_texels),
    ("textures::minified_textures_average_linear_light", textures::minified_textures_average_linear_light),
    ("textures::material_maps_reach_the_gbuffer", textures::material_maps_reach_the_gbuffer),
    ("textures::missing_material_channels_are_typed_errors", textures::missing_material_channels_are_typed_errors),
    (
        "textures::pbr_example_renders_textured_content_in_every_mode",
        textures::pbr_example_renders_textured_content_in_every_mode,
    ),
    (
        "rate_image::pixels_blend_the_samples_of_their_tiles_rate",
        rate_image::pixels_blend_the_samples_of_their_tiles_rate,
    ),
    ("rate_image::tile_borders_have_no_seams", rate_image::tile_borders_have_no_seams),
    (
        "rate_image::forced_refinement_equals_reference_at_every_rate",
        rate_image::forced_refinement_equals_reference_at_every_rate,
    ),
    ("rate_image::coarser_rates_shade_less", rate_image::coarser_rates_shade_less),
    ("rate_image::bad_shading_rate_images_are_typed_errors", rate_image::bad_shading_rate_images_are_typed_errors),
    (
        "suite_scenes::generated_scene_workload_matches_its_reference",
        suite_scenes::generated_scene_workload_matches_its_reference,
    ),
    (
        "views::views_in_one_submission_are_each_their_own_render",
        views::views_in_one_submission_are_each_their_own_render,
    ),
    ("language::new_forms_force_to_the_reference", language::new_forms_force_to_the_reference),
    ("language::dynamic_limits_render_as_breaks", language::dynamic_limits_render_as_breaks),
];

/// Tests that run on the CPU only.
const CPU_TESTS: &[(&str, fn())] = &[
    (
        "binding::scene_file_images_parse_and_name_their_mistakes",
        binding::scene_file_images_parse_and_name_their_mistakes,
    ),
    ("errors::unknown_modes_are_named", errors::unknown_modes_are_named),
    ("errors::compiled_kernels_are_those_of_the_modes", errors::compiled_kernels_are_those_of_the_modes),
    ("sponza::sponza_loads_with_its_35_materials", sponza::sponza_loads_with_its_35_materials),
    ("sponza::obj_written_to_a_temp_dir_loads", sponza::obj_written_to_a_temp_dir_loads),
    ("sponza::gltf_and_glb_written_to_a_temp_dir_load", sponza::gltf_and_glb_written_to_a_temp_dir_load),
    ("sponza::bad_mesh_files_are_typed_errors", sponza::bad_mesh_files_are_typed_errors),
    ("textures::loaders_report_what_they_skip", textures::loaders_report_what_they_skip),
    ("suite_scenes::scaled_rigs_keep_sponzas_light_level", suite_scenes::scaled_rigs_keep_sponzas_light_level),
    ("suite_scenes::ac3d_written_to_a_temp_dir_loads", suite_scenes::ac3d_written_to_a_temp_dir_loads),
    ("suite_scenes::bad_ac3d_files_are_typed_errors", suite_scenes::bad_ac3d_files_are_typed_errors),
];

/// GPU tests over the textured dungeon, which is fetched separately
/// (scripts/fetch-dungeon.sh): listed as ignored, after a line saying why,
/// where it is not there.
const DUNGEON_TESTS: &[GpuTest] = &[("textures::pbr_example_over_the_dungeon", textures::pbr_example_over_the_dungeon)];

fn main() {
    // Before the test threads and the Vulkan loader start: without it, Mesa
    // prints "error: XDG_RUNTIME_DIR is invalid or not set" on machines
    // without a session (see mrsl_lab::runtime_dir).
    // SAFETY: no other thread exists yet.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    let args = Arguments::from_args();
    if std::env::var_os(second_driver::SUBSET_VARIABLE).is_some() {
        return second_driver_subset(&args);
    }
    let gpu = harness::gpu(
        GPU_TESTS.len() + rate_source::GPU_TESTS.len() + DUNGEON_TESTS.len() + suite_scenes::FIXTURE_TESTS.len(),
    );
    let dungeon = mrsl_lab::fixtures::dungeon_path();
    if let (Some(_), Err(e)) = (gpu, &dungeon) {
        println!("SKIPPING {} render test(s) over the dungeon (reported as ignored below): {e}", DUNGEON_TESTS.len());
    }
    let mut trials: Vec<Trial> = GPU_TESTS
        .iter()
        .chain(rate_source::GPU_TESTS)
        .map(|&(name, test)| match gpu {
            Some(gpu) => Trial::test(name, move || {
                test(gpu);
                Ok(())
            }),
            None => Trial::test(name, || Ok(())).with_ignored_flag(true),
        })
        .collect();
    trials.extend(DUNGEON_TESTS.iter().map(|&(name, test)| match (gpu, &dungeon) {
        (Some(gpu), Ok(_)) => Trial::test(name, move || {
            test(gpu);
            Ok(())
        }),
        _ => Trial::test(name, || Ok(())).with_ignored_flag(true),
    }));
    // The outdoor and small scenes' tests, fetched separately as the dungeon is.
    trials.extend(suite_scenes::fixture_trials(gpu));
    trials.extend(CPU_TESTS.iter().map(|&(name, test)| {
        Trial::test(name, move || {
            test();
            Ok(())
        })
    }));
    trials.push(second_driver_trial(gpu.is_some()));
    libtest_mimic::run(&args, trials).exit();
}

/// The subset of the GPU tests that runs again on SwiftShader, in a child
/// process ([`second_driver`]); skipped visibly where SwiftShader is not
/// installed, a failure under `CI=true`.
fn second_driver_trial(has_gpu: bool) -> Trial {
    const NAME: &str = "second_driver::subset_on_swiftshader";
    match second_driver::swiftshader_icd() {
        Ok(icd) if has_gpu => Trial::test(NAME, move || {
            second_driver::subset_on_swiftshader(&icd);
            Ok(())
        }),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            Trial::test(NAME, move || Err(format!("CI=true but {e}").into()))
        }
        Err(e) => {
            println!("SKIPPING {NAME} (reported as ignored below): {e}");
            Trial::test(NAME, || Ok(())).with_ignored_flag(true)
        }
        Ok(_) => Trial::test(NAME, || Ok(())).with_ignored_flag(true),
    }
}

/// In the child of [`second_driver_trial`]: the subset alone, on the adapter
/// `VK_ICD_FILENAMES` leaves (a missing one is a failure: it was asked for).
fn second_driver_subset(args: &Arguments) {
    let gpu = harness::gpu_or_fail();
    let all = GPU_TESTS.iter().chain(rate_source::GPU_TESTS);
    let trials: Vec<Trial> = all
        .filter(|(name, _)| second_driver::SUBSET.contains(name))
        .map(|&(name, test)| {
            Trial::test(format!("{name} (second driver)"), move || {
                test(gpu);
                Ok(())
            })
        })
        .collect();
    assert_eq!(trials.len(), second_driver::SUBSET.len(), "every test of the subset exists");
    libtest_mimic::run(args, trials).exit();
}
