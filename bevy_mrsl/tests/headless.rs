//! The headless example's Bevy app (Bevy 0.19, its deferred renderer, on
//! whatever Vulkan adapter there is: lavapipe in CI) with bevy_mrsl running
//! `lighting.mrsl` in several modes, switched at run time in one app:
//!
//! * forced refinement equals the per-pixel reference bit for bit, in
//!   every adaptive mode (the runtime's promise, through Bevy's textures);
//! * each adaptive image is within MSSIM 0.99 of the reference (measured
//!   0.998 for coarse 4x4 at this size: the bound leaves room for driver
//!   differences, not for a broken interpolation, which costs far more);
//! * the statistics bevy_mrsl reports say the adaptive mode shaded less;
//! * the camera's image is the output where the program owns the pixel
//!   (alpha 1) and Bevy's clear colour where it does not, within one 8-bit
//!   step (the sRGB encoding of the target against ours).

// The example's benchmark, also in this module, is not used here.
#[allow(dead_code)]
#[path = "../examples/common/mod.rs"]
mod common;

use bevy::color::ColorToPacked;
use bevy_mrsl::Mode;
use common::{Capture, Captured};

const SIZE: (u32, u32) = (256, 144);

/// Whether a Vulkan adapter exists; under `CI=true` a missing one fails the test.
fn adapter() -> bool {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let found = !pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN)).is_empty();
    if !found {
        assert!(std::env::var("CI").map_or(true, |v| v != "true"), "CI=true but no Vulkan adapter");
        println!(
            "SKIPPING the Bevy test: no Vulkan adapter. Install Mesa's lavapipe: apt-get install mesa-vulkan-drivers libvulkan1"
        );
    }
    found
}

fn capture(mode: Mode, force_refine: bool, composite: bool) -> Capture {
    let name = format!("{}{}", mode.name(), if force_refine { " forced" } else { "" });
    Capture { name, mode, force_refine, composite }
}

#[test]
fn bevy_renders_adaptive_modes_against_the_reference() {
    // SAFETY: before any thread of this test binary starts Vulkan.
    unsafe { mrsl_lab::runtime_dir::ensure_xdg_runtime_dir() };
    if !adapter() {
        return;
    }
    let adaptive = [Mode::Coarse4x4, Mode::Coarse2x2, Mode::Dynamic, Mode::Hierarchical, Mode::Checkerboard];
    let mut captures = vec![capture(Mode::Reference, false, false)];
    for (i, mode) in adaptive.into_iter().enumerate() {
        captures.push(capture(mode, false, i == 0));
        captures.push(capture(mode, true, false));
    }
    let images = common::render(SIZE, &common::Scene::Spheres, captures).expect("the Bevy app renders");
    let reference = &images[0];
    let (width, height) = SIZE;
    for image in &images[1..] {
        let name = &image.capture.name;
        if image.capture.force_refine {
            let differ = image.pixels.iter().zip(&reference.pixels).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{name}: {differ} pixels differ from the reference");
            continue;
        }
        let quality = mrsl_lab::metrics::compare(&image.pixels, &reference.pixels, width, height).unwrap();
        println!("{name}: PSNR {:.2} dB, MSSIM {:.4}", quality.psnr, quality.mssim);
        assert!(quality.mssim >= 0.99, "{name}: MSSIM {} against the reference", quality.mssim);
        let stats = image.stats.as_ref().unwrap_or_else(|| panic!("{name}: no statistics reported"));
        assert!(stats.shaded_fraction < 0.95, "{name}: shaded {} of the reference's work", stats.shaded_fraction);
        if let Some(composite) = &image.composite {
            check_composite(image, composite);
        }
    }
    let reference_stats = reference.stats.as_ref().expect("the reference's statistics");
    assert_eq!(reference_stats.shaded_fraction, 1.0);
}

/// The camera's image: the output where its alpha is 1, the clear colour
/// where it is 0.
fn check_composite(image: &Captured, composite: &[[u8; 4]]) {
    let sky = common::SKY.to_srgba().to_u8_array();
    let mut owned = 0;
    for (i, (output, shown)) in image.pixels.iter().zip(composite).enumerate() {
        let expected = match output[3] {
            1.0 => {
                owned += 1;
                [0, 1, 2].map(|c| mrsl_lab::color::linear_to_srgb8(output[c]))
            }
            0.0 => [sky[0], sky[1], sky[2]],
            alpha => panic!("pixel {i}: alpha {alpha}, the program writes 0 or 1"),
        };
        for c in 0..3 {
            assert!(
                expected[c].abs_diff(shown[c]) <= 1,
                "pixel {i}: the camera shows {shown:?}, expected {expected:?} (output {output:?})"
            );
        }
    }
    assert!(owned > composite.len() / 4, "the program owns {owned} of {} pixels", composite.len());
}
