//! The background rule (`@background`) and the surface key
//! (`@surface_key`): background pixels are never evaluated, refined or
//! resampled from, forced refinement still equals the reference there, and
//! a surface key refines the same pixels whatever the scene's scale.

use crate::harness::*;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::{BACKGROUND, ChannelData, GBuffer, Scene};
use mrsl_runtime::{DispatchOptions, Mode};

/// Lighting over the demo scene's spheres, ground and sky (material 255),
/// with a derivative, a refine predicate, an integer coarse effect and one
/// that reads the position.
const PROGRAM: &str = "\
@surface_key(normal, 0.25) in float3 position;
@key(0.4) in float3 normal;
@background(255) in uint material;
uniform float3 light = float3(0.3, 0.9, 0.3);
coarse effect float diffuse {
    diffuse = saturate(dot(normalize(normal), normalize(light)));
    if (fwidth(diffuse) > 0.02) refine;
}
coarse effect uint band = uint(diffuse * 4.0);
coarse effect float3 tint = float3(diffuse * 0.5, 0.25, 0.1 * float(band));
// Reads the position (so its key concerns it) in a way no scale changes.
coarse effect float3 direction = normalize(position);
fine out float4 color = material == 255u
    ? float4(0.3, 0.4, 0.6, 1.0)
    : float4(tint + float3(diffuse) + 0.1 * direction, 1.0);
";

/// The size of the background test: odd, so that blocks and tiles cut the
/// image, and wide enough for the sky to fill a 32x32 tile.
const W: usize = 131;
const H: usize = 83;

fn materials(gbuffer: &GBuffer) -> &[u32] {
    match gbuffer.channels.iter().find(|(n, _)| n == "material") {
        Some((_, ChannelData::Uint(ids))) => ids,
        _ => panic!("the demo scene has a material channel"),
    }
}

/// Pixels in `tile`-pixel tiles of a `w` x `h` image whose every pixel is background.
fn sky_tiles(background: &[bool], (w, h): (usize, usize), tile: usize) -> usize {
    (0..h.div_ceil(tile))
        .flat_map(|ty| (0..w.div_ceil(tile)).map(move |tx| (tx, ty)))
        .filter(|&(tx, ty)| {
            let rows = ty * tile..(ty * tile + tile).min(h);
            rows.flat_map(|y| (tx * tile..(tx * tile + tile).min(w)).map(move |x| y * w + x)).all(|i| background[i])
        })
        .count()
}

/// Forced refinement equals the reference bit for bit, background pixels
/// included; adaptive (the block and dynamic modes shading wholly-background
/// tiles from their own list, the hierarchical mode its wholly-background
/// 32x32 tiles), a background pixel is counted as background and
/// nothing else (the refine mask marks it x 0, y all ones), its output is
/// the reference's, and no coarse evaluation is spent on a background sample.
pub fn background_pixels_are_never_shaded_or_refined(gpu: &Gpu) {
    let program = compile(PROGRAM);
    // An odd size: blocks and tiles the image cuts.
    let (w, h) = (W, H);
    let gbuffer = Scene::Demo.render(w as u32, h as u32);
    let background: Vec<bool> = materials(&gbuffer).iter().map(|&m| m == BACKGROUND).collect();
    let count = background.iter().filter(|&&b| b).count() as u64;
    assert!(count > 200 && count < background.len() as u64 / 2, "the demo shows some sky: {count} pixels");
    // The block and dynamic modes shade these with their background entry
    // point, the hierarchical mode its tiles of 32 pixels.
    let tiles = sky_tiles(&background, (w, h), mrsl_abi::geometry::TILE as usize);
    assert!(tiles >= 3, "the demo has wholly-background tiles: {tiles}");
    let tiles = sky_tiles(&background, (w, h), mrsl_abi::geometry::HIERARCHICAL_TILE as usize);
    assert!(tiles >= 1, "the demo has wholly-background hierarchical tiles: {tiles}");
    let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap().pixels;
    for mode in adaptive_modes() {
        let forced = run(gpu, &program, &gbuffer, mode, true).unwrap();
        assert_eq!(worst_ulps(&forced.pixels, &reference), 0, "{mode}: forced refinement differs from the reference");
        let rates = mrsl_lab::shading_rate::pattern(mrsl_abi::shading_rate::rate_image_size((W as u32, H as u32), 8));
        let options = DispatchOptions { rate_tile: 8, ..DispatchOptions::new(mode) };
        let [run] = dispatch_in_turn(gpu, &program, &gbuffer, &rates, [options]).unwrap();
        let stats = run.stats.unwrap();
        assert_eq!(stats.background_pixels, count, "{mode}: background pixels counted");
        let (x, y) = (run.refine_masks.unwrap(), run.refine_masks_y.unwrap());
        for (i, &bg) in background.iter().enumerate() {
            if bg {
                assert_eq!((x[i], y[i]), (0, u32::MAX), "{mode}: pixel {i} is background");
                assert_eq!(run.pixels[i], reference[i], "{mode}: pixel {i} shows the sky");
            } else {
                assert_ne!(y[i], u32::MAX, "{mode}: pixel {i} was drawn");
            }
        }
        let pixels = background.len() as u64;
        for e in stats.effects.iter().filter(|e| e.rate == mrsl_abi::Rate::Coarse) {
            assert!(e.pixel_evaluations <= pixels - count, "{mode}: `{}` evaluated at background pixels", e.name);
            assert_eq!(e.resampled + e.pixel_evaluations + count, pixels, "{mode}: `{}`'s pixels add up", e.name);
            if stats.coarse_samples > 0 {
                assert_eq!(e.coarse_evaluations, stats.coarse_samples - stats.background_samples, "{mode}");
                assert!(stats.background_samples > 0, "{mode}: some coarse samples fall on the sky");
            }
        }
    }
}

/// The scene with every position multiplied by `scale` about the origin (the
/// camera with it): the same image, in other units.
fn scaled(gbuffer: &GBuffer, scale: f32) -> GBuffer {
    let mut scaled = gbuffer.clone();
    for (name, data) in &mut scaled.channels {
        if let (true, ChannelData::Float { data, .. }) = (name == "position", data) {
            data.iter_mut().for_each(|v| *v *= scale);
        }
    }
    scaled
}

/// The pixels that evaluated some coarse effect per pixel.
fn refined(gpu: &Gpu, program: &mrsl::Program, gbuffer: &GBuffer) -> usize {
    let options = DispatchOptions::new(Mode::Coarse4x4);
    let size = (gbuffer.width, gbuffer.height);
    let rates = mrsl_lab::shading_rate::pattern(mrsl_abi::shading_rate::rate_image_size(size, options.rate_tile));
    let [run] = dispatch_in_turn(gpu, program, gbuffer, &rates, [options]).unwrap();
    run.refine_masks.unwrap().iter().filter(|&&m| m != 0).count()
}

/// A surface key refines the same silhouettes in the scene scaled by 0.01
/// and by 100 (within 1% of the refined pixels, for rounding), where a
/// threshold key in world units refines others at each scale.
pub fn surface_keys_refine_the_same_pixels_at_any_scale(gpu: &Gpu) {
    let gbuffer = Scene::Demo.render(160, 90);
    let surface = compile(PROGRAM);
    let at_one = refined(gpu, &surface, &gbuffer);
    assert!(at_one > 100, "the silhouettes refine: {at_one} pixels");
    for scale in [0.01, 100.0] {
        let at_scale = refined(gpu, &surface, &scaled(&gbuffer, scale));
        let apart = at_scale.abs_diff(at_one) as f64 / at_one as f64;
        println!("surface key: {at_scale} refined pixels at scale {scale}, {at_one} at 1");
        assert!(
            apart <= 0.01,
            "scale {scale}: {at_scale} refined pixels against {at_one} ({:.1}% apart)",
            100.0 * apart
        );
    }
    // The same program with the position compared in world units.
    let world = compile(&PROGRAM.replace("@surface_key(normal, 0.25)", "@key(0.5)"));
    let small = refined(gpu, &world, &scaled(&gbuffer, 0.01));
    let large = refined(gpu, &world, &scaled(&gbuffer, 100.0));
    println!("world-unit key: {small} refined pixels at scale 0.01, {large} at 100");
    assert!(large > 2 * small, "a world-unit key refines far more of a larger scene: {large} against {small}");
}

/// Fine effects that read the background channel, at the pixel and at its
/// quad partner (`fwidth`), for the test below.
const CHANNEL_PROGRAM: &str = "\
in float3 normal;
@background(255) in uint material;
coarse effect float lit = saturate(normal.y);
fine effect float id = float(material);
fine effect float jump = fwidth(float(material));
fine out float4 color = float4(id / 255.0, jump, lit, 1.0);
";

/// The entry points over wholly-background tiles evaluate the fine effects
/// with the background channel's value at the pixel they shade, not a load
/// (so that what a program computes only for drawn pixels folds away
/// there). The value is the pixel's own: a quad partner in another tile
/// still reads its own channel. Here the image is one pixel wider and taller
/// than a multiple of 8 and 32, so the last column and row lie in tiles of
/// their own, which the test makes background, with drawn pixels in the
/// column and row before them: the last pixels' quad partners (the border
/// rule pairs them with those) lie in surface tiles. Every mode's background
/// pixels must equal the reference's bit for bit.
pub fn background_tiles_read_their_own_channel(gpu: &Gpu) {
    let (w, h) = (129usize, 89usize);
    let mut gbuffer = Scene::Demo.render(w as u32, h as u32);
    let Some((_, ChannelData::Uint(ids))) = gbuffer.channels.iter_mut().find(|(n, _)| n == "material") else {
        panic!("the demo scene has a material channel")
    };
    for y in 0..h {
        for x in 0..w {
            let id = &mut ids[y * w + x];
            if x == w - 1 || y == h - 1 {
                *id = BACKGROUND;
            } else if (x == w - 2 || y == h - 2) && *id == BACKGROUND {
                *id = 1;
            }
        }
    }
    let background: Vec<bool> = materials(&gbuffer).iter().map(|&m| m == BACKGROUND).collect();
    let program = compile(CHANNEL_PROGRAM);
    let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap().pixels;
    // The last column's pixels (but the corner's) differ from their drawn
    // partners: the test can fail.
    let jumps = (0..h - 1).filter(|y| reference[y * w + w - 1][1] != 0.0).count();
    assert_eq!(jumps, h - 1, "the last column's pixels step to their drawn partners");
    for mode in adaptive_modes() {
        let pixels = run(gpu, &program, &gbuffer, mode, false).unwrap().pixels;
        for (i, &bg) in background.iter().enumerate() {
            if bg {
                let (x, y) = (i % w, i / w);
                assert_eq!(pixels[i], reference[i], "{mode}: background pixel ({x}, {y})");
            }
        }
    }
}
