//! The render tests on a second Vulkan driver: SwiftShader (Google's CPU
//! Vulkan, shipped with Debian's `chromium` package), besides whatever
//! adapter the run found first (lavapipe in CI). The trial starts this test
//! binary again with `VK_ICD_FILENAMES` naming SwiftShader's driver alone,
//! asking it (through `MRSL_RENDER_SUBSET`) for the subset below: forced
//! refinement equal to the reference in every mode, odd sizes, the
//! rate-image mode's blending, seams and forced refinement, and the rate
//! source against its CPU model. The child prints the adapter it ran on.

use std::path::PathBuf;

/// The tests run on the second driver.
pub const SUBSET: &[&str] = &[
    "modes::forced_refinement_equals_reference_for_every_example",
    "modes::odd_sizes_cover_every_pixel",
    "modes::silhouettes_are_never_blended",
    "rate_image::forced_refinement_equals_reference_at_every_rate",
    "rate_image::pixels_blend_the_samples_of_their_tiles_rate",
    "rate_image::tile_borders_have_no_seams",
    "rate_source::gpu_decisions_equal_the_cpu_reference",
];

/// The environment variable that asks this binary for [`SUBSET`] alone.
pub const SUBSET_VARIABLE: &str = "MRSL_RENDER_SUBSET";

/// SwiftShader's Vulkan driver manifest: `$MRSL_SWIFTSHADER_ICD`, else
/// where Debian's chromium package puts it.
pub fn swiftshader_icd() -> Result<PathBuf, String> {
    let path = std::env::var_os("MRSL_SWIFTSHADER_ICD")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/lib/chromium/vk_swiftshader_icd.json"));
    if path.exists() {
        Ok(path)
    } else {
        Err(format!(
            "SwiftShader's Vulkan driver was not found at {} (apt-get install chromium, or set MRSL_SWIFTSHADER_ICD)",
            path.display()
        ))
    }
}

/// Runs [`SUBSET`] in a child process on SwiftShader; panics with its output's verdict on failure.
pub fn subset_on_swiftshader(icd: &std::path::Path) {
    let exe = std::env::current_exe().expect("the test binary knows its path");
    let status = std::process::Command::new(exe)
        .env("VK_ICD_FILENAMES", icd)
        .env(SUBSET_VARIABLE, "second-driver")
        .arg("--test-threads=2")
        .status()
        .expect("the test binary starts again");
    assert!(status.success(), "the render tests failed on SwiftShader (their output is above)");
}
