//! The rate-image mode against a CPU model of its sampling rule: which
//! samples each tile lists, which cell corners each pixel resamples, how a
//! tile border shared with a coarser tile is resampled. The model is written
//! from the rule in docs/rate-image.md, not from the kernels.

use crate::{compile, run, run_at_rates, worst_ulps};
use mrsl_abi::ShadingRate;
use mrsl_abi::shading_rate::rate_image_size;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::{ChannelData, GBuffer, Scene};
use mrsl_runtime::{Bindings, DispatchOptions, Error, Mode, Shader};
use std::collections::HashSet;

/// The sampling rule for one image: tile size and one rate per tile.
struct Model<'a> {
    size: (i64, i64),
    tile: i64,
    tiles: (i64, i64),
    rates: &'a [ShadingRate],
}

/// One corner of a pixel's cell: two samples and the weight of the second.
type Corner = ((i64, i64), (i64, i64), f64);

impl<'a> Model<'a> {
    fn new(size: (u32, u32), tile: u32, rates: &'a [ShadingRate]) -> Self {
        let tiles = rate_image_size(size, tile);
        Model {
            size: (size.0 as i64, size.1 as i64),
            tile: tile as i64,
            tiles: (tiles.0 as i64, tiles.1 as i64),
            rates,
        }
    }

    fn rate(&self, t: (i64, i64)) -> (i64, i64) {
        let (w, h) = self.rates[(t.1 * self.tiles.0 + t.0) as usize].size();
        (w as i64, h as i64)
    }

    /// Positions along one axis a tile lists at `step`: its lattice, and the
    /// image's last pixel where the tile reaches the edge off the lattice.
    fn axis(&self, origin: i64, step: i64, n: i64) -> Vec<i64> {
        let end = (origin + self.tile).min(n);
        let mut at: Vec<i64> = (origin..end).step_by(step as usize).collect();
        if end == n && (n - 1 - origin) % step != 0 {
            at.push(n - 1);
        }
        at
    }

    /// Every sample the tiles list.
    fn listed(&self) -> Vec<(i64, i64)> {
        let mut out = vec![];
        for ty in 0..self.tiles.1 {
            for tx in 0..self.tiles.0 {
                let origin = (tx * self.tile, ty * self.tile);
                let rate = self.rate((tx, ty));
                if rate != (1, 1) {
                    // Its lattice, but along its first row (column) only the coarser side's steps.
                    let row_step = if ty > 0 { rate.0.max(self.rate((tx, ty - 1)).0) } else { rate.0 };
                    let column_step = if tx > 0 { rate.1.max(self.rate((tx - 1, ty)).1) } else { rate.1 };
                    for &y in &self.axis(origin.1, rate.1, self.size.1) {
                        for &x in &self.axis(origin.0, rate.0, self.size.0) {
                            let on_row = y == origin.1 && (x - origin.0) % row_step == 0 || x == self.size.0 - 1;
                            let on_column = x == origin.0 && (y - origin.1) % column_step == 0 || y == self.size.1 - 1;
                            let inside = x != origin.0 && y != origin.1;
                            if inside || (y == origin.1 && on_row) || (x == origin.0 && on_column) {
                                out.push((x, y));
                            }
                        }
                    }
                    continue;
                }
                // A full-rate tile lists what its coarser left, upper and upper-left neighbours' cells need.
                let mut mine = vec![];
                if tx > 0 && ty > 0 && self.rate((tx - 1, ty - 1)) != (1, 1) {
                    mine.push(origin);
                }
                if tx > 0 && self.rate((tx - 1, ty)) != (1, 1) {
                    let step = self.rate((tx - 1, ty)).1;
                    mine.extend(self.axis(origin.1, step, self.size.1).into_iter().map(|y| (origin.0, y)));
                }
                if ty > 0 && self.rate((tx, ty - 1)) != (1, 1) {
                    let step = self.rate((tx, ty - 1)).0;
                    mine.extend(self.axis(origin.0, step, self.size.0).into_iter().map(|x| (x, origin.1)));
                }
                mine.sort();
                mine.dedup();
                out.extend(mine);
            }
        }
        out
    }

    /// Corner `c` of a cell of tile `t`: on a tile border shared with a
    /// neighbour, the border is resampled every `max(rates along it)` pixels.
    fn corner(&self, c: (i64, i64), t: (i64, i64), rate: (i64, i64)) -> Corner {
        let origin = (t.0 * self.tile, t.1 * self.tile);
        let on_x = c.0 == origin.0 || c.0 == origin.0 + self.tile;
        let on_y = c.1 == origin.1 || c.1 == origin.1 + self.tile;
        let blend = |along: i64, start: i64, step: i64, n: i64| {
            let off = (along - start) % step;
            if off == 0 || along == n - 1 {
                return (along, along, 0.0);
            }
            let a = along - off;
            let b = (a + step).min(n - 1);
            (a, b, (along - a) as f64 / (b - a) as f64)
        };
        if on_x && !on_y {
            let n = if c.0 == origin.0 { t.0 - 1 } else { t.0 + 1 };
            if (0..self.tiles.0).contains(&n) {
                let step = rate.1.max(self.rate((n, t.1)).1);
                let (a, b, f) = blend(c.1, origin.1, step, self.size.1);
                return ((c.0, a), (c.0, b), f);
            }
        } else if on_y && !on_x {
            let n = if c.1 == origin.1 { t.1 - 1 } else { t.1 + 1 };
            if (0..self.tiles.1).contains(&n) {
                let step = rate.0.max(self.rate((t.0, n)).0);
                let (a, b, f) = blend(c.0, origin.0, step, self.size.0);
                return ((a, c.1), (b, c.1), f);
            }
        }
        (c, c, 0.0)
    }

    /// The four corners of pixel `p`'s cell with their bilinear weights, or
    /// `None` in a full-rate tile (shaded per pixel).
    fn cell(&self, p: (i64, i64)) -> Option<[(Corner, f64); 4]> {
        let t = (p.0 / self.tile, p.1 / self.tile);
        let rate = self.rate(t);
        if rate == (1, 1) {
            return None;
        }
        let origin = (t.0 * self.tile, t.1 * self.tile);
        let p0 = (origin.0 + (p.0 - origin.0) / rate.0 * rate.0, origin.1 + (p.1 - origin.1) / rate.1 * rate.1);
        let p1 = ((p0.0 + rate.0).min(self.size.0 - 1), (p0.1 + rate.1).min(self.size.1 - 1));
        let frac = |v: i64, a: i64, b: i64| if b > a { (v - a) as f64 / (b - a) as f64 } else { 0.0 };
        let (u, v) = (frac(p.0, p0.0, p1.0), frac(p.1, p0.1, p1.1));
        Some([
            (self.corner(p0, t, rate), (1.0 - u) * (1.0 - v)),
            (self.corner((p1.0, p0.1), t, rate), u * (1.0 - v)),
            (self.corner((p0.0, p1.1), t, rate), (1.0 - u) * v),
            (self.corner(p1, t, rate), u * v),
        ])
    }
}

/// A coarse effect that no interpolation can guess: a hash of the pixel.
const HASH: &str = "
in float2 coord;
coarse effect float h = fract(sin(dot(coord, float2(12.9898, 78.233))) * 43758.5453);
fine out float4 color = float4(h, 0.0, 0.0, 1.0);
";

fn coords(size: (u32, u32)) -> GBuffer {
    let data = (0..size.1).flat_map(|y| (0..size.0).flat_map(move |x| [x as f32, y as f32])).collect();
    GBuffer {
        width: size.0,
        height: size.1,
        channels: vec![("coord".into(), ChannelData::Float { components: 2, data })],
    }
}

/// Each pixel of the rate-image mode is the model's blend of the reference's
/// values at the samples the model names, and the tiles list exactly the
/// model's samples, for mixed and uniform rates, both tile sizes and sizes
/// that cut tiles at the edges. The values are in [0, 1); the kernel blends
/// up to eight of them in f32, so 1e-5 bounds the rounding (the model
/// computes in f64), while a wrong sample is off by about 0.3 on average.
pub fn pixels_blend_the_samples_of_their_tiles_rate(gpu: &Gpu) {
    let program = compile(HASH);
    let mut cases: Vec<((u32, u32), u32, Vec<ShadingRate>)> = vec![];
    for (size, tile) in [((61, 37), 8), ((61, 37), 16), ((160, 160), 8), ((9, 1), 8), ((1, 1), 8)] {
        cases.push((size, tile, mrsl_lab::shading_rate::pattern(rate_image_size(size, tile))));
    }
    for rate in ShadingRate::ALL {
        let size = (29, 21);
        let (tx, ty) = rate_image_size(size, 8);
        cases.push((size, 8, vec![rate; (tx * ty) as usize]));
    }
    for (size, tile, rates) in &cases {
        let gbuffer = coords(*size);
        let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap();
        let out = run_at_rates(gpu, &program, &gbuffer, Mode::RateImage, false, *tile, rates).unwrap();
        let model = Model::new(*size, *tile, rates);
        let listed = model.listed();
        let unique: HashSet<(i64, i64)> = listed.iter().copied().collect();
        assert_eq!(unique.len(), listed.len(), "{size:?}/{tile}: a sample is listed twice");
        assert_eq!(out.stats.coarse_samples, listed.len() as u64, "{size:?}/{tile}: samples listed");
        let value = |p: (i64, i64)| reference.pixels[(p.1 * model.size.0 + p.0) as usize][0] as f64;
        let mut worst = (0.0f64, (0, 0));
        for y in 0..model.size.1 {
            for x in 0..model.size.0 {
                let got = out.pixels[(y * model.size.0 + x) as usize][0] as f64;
                let want = match model.cell((x, y)) {
                    None => value((x, y)),
                    Some(corners) => corners
                        .iter()
                        .map(|&((a, b, f), w)| {
                            for s in [a, b] {
                                assert!(w == 0.0 || unique.contains(&s), "{size:?}/{tile}: ({x}, {y}) needs {s:?}");
                            }
                            w * ((1.0 - f) * value(a) + f * value(b))
                        })
                        .sum(),
                };
                if (got - want).abs() > worst.0 {
                    worst = ((got - want).abs(), (x, y));
                }
            }
        }
        assert!(worst.0 <= 1e-5, "{size:?} tile {tile}: pixel {:?} is off the model by {}", worst.1, worst.0);
    }
}

/// Resampling across a tile border uses the coarser side's samples on both
/// sides, so a smooth function shows no seam there: the step between the
/// two pixel columns astride a border is no larger than the steps inside
/// the tiles. The function is a paraboloid, which bilinear resampling does
/// not reproduce, so a seam (a jump at the border) would show.
pub fn tile_borders_have_no_seams(gpu: &Gpu) {
    let program = compile(
        "in float2 coord;\ncoarse effect float q = dot(coord - float2(20.0, 13.0), coord - float2(20.0, 13.0)) / 800.0;\nfine out float4 color = float4(q, 0.0, 0.0, 1.0);\n",
    );
    let size = (48u32, 32u32);
    // Fine (1x2) beside coarse (4x4) tiles, in columns and in rows.
    let (tx, ty) = rate_image_size(size, 8);
    let rates: Vec<ShadingRate> = (0..ty)
        .flat_map(|y| (0..tx).map(move |x| if (x + y) % 2 == 0 { ShadingRate::R4x4 } else { ShadingRate::R1x2 }))
        .collect();
    let gbuffer = coords(size);
    let out = run_at_rates(gpu, &program, &gbuffer, Mode::RateImage, false, 8, &rates).unwrap();
    let at = |x: u32, y: u32| out.pixels[(y * size.0 + x) as usize][0];
    let model = Model::new(size, 8, &rates);
    // The image is the model's, as above (so the borders are blended as specified) ...
    let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap();
    let value = |p: (i64, i64)| reference.pixels[(p.1 * size.0 as i64 + p.0) as usize][0] as f64;
    for y in 0..size.1 as i64 {
        for x in 0..size.0 as i64 {
            let want = match model.cell((x, y)) {
                None => value((x, y)),
                Some(c) => c.iter().map(|&((a, b, f), w)| w * ((1.0 - f) * value(a) + f * value(b))).sum(),
            };
            assert!((at(x as u32, y as u32) as f64 - want).abs() <= 1e-5, "({x}, {y})");
        }
    }
    // ... and continuous: along each border column x = 8k, the values just
    // left and right of it differ by no more than one interior step does.
    for k in 1..tx {
        let x = 8 * k;
        for y in 0..size.1 {
            let across = (at(x, y) - at(x - 1, y)).abs();
            let inside = (at(x + 1, y) - at(x, y)).abs().max((at(x - 1, y) - at(x - 2, y)).abs());
            assert!(across <= inside * 1.5 + 1e-4, "seam at x = {x}, y = {y}: {across} against {inside}");
        }
    }
}

/// With every predicate forced, the rate-image mode evaluates every effect
/// per pixel with the reference kernel's code: bit-identical images, at
/// every rate, with tiles of 8 and 16, at sizes that cut tiles.
pub fn forced_refinement_equals_reference_at_every_rate(gpu: &Gpu) {
    let program = compile(include_str!("../../examples/demo.mrsl"));
    for (w, h) in [(37, 23), (1, 1)] {
        let gbuffer = Scene::Demo.render(w, h);
        let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap();
        for tile in [8, 16] {
            let tiles = rate_image_size((w, h), tile);
            let n = (tiles.0 * tiles.1) as usize;
            let mut images: Vec<Vec<ShadingRate>> = ShadingRate::ALL.iter().map(|&r| vec![r; n]).collect();
            images.push(mrsl_lab::shading_rate::pattern(tiles));
            for rates in images {
                let out = run_at_rates(gpu, &program, &gbuffer, Mode::RateImage, true, tile, &rates).unwrap();
                let worst = worst_ulps(&out.pixels, &reference.pixels);
                assert_eq!(worst, 0, "{w}x{h} tile {tile} {}: {worst} ulps off the reference", rates[0]);
            }
        }
    }
}

/// Full rate everywhere is the reference, unforced; coarser rates shade
/// fewer samples, and refinement still catches the scene's edges (the
/// Phong test program over the demo scene, which the orders below were
/// measured with).
pub fn coarser_rates_shade_less(gpu: &Gpu) {
    let program = compile(include_str!("data/phong.mrsl"));
    let size = (160u32, 96u32);
    let gbuffer = Scene::Demo.render(size.0, size.1);
    let reference = run(gpu, &program, &gbuffer, Mode::Reference, false).unwrap();
    let n = {
        let t = rate_image_size(size, 8);
        (t.0 * t.1) as usize
    };
    let shade = |rate: ShadingRate| run_at_rates(gpu, &program, &gbuffer, Mode::RateImage, false, 8, &vec![rate; n]);
    let full = shade(ShadingRate::R1x1).unwrap();
    assert!(full.pixels == reference.pixels, "1x1 everywhere differs from the reference");
    // Full-rate tiles list nothing when no neighbour is coarser.
    assert_eq!(full.stats.coarse_samples, 0);
    assert_eq!(full.stats.coarse_shaded_fraction, 1.0);
    let fractions: Vec<(ShadingRate, f64)> =
        ShadingRate::ALL.iter().map(|&r| (r, shade(r).unwrap().stats.coarse_shaded_fraction)).collect();
    eprintln!("demo 160x96 rate-image, fraction of the coarse work per uniform rate: {fractions:?}");
    let of = |r: ShadingRate| fractions.iter().find(|(x, _)| *x == r).unwrap().1;
    assert!(of(ShadingRate::R2x2) < of(ShadingRate::R1x2), "{fractions:?}");
    assert!(of(ShadingRate::R2x4) < of(ShadingRate::R2x2), "{fractions:?}");
    assert!(of(ShadingRate::R4x4) < of(ShadingRate::R2x4), "{fractions:?}");
    assert!(of(ShadingRate::R4x2) < of(ShadingRate::R2x2), "{fractions:?}");
    // 4x4 and 4x2 are not ordered on this scene: larger cells straddle more of the keys'
    // edges, so more pixels refine (measured on lavapipe: 0.599 against 0.580 of the coarse work).
    assert!(of(ShadingRate::R4x4) < of(ShadingRate::R2x2), "{fractions:?}");
    let quality = crate::psnr_of(&shade(ShadingRate::R4x4).unwrap().pixels, &reference.pixels);
    // 4x4 everywhere shades the coarse effects on the block mode's lattice, with the same
    // refine predicates (derivatives across a cell) and keys, so the quality is the coarse
    // 4x4 mode's (measured on lavapipe: 76.5 dB for both); 1 dB of slack for another driver.
    let block = run(gpu, &program, &gbuffer, Mode::Coarse4x4, false).unwrap();
    let block_quality = crate::psnr_of(&block.pixels, &reference.pixels);
    eprintln!("demo 160x96: rate-image 4x4 {quality:.1} dB, coarse4x4 {block_quality:.1} dB");
    assert!(quality >= block_quality - 1.0, "{quality} dB against the 4x4 mode's {block_quality} dB");
}

/// Bad shading-rate images are typed errors naming what is wrong.
pub fn bad_shading_rate_images_are_typed_errors(gpu: &Gpu) {
    let program = compile(HASH);
    let size = (40u32, 24u32);
    let gbuffer = coords(size);
    let channels = gbuffer.upload(gpu);
    let color = gpu.output_texture("color", size, wgpu::TextureFormat::Rgba32Float);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    let good = mrsl_lab::shading_rate::upload_pattern(gpu, size, 8);
    let wrong_size = mrsl_lab::shading_rate::upload_pattern(gpu, (48, 24), 8);
    let float = gpu.output_texture("float", rate_image_size(size, 8), wgpu::TextureFormat::R32Float);
    let mut encode = |rate: Option<&wgpu::Texture>, tile: u32| {
        let mut bindings = Bindings { size, ..Default::default() };
        for (name, t) in &channels {
            bindings.channels.insert(name.clone(), t);
        }
        bindings.outputs.insert("color".into(), &color);
        bindings.shading_rate = rate;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let options = DispatchOptions { rate_tile: tile, ..DispatchOptions::new(Mode::RateImage) };
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, options)
    };
    assert_eq!(encode(None, 8), Err(Error::MissingShadingRate));
    match encode(Some(&float), 8) {
        Err(e @ Error::RateFormat { found: wgpu::TextureFormat::R32Float, .. }) => {
            assert!(e.to_string().contains("R8Uint"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(encode(Some(&good), 12), Err(Error::BadTileSize(12)));
    match encode(Some(&wrong_size), 8) {
        Err(e @ Error::RateImageSize { expected: (5, 3), found: (6, 3), tile: 8, .. }) => {
            assert!(e.to_string().contains("shading-rate image is 6x3"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // The same image is the wrong size for 16-pixel tiles.
    assert!(matches!(encode(Some(&good), 16), Err(Error::RateImageSize { expected: (3, 2), .. })));
    assert_eq!(encode(Some(&good), 8), Ok(()));
}
