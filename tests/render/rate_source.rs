//! The rate source of the `rate-image` mode on synthetic previous frames:
//! VALAR's decisions (flat, stripes along each axis, checker, motion,
//! Weber–Fechner), the first frame and resizes, temporal damping,
//! reprojection, external rate images with their combiners, foveation, typed
//! errors, the threshold controller driving t, and an exact comparison with a
//! CPU implementation of the same equations on random images.
//!
//! Axis convention: a rate is width x height, width along x. Vertical stripes
//! vary along x, so they need full rate along x and none along y: 1x4, which
//! is not a rate, so 1x2.

use mrsl_abi::shading_rate::{ShadingRate, rate_image_size};
use mrsl_lab::gpu::Gpu;
use mrsl_runtime::Error;
use mrsl_runtime::controller::Target;
use mrsl_runtime::rate_source::{
    Combiner, ExternalRates, Foveation, Preset, RateInputs, RateOptions, RateSource, create_rate_image, rate_fraction,
    read_rate_image, sensitivity_controller, upload_rate_image,
};

/// Tests that need a device (registered by main.rs).
pub const GPU_TESTS: &[crate::GpuTest] = &[
    ("rate_source::flat_luminance_is_4x4_everywhere", flat_luminance_is_4x4_everywhere),
    ("rate_source::stripes_are_full_rate_across_and_coarse_along", stripes_are_full_rate_across_and_coarse_along),
    ("rate_source::high_contrast_checker_is_1x1", high_contrast_checker_is_1x1),
    ("rate_source::motion_lowers_the_rate_by_the_velocity_terms", motion_lowers_the_rate_by_the_velocity_terms),
    ("rate_source::weber_fechner_is_more_conservative_in_the_dark", weber_fechner_is_more_conservative_in_the_dark),
    ("rate_source::half_float_inputs_are_read_alike", half_float_inputs_are_read_alike),
    (
        "rate_source::one_and_two_channel_inputs_are_read_as_their_luminance",
        one_and_two_channel_inputs_are_read_as_their_luminance,
    ),
    ("rate_source::first_frame_and_resizes_are_full_rate", first_frame_and_resizes_are_full_rate),
    (
        "rate_source::hysteresis_stops_an_alternating_input_from_flickering",
        hysteresis_stops_an_alternating_input_from_flickering,
    ),
    ("rate_source::reprojection_follows_the_motion", reprojection_follows_the_motion),
    (
        "rate_source::external_rates_are_honoured_and_combined_per_axis",
        external_rates_are_honoured_and_combined_per_axis,
    ),
    ("rate_source::foveation_is_full_rate_at_the_gaze", foveation_is_full_rate_at_the_gaze),
    ("rate_source::bad_inputs_are_typed_errors", bad_inputs_are_typed_errors),
    ("rate_source::gpu_decisions_equal_the_cpu_reference", gpu_decisions_equal_the_cpu_reference),
    ("rate_source::controller_steers_the_sensitivity_to_a_fraction", controller_steers_the_sensitivity_to_a_fraction),
];

/// A previous frame: linear RGB per pixel, row by row.
#[derive(Clone)]
struct Frame {
    size: (u32, u32),
    rgb: Vec<[f32; 3]>,
}

impl Frame {
    fn new(size: (u32, u32), f: impl Fn(u32, u32) -> [f32; 3]) -> Frame {
        Frame { size, rgb: (0..size.1).flat_map(|y| (0..size.0).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect() }
    }

    fn grey(size: (u32, u32), f: impl Fn(u32, u32) -> f32) -> Frame {
        Frame::new(size, |x, y| [f(x, y); 3])
    }

    fn upload(&self, gpu: &Gpu) -> wgpu::Texture {
        let data: Vec<f32> = self.rgb.iter().flat_map(|c| [c[0], c[1], c[2], 1.0]).collect();
        gpu.texture_with_data(
            "previous frame",
            self.size,
            wgpu::TextureFormat::Rgba32Float,
            bytemuck::cast_slice(&data),
        )
    }
}

fn velocity_texture(gpu: &Gpu, size: (u32, u32), v: &[[f32; 2]]) -> wgpu::Texture {
    gpu.texture_with_data("velocity", size, wgpu::TextureFormat::Rg32Float, bytemuck::cast_slice(v))
}

/// Options with the damping off, so that each frame shows its own decision.
fn undamped(preset: Preset) -> RateOptions {
    RateOptions { hysteresis: false, ..RateOptions::preset(preset) }
}

/// Runs one frame of `source` and reads the rates back.
fn frame(
    gpu: &Gpu,
    source: &mut RateSource,
    inputs: &RateInputs,
    options: &RateOptions,
) -> Result<Vec<ShadingRate>, Error> {
    let size = (inputs.color.width(), inputs.color.height());
    let target = create_rate_image(&gpu.device, size, options.tile)?;
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    source.encode(&gpu.device, &mut encoder, inputs, options, &target)?;
    gpu.queue.submit([encoder.finish()]);
    read_rate_image(&gpu.device, &gpu.queue, &target)
}

/// The rates of the second frame over the same input (the first is 1x1).
fn settled(gpu: &Gpu, frame_: &Frame, velocity: Option<&[[f32; 2]]>, options: &RateOptions) -> Vec<ShadingRate> {
    let mut source = RateSource::new(&gpu.device).unwrap();
    let color = frame_.upload(gpu);
    let velocity = velocity.map(|v| velocity_texture(gpu, frame_.size, v));
    let inputs = RateInputs { velocity: velocity.as_ref(), ..RateInputs::new(&color) };
    let first = frame(gpu, &mut source, &inputs, options).unwrap();
    // Before the combiners, that is: foveation may coarsen it.
    if options.foveation.is_none() && inputs.external.is_none() {
        assert!(first.iter().all(|&r| r == ShadingRate::R1x1), "the first frame is full rate: {first:?}");
    }
    frame(gpu, &mut source, &inputs, options).unwrap()
}

fn assert_all(rates: &[ShadingRate], want: ShadingRate, what: &str) {
    let wrong: Vec<(usize, ShadingRate)> = rates.iter().copied().enumerate().filter(|&(_, r)| r != want).collect();
    assert!(wrong.is_empty(), "{what}: expected {want} everywhere, but (tile index, rate) {wrong:?}");
}

pub fn flat_luminance_is_4x4_everywhere(gpu: &Gpu) {
    // Odd sizes: the right and bottom tiles are cut by the border.
    for (size, tile) in [((64, 48), 8), ((61, 45), 8), ((61, 45), 16)] {
        for preset in Preset::ALL {
            let options = RateOptions { tile, ..RateOptions::preset(preset) };
            let rates = settled(gpu, &Frame::grey(size, |_, _| 0.5), None, &options);
            assert_eq!(rates.len() as u32, rate_image_size(size, tile).0 * rate_image_size(size, tile).1);
            assert_all(&rates, ShadingRate::R4x4, &format!("flat {size:?}, tile {tile}, {}", preset.name()));
        }
    }
}

pub fn stripes_are_full_rate_across_and_coarse_along(gpu: &Gpu) {
    let size = (64, 40);
    let options = RateOptions::preset(Preset::Balanced);
    // Vertical stripes (columns alternate): luminance varies along x.
    let vertical = settled(gpu, &Frame::grey(size, |x, _| if x % 2 == 0 { 0.1 } else { 0.9 }), None, &options);
    assert_all(&vertical, ShadingRate::R1x2, "vertical stripes: full rate along x, 4x along y clamped to 2x");
    let horizontal = settled(gpu, &Frame::grey(size, |_, y| if y % 2 == 0 { 0.1 } else { 0.9 }), None, &options);
    assert_all(&horizontal, ShadingRate::R2x1, "horizontal stripes: full rate along y");
    // Low-contrast stripes two pixels wide: 2x along x, 4x along y.
    let soft = settled(gpu, &Frame::grey(size, |x, _| if x / 2 % 2 == 0 { 0.5 } else { 0.6 }), None, &options);
    assert_all(&soft, ShadingRate::R2x4, "soft vertical stripes");
    assert_eq!(soft, cpu_rates(&Frame::grey(size, |x, _| if x / 2 % 2 == 0 { 0.5 } else { 0.6 }), None, &options));
}

pub fn high_contrast_checker_is_1x1(gpu: &Gpu) {
    for preset in Preset::ALL {
        let checker = Frame::grey((48, 48), |x, y| if (x + y) % 2 == 0 { 0.02 } else { 0.95 });
        let rates = settled(gpu, &checker, None, &RateOptions::preset(preset));
        assert_all(&rates, ShadingRate::R1x1, &format!("checker, {}", preset.name()));
    }
}

pub fn motion_lowers_the_rate_by_the_velocity_terms(gpu: &Gpu) {
    let size = (64, 32);
    // Stripes whose half-rate error (sqrt(0.1) = 0.32) just exceeds the
    // Balanced JND threshold (0.5 * (0.5 + 0.05) = 0.275): 1x2 at rest.
    let stripes = Frame::grey(size, |x, _| if x % 2 == 0 { 0.4 } else { 0.6 });
    let still = RateOptions::preset(Preset::Balanced);
    assert_all(&settled(gpu, &stripes, None, &still), ShadingRate::R1x2, "stripes at rest");
    let moving = RateOptions { motion: true, ..still };
    let mut previous = ShadingRate::R1x2;
    for speed in [0.0f32, 1.0, 2.0, 4.0] {
        // Uniform motion along x: Eq. 20 and 21 scale the errors down.
        let v = vec![[speed, 0.0]; (size.0 * size.1) as usize];
        let rates = settled(gpu, &stripes, Some(&v), &moving);
        assert_eq!(rates, cpu_rates(&stripes, Some(&v), &moving), "speed {speed}");
        let r = rates[0];
        assert_all(&rates, r, &format!("uniform motion at {speed} px"));
        assert!(r.pixels() >= previous.pixels(), "speed {speed}: {r} is finer than {previous} at a lower speed");
        previous = r;
    }
    // At 4 px per frame the quarter-rate error 2.13 * 0.37 * 0.32 = 0.25 < 0.275: 4x along x.
    assert_eq!(previous, ShadingRate::R4x4);
    // The tile's minimum speed counts: one still pixel keeps the tile at rest.
    let mut v = vec![[4.0, 0.0]; (size.0 * size.1) as usize];
    v[(9 * size.0 + 9) as usize] = [0.0, 0.0];
    let rates = settled(gpu, &stripes, Some(&v), &moving);
    assert_eq!(rates[rate_image_size(size, 8).0 as usize + 1], ShadingRate::R1x2, "the tile with a still pixel");
    assert_eq!(rates[0], ShadingRate::R4x4);
}

pub fn weber_fechner_is_more_conservative_in_the_dark(gpu: &Gpu) {
    let size = (64, 32);
    // Dark stripes (0.020 / 0.022): the approximate difference halves |ΔL|,
    // Weber's law divides it by about 1 (the brightness sensitivity).
    let dark = Frame::grey(size, |x, _| if x % 2 == 0 { 0.020 } else { 0.022 });
    let approximate = RateOptions::preset(Preset::Balanced);
    let weber = RateOptions { weber_fechner: true, ..approximate };
    let a = settled(gpu, &dark, None, &approximate);
    let w = settled(gpu, &dark, None, &weber);
    assert_all(&a, ShadingRate::R2x4, "dark stripes, approximate");
    assert_all(&w, ShadingRate::R1x2, "dark stripes, Weber–Fechner");
    assert_eq!(a, cpu_rates(&dark, None, &approximate));
    assert_eq!(w, cpu_rates(&dark, None, &weber));
    // A smaller constant (less brightness sensitivity) is more conservative still.
    let faint = Frame::grey(size, |x, _| if x % 2 == 0 { 0.020 } else { 0.0203 });
    let strict = RateOptions { weber_fechner_constant: 0.2, ..weber };
    assert_all(&settled(gpu, &faint, None, &weber), ShadingRate::R2x4, "faint dark stripes, constant 1");
    assert_all(&settled(gpu, &faint, None, &strict), ShadingRate::R1x2, "faint dark stripes, constant 0.2");
}

pub fn half_float_inputs_are_read_alike(gpu: &Gpu) {
    // Values exact in f16, so that both precisions hold the same frame.
    let size = (48, 40);
    let stripes = Frame::grey(size, |x, y| [0.375, 0.625][(x % 2) as usize] + 0.125 * (y / 8 % 2) as f32);
    let speeds: Vec<[f32; 2]> = (0..size.0 * size.1).map(|i| [(i % size.0 / 8) as f32, 0.5]).collect();
    let options = RateOptions { motion: true, ..undamped(Preset::Balanced) };
    let full = settled(gpu, &stripes, Some(&speeds), &options);
    let halves = |values: Vec<f32>| -> Vec<u8> {
        values.into_iter().flat_map(|v| half::f16::from_f32(v).to_le_bytes()).collect()
    };
    let color = gpu.texture_with_data(
        "f16 frame",
        size,
        wgpu::TextureFormat::Rgba16Float,
        &halves(stripes.rgb.iter().flat_map(|c| [c[0], c[1], c[2], 1.0]).collect()),
    );
    let velocity = gpu.texture_with_data(
        "f16 velocity",
        size,
        wgpu::TextureFormat::Rg16Float,
        &halves(speeds.iter().flat_map(|v| *v).collect()),
    );
    let mut source = RateSource::new(&gpu.device).unwrap();
    let inputs = RateInputs { velocity: Some(&velocity), ..RateInputs::new(&color) };
    frame(gpu, &mut source, &inputs, &options).unwrap();
    let half_rates = frame(gpu, &mut source, &inputs, &options).unwrap();
    assert_eq!(half_rates, full);
    assert!(full.iter().collect::<std::collections::BTreeSet<_>>().len() >= 3, "varied rates: {full:?}");
}

/// A one- or two-channel output (an AO or shadow pass, say) is read as its
/// luminance: the value itself, or the mean of the two; so a grey frame
/// given as R32Float, as Rg32Float (the value twice) and as RGBA gets the
/// same rates.
pub fn one_and_two_channel_inputs_are_read_as_their_luminance(gpu: &Gpu) {
    let size = (48, 40);
    // Flat on the left (4x4), stripes across x on the right (full rate across them).
    let grey = Frame::grey(size, |x, _| if x < 24 { 0.5 } else { [0.375, 0.625][(x % 2) as usize] });
    let options = undamped(Preset::Balanced);
    let rgba = settled(gpu, &grey, None, &options);
    let value = |c: &[f32; 3]| c[0];
    let bytes = |values: Vec<f32>| -> Vec<u8> { values.into_iter().flat_map(f32::to_le_bytes).collect() };
    let one =
        gpu.texture_with_data("r", size, wgpu::TextureFormat::R32Float, &bytes(grey.rgb.iter().map(value).collect()));
    let two = gpu.texture_with_data(
        "rg",
        size,
        wgpu::TextureFormat::Rg32Float,
        &bytes(grey.rgb.iter().flat_map(|c| [value(c); 2]).collect()),
    );
    for color in [&one, &two] {
        let mut source = RateSource::new(&gpu.device).unwrap();
        frame(gpu, &mut source, &RateInputs::new(color), &options).unwrap();
        let rates = frame(gpu, &mut source, &RateInputs::new(color), &options).unwrap();
        assert_eq!(rates, rgba, "{:?}", color.format());
    }
    assert!(rgba.iter().collect::<std::collections::BTreeSet<_>>().len() >= 2, "varied rates: {rgba:?}");
}

pub fn first_frame_and_resizes_are_full_rate(gpu: &Gpu) {
    let mut source = RateSource::new(&gpu.device).unwrap();
    let options = RateOptions::preset(Preset::Performance);
    let mut run = |frame_: &Frame, options: &RateOptions| {
        let color = frame_.upload(gpu);
        frame(gpu, &mut source, &RateInputs::new(&color), options).unwrap()
    };
    let flat = Frame::grey((64, 32), |_, _| 0.3);
    assert_all(&run(&flat, &options), ShadingRate::R1x1, "first frame");
    assert_all(&run(&flat, &options), ShadingRate::R4x4, "second frame");
    // A resize starts over.
    let larger = Frame::grey((80, 40), |_, _| 0.3);
    assert_all(&run(&larger, &options), ShadingRate::R1x1, "first frame after a resize");
    assert_all(&run(&larger, &options), ShadingRate::R4x4, "second frame after a resize");
    // So does a change of tile size.
    let sixteen = RateOptions { tile: 16, ..options };
    assert_all(&run(&larger, &sixteen), ShadingRate::R1x1, "first frame with 16x16 tiles");
    assert_all(&run(&larger, &sixteen), ShadingRate::R4x4, "second frame with 16x16 tiles");
    // And a reset (a camera cut).
    source.reset();
    let color = larger.upload(gpu);
    assert_all(&frame(gpu, &mut source, &RateInputs::new(&color), &sixteen).unwrap(), ShadingRate::R1x1, "reset");
}

pub fn hysteresis_stops_an_alternating_input_from_flickering(gpu: &Gpu) {
    let size = (32, 32);
    let flat = Frame::grey(size, |_, _| 0.5).upload(gpu);
    let checker = Frame::grey(size, |x, y| if (x + y) % 2 == 0 { 0.1 } else { 0.9 }).upload(gpu);
    let sequence = |gpu: &Gpu, options: &RateOptions, inputs: &[&wgpu::Texture]| -> Vec<ShadingRate> {
        let mut source = RateSource::new(&gpu.device).unwrap();
        inputs.iter().map(|t| frame(gpu, &mut source, &RateInputs::new(t), options).unwrap()[0]).collect()
    };
    let alternating: Vec<&wgpu::Texture> = (0..10).map(|i| if i % 2 == 0 { &flat } else { &checker }).collect();
    // Without damping the rate follows the input: it flips every frame.
    let raw = sequence(gpu, &undamped(Preset::Balanced), &alternating);
    let flips = raw.windows(2).skip(1).filter(|w| w[0] != w[1]).count();
    assert_eq!(flips, 8, "undamped rates {raw:?}");
    // With damping it holds full rate.
    let damped = sequence(gpu, &RateOptions::preset(Preset::Balanced), &alternating);
    assert!(damped.iter().all(|&r| r == ShadingRate::R1x1), "damped rates {damped:?}");
    // It coarsens once three frames agree, and refines at once.
    let settle: Vec<&wgpu::Texture> = vec![&checker, &checker, &flat, &flat, &flat, &flat, &checker, &flat];
    let rates = sequence(gpu, &RateOptions::preset(Preset::Balanced), &settle);
    use ShadingRate::*;
    assert_eq!(rates, [R1x1, R1x1, R1x1, R1x1, R4x4, R4x4, R1x1, R1x1]);
}

pub fn reprojection_follows_the_motion(gpu: &Gpu) {
    // A checker region (1x1) to the left of a flat one (4x4), the boundary
    // moving right by two tiles a frame; the velocity says so.
    let size = (128, 32);
    let step = 16.0;
    let scene =
        |k: u32| Frame::grey(size, move |x, y| if x < 32 + 16 * k { [0.1, 0.9][((x + y) % 2) as usize] } else { 0.5 });
    let v = vec![[step, 0.0]; (size.0 * size.1) as usize];
    let velocity = velocity_texture(gpu, size, &v);
    let tiles = rate_image_size(size, 8);
    for (reproject, hysteresis) in [(true, false), (true, true), (false, true)] {
        let options = RateOptions { reproject, hysteresis, ..RateOptions::preset(Preset::Balanced) };
        let mut source = RateSource::new(&gpu.device).unwrap();
        for k in 0..5 {
            let color = scene(k).upload(gpu);
            let inputs = RateInputs { velocity: Some(&velocity), ..RateInputs::new(&color) };
            let rates = frame(gpu, &mut source, &inputs, &options).unwrap();
            if k < 2 {
                continue;
            }
            // What the next frame's content needs, decided on that frame alone.
            let next = settled(gpu, &scene(k + 1), None, &undamped(Preset::Balanced));
            let mismatches: Vec<(u32, u32, ShadingRate, ShadingRate)> = (0..tiles.1)
                .flat_map(|ty| (0..tiles.0).map(move |tx| (tx, ty)))
                .filter_map(|(tx, ty)| {
                    let i = (ty * tiles.0 + tx) as usize;
                    // The two columns whose content comes from off screen are full rate.
                    let want = if tx < 2 { ShadingRate::R1x1 } else { next[i] };
                    (rates[i] != want).then_some((tx, ty, rates[i], want))
                })
                .collect();
            if reproject {
                assert!(
                    mismatches.is_empty(),
                    "frame {k}, hysteresis {hysteresis}: (tx, ty, got, want) {mismatches:?}"
                );
            } else {
                // Unprojected, the damped rates lag behind the moving boundary.
                assert!(!mismatches.is_empty(), "frame {k}: without reprojection the rates should lag");
            }
        }
    }
}

pub fn external_rates_are_honoured_and_combined_per_axis(gpu: &Gpu) {
    let size = (56, 40); // 7 x 5 tiles
    let tiles = rate_image_size(size, 8);
    let external: Vec<ShadingRate> =
        (0..tiles.0 * tiles.1).map(|i| ShadingRate::ALL[(i as usize * 3 + i as usize / 7) % 7]).collect();
    assert!(ShadingRate::ALL.iter().all(|r| external.contains(r)));
    let texture = upload_rate_image(&gpu.device, &gpu.queue, tiles, &external).unwrap();
    assert_eq!(read_rate_image(&gpu.device, &gpu.queue, &texture).unwrap(), external, "R8Uint round trip");
    // Vertical stripes: the content-adaptive rate is 1x2 everywhere.
    let stripes = Frame::grey(size, |x, _| if x % 2 == 0 { 0.1 } else { 0.9 }).upload(gpu);
    let options = RateOptions::preset(Preset::Balanced);
    for combiner in [Combiner::Override, Combiner::Min, Combiner::Max] {
        let mut source = RateSource::new(&gpu.device).unwrap();
        let inputs =
            RateInputs { external: Some(ExternalRates { texture: &texture, combiner }), ..RateInputs::new(&stripes) };
        // Override holds from the first frame on; the others combine with 1x1 there.
        let first = frame(gpu, &mut source, &inputs, &options).unwrap();
        let second = frame(gpu, &mut source, &inputs, &options).unwrap();
        for (i, &e) in external.iter().enumerate() {
            assert_eq!(first[i], combiner.apply(ShadingRate::R1x1, e), "{combiner:?}, first frame, tile {i}");
            assert_eq!(second[i], combiner.apply(ShadingRate::R1x2, e), "{combiner:?}, tile {i}");
        }
        if combiner == Combiner::Override {
            assert_eq!(second, external);
        }
    }
    // Per axis: 1x2 and 4x2 give 1x2 under min and 4x2 under max.
    assert_eq!(Combiner::Min.apply(ShadingRate::R1x2, ShadingRate::R4x2), ShadingRate::R1x2);
    assert_eq!(Combiner::Max.apply(ShadingRate::R1x2, ShadingRate::R4x2), ShadingRate::R4x2);
}

pub fn foveation_is_full_rate_at_the_gaze(gpu: &Gpu) {
    let size = (96, 64);
    let tiles = rate_image_size(size, 8);
    let flat = Frame::grey(size, |_, _| 0.5);
    let checker = Frame::grey(size, |x, y| if (x + y) % 2 == 0 { 0.1 } else { 0.9 });
    let fovea = |combiner| Foveation { gaze: [30.0, 21.0], inner_radius: 6.0, outer_radius: 20.0, combiner };
    // Min over flat content (4x4), max over a checker (1x1), override: the rings alone.
    for (content, combiner) in [(&flat, Combiner::Min), (&checker, Combiner::Max), (&checker, Combiner::Override)] {
        let f = fovea(combiner);
        let rates = settled(gpu, content, None, &RateOptions { foveation: Some(f), ..Default::default() });
        let expected: Vec<ShadingRate> =
            (0..tiles.1).flat_map(|ty| (0..tiles.0).map(move |tx| f.rate(size, 8, (tx, ty)))).collect();
        assert_eq!(rates, expected, "{combiner:?}");
        assert_eq!(rates[(21 / 8 * tiles.0 + 30 / 8) as usize], ShadingRate::R1x1, "the gaze's tile");
        for r in [ShadingRate::R1x1, ShadingRate::R2x2, ShadingRate::R4x4] {
            assert!(rates.contains(&r), "{combiner:?}: no {r} tile");
        }
    }
}

pub fn bad_inputs_are_typed_errors(gpu: &Gpu) {
    use wgpu::TextureFormat as F;
    let size = (40, 24);
    let mut source = RateSource::new(&gpu.device).unwrap();
    let color = Frame::grey(size, |_, _| 0.5).upload(gpu);
    let target = create_rate_image(&gpu.device, size, 8).unwrap();
    let options = RateOptions::default();
    let mut encode = |inputs: &RateInputs, options: &RateOptions, target: &wgpu::Texture| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        source.encode(&gpu.device, &mut encoder, inputs, options, target)
    };
    // A target of the wrong size, and one of the wrong format.
    let wrong_size = create_rate_image(&gpu.device, (48, 24), 8).unwrap();
    assert_eq!(
        encode(&RateInputs::new(&color), &options, &wrong_size),
        Err(Error::RateImageSize {
            what: "the rate image (target)",
            image: size,
            tile: 8,
            expected: (5, 3),
            found: (6, 3)
        })
    );
    let r8 = upload_rate_image(&gpu.device, &gpu.queue, (5, 3), &[ShadingRate::R1x1; 15]).unwrap();
    assert_eq!(
        encode(&RateInputs::new(&color), &options, &r8),
        Err(Error::RateFormat { what: "the rate image (target)", expected: "R32Uint", found: F::R8Uint })
    );
    // The 16x16 target of a 40x24 image is 3x2.
    let sixteen = RateOptions { tile: 16, ..options };
    assert!(matches!(
        encode(&RateInputs::new(&color), &sixteen, &target),
        Err(Error::RateImageSize { expected: (3, 2), found: (5, 3), .. })
    ));
    // Tile sizes other than 8 and 16.
    assert_eq!(
        encode(&RateInputs::new(&color), &RateOptions { tile: 4, ..options }, &target),
        Err(Error::BadTileSize(4))
    );
    assert_eq!(create_rate_image(&gpu.device, size, 12).err(), Some(Error::BadTileSize(12)));
    // A colour input the source cannot read as linear float values.
    let unorm = gpu.texture_with_data("unorm", size, F::Rgba8Unorm, &vec![0u8; (size.0 * size.1 * 4) as usize]);
    match encode(&RateInputs::new(&unorm), &options, &target) {
        Err(Error::RateFormat { what: "the colour input", expected, found: F::Rgba8Unorm }) => {
            assert!(expected.contains("R32Float") && expected.contains("Rgba16Float"), "{expected}")
        }
        other => panic!("expected a format error, got {other:?}"),
    }
    // Motion without a velocity texture; a velocity of the wrong size or format.
    let motion = RateOptions { motion: true, ..options };
    assert_eq!(encode(&RateInputs::new(&color), &motion, &target), Err(Error::MissingVelocity));
    let small = velocity_texture(gpu, (8, 8), &[[0.0; 2]; 64]);
    let inputs = RateInputs { velocity: Some(&small), ..RateInputs::new(&color) };
    assert!(matches!(encode(&inputs, &motion, &target), Err(Error::SizeMismatch { found_width: 8, width: 40, .. })));
    let inputs = RateInputs { velocity: Some(&unorm), ..RateInputs::new(&color) };
    assert!(matches!(
        encode(&inputs, &motion, &target),
        Err(Error::RateFormat { what: "the velocity input", found: F::Rgba8Unorm, .. })
    ));
    // An external image of the wrong size or format.
    let external = upload_rate_image(&gpu.device, &gpu.queue, (4, 3), &[ShadingRate::R1x1; 12]).unwrap();
    let inputs = RateInputs {
        external: Some(ExternalRates { texture: &external, combiner: Combiner::Min }),
        ..RateInputs::new(&color)
    };
    assert!(matches!(
        encode(&inputs, &options, &target),
        Err(Error::RateImageSize { what: "the external rate image", expected: (5, 3), found: (4, 3), .. })
    ));
    let inputs = RateInputs {
        external: Some(ExternalRates { texture: &unorm, combiner: Combiner::Min }),
        ..RateInputs::new(&color)
    };
    assert!(matches!(
        encode(&inputs, &options, &target),
        Err(Error::RateFormat { what: "the external rate image", found: F::Rgba8Unorm, .. })
    ));
    // Bad numbers.
    assert!(matches!(
        encode(&RateInputs::new(&color), &RateOptions { sensitivity: f32::NAN, ..options }, &target),
        Err(Error::BadRateOption { name: "sensitivity", .. })
    ));
    // A target that cannot be written.
    let readonly = gpu.texture_2d("read-only", (5, 3), F::R32Uint, wgpu::TextureUsages::TEXTURE_BINDING);
    assert_eq!(
        encode(&RateInputs::new(&color), &options, &readonly),
        Err(Error::RateUsage { what: "the rate image (target)", missing: "STORAGE_BINDING" })
    );
    // Reading back what is no rate image.
    assert!(matches!(
        read_rate_image(&gpu.device, &gpu.queue, &unorm),
        Err(Error::RateFormat { found: F::Rgba8Unorm, .. })
    ));
    // None of that advanced the history: the next good frame is the first.
    let flat = Frame::grey(size, |_, _| 0.5).upload(gpu);
    assert_all(&frame(gpu, &mut source, &RateInputs::new(&flat), &options).unwrap(), ShadingRate::R1x1, "first");
}

pub fn gpu_decisions_equal_the_cpu_reference(gpu: &Gpu) {
    let mut rng = Lcg(0x5eed_1234);
    let mut compared = 0;
    let mut ties = 0;
    let mut seen = std::collections::BTreeSet::new();
    for (size, tile) in [((96, 64), 8), ((77, 53), 8), ((77, 53), 16), ((128, 96), 16)] {
        let frame_ = random_frame(&mut rng, size, tile);
        let v: Vec<[f32; 2]> = random_velocity(&mut rng, size, tile);
        for options in [
            RateOptions::preset(Preset::Quality),
            RateOptions::preset(Preset::Balanced),
            RateOptions::preset(Preset::Performance),
            RateOptions { weber_fechner: true, ..RateOptions::preset(Preset::Balanced) },
            RateOptions {
                weber_fechner: true,
                weber_fechner_constant: 0.3,
                ..RateOptions::preset(Preset::Performance)
            },
            RateOptions { motion: true, ..RateOptions::preset(Preset::Balanced) },
            RateOptions {
                motion: true,
                weber_fechner: true,
                k: 1.5,
                env_luma: 0.2,
                ..RateOptions::preset(Preset::Quality)
            },
        ] {
            // Reprojection off: the decision of each tile in place.
            let options = RateOptions { tile, reproject: false, hysteresis: false, ..options };
            let velocity = options.motion.then_some(v.as_slice());
            let gpu_rates = settled(gpu, &frame_, velocity, &options);
            let cpu = cpu_decide(&frame_, velocity, &options);
            for (i, (&g, &(c, tie))) in gpu_rates.iter().zip(&cpu).enumerate() {
                if tie {
                    ties += 1;
                    continue;
                }
                compared += 1;
                seen.insert(c);
                assert_eq!(g, c, "{size:?} tile {tile}, tile index {i}, {options:?}");
            }
        }
    }
    // The random images reach every rate, and ties are rare.
    assert_eq!(seen.len(), 7, "rates reached: {seen:?}");
    assert!(ties * 100 < compared, "{ties} ties in {compared} tiles");
    println!("rate_source: {compared} tiles equal to the CPU reference, {ties} ties skipped");
}

pub fn controller_steers_the_sensitivity_to_a_fraction(gpu: &Gpu) {
    let size = (256, 192);
    let mut rng = Lcg(77);
    let color = random_frame(&mut rng, size, 8).upload(gpu);
    let mut source = RateSource::new(&gpu.device).unwrap();
    let goal = 0.4;
    let mut controller = sensitivity_controller(Target::ShadedFraction(goal), Preset::Quality.sensitivity());
    let mut history = vec![];
    for k in 0..14 {
        let options = RateOptions { sensitivity: controller.threshold() as f32, ..undamped(Preset::Quality) };
        let rates = frame(gpu, &mut source, &RateInputs::new(&color), &options).unwrap();
        let fraction = rate_fraction(&rates, size, 8).unwrap();
        history.push((options.sensitivity, fraction));
        // The first frame is full rate whatever t is: nothing to learn from it.
        if k > 0 {
            controller.update(fraction);
        }
    }
    let (t, fraction) = *history.last().unwrap();
    assert!((fraction - goal).abs() < 0.03, "(t, fraction) per frame: {history:?}");
    println!("rate_source: t = {t:.3} gives a rate fraction of {fraction:.3} (goal {goal}): {history:?}");
}

/// A small deterministic generator (the tests must not depend on a seed source).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
}

/// Per tile a random brightness and contrast (from smooth to noisy), per
/// pixel random noise in a random colour: decisions spread over every rate.
fn random_frame(rng: &mut Lcg, size: (u32, u32), tile: u32) -> Frame {
    let tiles = rate_image_size(size, tile);
    let params: Vec<(f32, f32, f32, f32)> = (0..tiles.0 * tiles.1)
        .map(|_| {
            let base = 0.01 + rng.next().powi(2);
            // Contrast along x and y independently, so that anisotropic rates occur.
            (base, base * rng.next().powi(3) * 2.0, base * rng.next().powi(3) * 2.0, rng.next())
        })
        .collect();
    let noise: Vec<[f32; 4]> = (0..size.0 * size.1).map(|_| [rng.next(), rng.next(), rng.next(), rng.next()]).collect();
    Frame::new(size, |x, y| {
        let (base, ax, ay, tint) = params[((y / tile) * tiles.0 + x / tile) as usize];
        let n = noise[(y * size.0 + x) as usize];
        // Stripes along x from ax, along y from ay, plus a little noise.
        let l = base + ax * (x % 2) as f32 + ay * (y % 2) as f32 + 0.05 * base * n[0];
        [l * (0.6 + 0.8 * tint), l, l * (0.6 + 0.8 * (1.0 - tint)) + 0.01 * n[1]]
    })
}

fn random_velocity(rng: &mut Lcg, size: (u32, u32), tile: u32) -> Vec<[f32; 2]> {
    let tiles = rate_image_size(size, tile);
    let per_tile: Vec<f32> = (0..tiles.0 * tiles.1).map(|_| 6.0 * rng.next()).collect();
    (0..size.0 * size.1)
        .map(|i| {
            let (x, y) = (i % size.0, i / size.0);
            let s = per_tile[((y / tile) * tiles.0 + x / tile) as usize] * (1.0 + rng.next());
            let a = std::f32::consts::TAU * rng.next();
            [s * a.cos(), s * a.sin()]
        })
        .collect()
}

/// The CPU reference's rates, asserting there is no tie.
fn cpu_rates(frame_: &Frame, velocity: Option<&[[f32; 2]]>, options: &RateOptions) -> Vec<ShadingRate> {
    cpu_decide(frame_, velocity, options)
        .into_iter()
        .map(|(r, tie)| {
            assert!(!tie, "a synthetic frame should not sit on a threshold");
            r
        })
        .collect()
}

/// Relative distance from a threshold under which the CPU reference calls a
/// comparison a tie: the GPU sums in f32 in another order (and its `pow`
/// and `sqrt` are not correctly rounded), so its error or threshold may
/// differ by some 1e-6 relative; 1e-3 leaves a wide margin.
const TIE: f64 = 1e-3;

/// The decision of every tile, computed in f64 from the same equations as
/// rate_source.wgsl (docs/rate-image.md), with whether any comparison was
/// within [`TIE`] of its threshold.
fn cpu_decide(frame_: &Frame, velocity: Option<&[[f32; 2]]>, o: &RateOptions) -> Vec<(ShadingRate, bool)> {
    let (w, h) = frame_.size;
    let luma = |x: u32, y: u32| {
        let c = frame_.rgb[(y * w + x) as usize];
        0.212671 * f64::from(c[0]) + 0.715160 * f64::from(c[1]) + 0.072169 * f64::from(c[2])
    };
    let min3 = |x: u32, y: u32| {
        let mut m = f64::MAX;
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let (nx, ny) = ((x as i64 + dx).clamp(0, w as i64 - 1), (y as i64 + dy).clamp(0, h as i64 - 1));
                m = m.min(luma(nx as u32, ny as u32));
            }
        }
        m
    };
    let tile = o.tile;
    let tiles = rate_image_size(frame_.size, tile);
    let mut out = vec![];
    for ty in 0..tiles.1 {
        for tx in 0..tiles.0 {
            let (mut sum, mut sx, mut sy, mut nx, mut ny, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            let mut speed = f64::MAX;
            for y in ty * tile..((ty + 1) * tile).min(h) {
                for x in tx * tile..((tx + 1) * tile).min(w) {
                    let l = luma(x, y);
                    let bs = if o.weber_fechner {
                        f64::from(o.weber_fechner_constant) * (1.0 - (min3(x, y) * 50.0 - 2.5).clamp(0.0, 1.0))
                    } else {
                        0.0
                    };
                    let diff = |a: f64, b: f64| {
                        if o.weber_fechner {
                            (a - b).abs() / (a.min(b) + bs).max(f64::from(mrsl_runtime::rate_source::WEBER_FLOOR))
                        } else {
                            (a - b).abs() / 2.0
                        }
                    };
                    sum += l;
                    n += 1.0;
                    if x > 0 {
                        sx += diff(l, luma(x - 1, y));
                        nx += 1.0;
                    }
                    if y > 0 {
                        sy += diff(l, luma(x, y - 1));
                        ny += 1.0;
                    }
                    if let Some(v) = velocity {
                        let [vx, vy] = v[(y * w + x) as usize];
                        speed = speed.min(f64::from(vx).hypot(f64::from(vy)));
                    }
                }
            }
            let tau = f64::from(o.sensitivity) * (sum / n + f64::from(o.env_luma));
            let mean = |s: f64, n: f64| if n > 0.0 { s / n } else { 0.0 };
            let errors = [mean(sx, nx).sqrt(), mean(sy, ny).sqrt()];
            let (mut half, mut quarter) = (1.0, f64::from(o.k));
            if o.motion {
                half = (1.0 / (1.0 + (1.05 * speed).powf(3.10))).powf(0.35);
                quarter = f64::from(o.k) * (1.0 / (1.0 + (0.55 * speed).powf(2.41))).powf(0.49);
            }
            let near = |a: f64| tau > 0.0 && (a / tau - 1.0).abs() < TIE;
            let mut tie = false;
            let mut axis = |e: f64| {
                tie |= near(half * e) || near(quarter * e);
                if half * e >= tau {
                    1
                } else if quarter * e < tau {
                    4
                } else {
                    2
                }
            };
            let (ax, ay) = (axis(errors[0]), axis(errors[1]));
            out.push((ShadingRate::clamp_size(ax, ay), tie));
        }
    }
    out
}
