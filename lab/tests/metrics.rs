//! Tests of `mrsl_lab::metrics`: fixtures with MSSIM, RMSE, PSNR and FLIP computed in Python (scikit-image, a
//! transcription of Wang's `ssim_index.m`, NVIDIA's `flip_evaluator`; see `tests/data/gen_fixtures.py`), closed
//! forms, symmetry and identity, and every error path.

use mrsl_lab::metrics::{self, Metrics, MetricsError};
use serde::Deserialize;
use std::path::PathBuf;

#[derive(Deserialize)]
struct Expected {
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    width: u32,
    height: u32,
    reference: String,
    test: String,
    mssim: f64,
    mssim_skimage: f64,
    rmse: f64,
    psnr: f64,
    flip_mean: f64,
}

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// Reads a raw little-endian f32 RGBA image.
fn load(name: &str, width: u32, height: u32) -> Vec<[f32; 4]> {
    let bytes = std::fs::read(data(name)).unwrap();
    assert_eq!(bytes.len(), 16 * (width * height) as usize, "{name}");
    bytes
        .chunks_exact(16)
        .map(|p| std::array::from_fn(|c| f32::from_le_bytes(p[4 * c..4 * c + 4].try_into().unwrap())))
        .collect()
}

/// A fixture: its expected values, the test image and the reference image.
type Fixture = (Case, Vec<[f32; 4]>, Vec<[f32; 4]>);

fn cases() -> Vec<Fixture> {
    let expected: Expected = serde_json::from_slice(&std::fs::read(data("expected.json")).unwrap()).unwrap();
    assert_eq!(expected.cases.len(), 6);
    expected
        .cases
        .into_iter()
        .map(|c| {
            let test = load(&c.test, c.width, c.height);
            let reference = load(&c.reference, c.width, c.height);
            (c, test, reference)
        })
        .collect()
}

fn constant(v: [f32; 3], width: u32, height: u32) -> Vec<[f32; 4]> {
    vec![[v[0], v[1], v[2], 1.0]; (width * height) as usize]
}

/// A deterministic structured image (no RNG crate needed).
fn pattern(width: u32, height: u32, phase: f32) -> Vec<[f32; 4]> {
    (0..height)
        .flat_map(|y| {
            (0..width).map(move |x| {
                let (x, y) = (x as f32, y as f32);
                [
                    x / width as f32,
                    0.5 + 0.45 * (0.7 * x + phase).sin() * (0.3 * y).cos(),
                    ((x * 7.0 + y * 13.0 + phase) % 17.0) / 17.0,
                    1.0,
                ]
            })
        })
        .collect()
}

/// MSSIM against the Python values. The fixtures' own `mssim` comes from a float64 transcription of `ssim_index.m`
/// ('valid' filtering, no padding) and `mssim_skimage` from scikit-image's `structural_similarity`, whose reflect
/// padding is cropped away; the generator already checked that the two agree to 1e-12.
#[test]
fn mssim_matches_wang_2004_fixtures() {
    for (c, test, reference) in cases() {
        let got = metrics::mssim(&test, &reference, c.width, c.height).unwrap();
        eprintln!("{} vs {}: mssim {got:.15} expected {:.15}", c.test, c.reference, c.mssim);
        assert!((got - c.mssim).abs() < 1e-5, "{}: {got} vs {}", c.test, c.mssim);
        assert!((got - c.mssim_skimage).abs() < 1e-5, "{}: {got} vs skimage {}", c.test, c.mssim_skimage);
        // The agreement is in fact to rounding: same definition, both in f64.
        assert!((got - c.mssim).abs() < 1e-12, "{}: {got} vs {}", c.test, c.mssim);

        let map = metrics::ssim_map(&test, &reference, c.width, c.height).unwrap();
        assert_eq!((map.width, map.height), (c.width - 10, c.height - 10));
        assert_eq!(map.values.len(), ((c.width - 10) * (c.height - 10)) as usize);
        assert_eq!(map.mean, got);
        assert!(map.values.iter().all(|v| (-1.0..=1.0).contains(v)));
    }
}

#[test]
fn rmse_and_psnr_match_fixtures() {
    for (c, test, reference) in cases() {
        let rmse = metrics::rmse(&test, &reference, c.width, c.height).unwrap();
        let psnr = metrics::psnr(&test, &reference, c.width, c.height).unwrap();
        assert!((rmse - c.rmse).abs() < 1e-12, "{}: {rmse} vs {}", c.test, c.rmse);
        assert!((psnr - c.psnr).abs() < 1e-9, "{}: {psnr} vs {}", c.test, c.psnr);
    }
}

/// FLIP means pinned to NVIDIA's own implementation (`flip_evaluator` 1.7, the C++ code behind a Python binding),
/// run once by `gen_fixtures.py` on the same sRGB 8-bit quantisation. `flip-rs` reproduces that code's arithmetic
/// (the six means agree to all 9 printed decimals); the tolerance of 1e-5 leaves room for `f32` pooling order in
/// other versions but would catch a different colour conversion, PPD or argument order, which move the mean by far
/// more.
#[test]
fn flip_matches_nvidia_fixtures() {
    for (c, test, reference) in cases() {
        let map = metrics::flip(&test, &reference, c.width, c.height).unwrap();
        eprintln!("{} vs {}: flip {:.9} expected {:.9}", c.test, c.reference, map.mean, c.flip_mean);
        assert!((f64::from(map.mean) - c.flip_mean).abs() < 1e-5, "{}: {} vs {}", c.test, map.mean, c.flip_mean);
        assert_eq!((map.width, map.height), (c.width, c.height));
        assert_eq!(map.values.len(), (c.width * c.height) as usize);
        assert!(map.values.iter().all(|v| (0.0..=1.0).contains(v)));
        // A visible but moderate difference: well inside (0, 1).
        assert!(map.mean > 0.01 && map.mean < 0.5, "{}: {}", c.test, map.mean);
        let heatmap = map.to_rgba8();
        assert_eq!(heatmap.len(), 4 * map.values.len());
    }
}

/// A value computed once with this crate and pinned, for a case with no Python fixture: a 40x30 pattern against
/// the same pattern shifted in phase. Tolerance 1e-6: FLIP is deterministic (single-threaded, f32 arithmetic in a
/// fixed order), so only a change of `flip-rs` version, PPD or sRGB conversion should move it.
#[test]
fn flip_pinned_value() {
    let (w, h) = (40, 30);
    let map = metrics::flip(&pattern(w, h, 0.5), &pattern(w, h, 0.0), w, h).unwrap();
    const PINNED: f32 = 0.307_456_52;
    eprintln!("pinned flip: {:.9}", map.mean);
    assert!((map.mean - PINNED).abs() < 1e-6, "{} vs {PINNED}", map.mean);
}

#[test]
fn identical_images() {
    let (w, h) = (37, 23);
    let img = pattern(w, h, 0.0);
    let m = metrics::compare(&img, &img, w, h).unwrap();
    assert_eq!(m, Metrics { rmse: 0.0, psnr: f64::INFINITY, mssim: 1.0, flip: 0.0 });
    let map = metrics::flip(&img, &img, w, h).unwrap();
    assert!(map.values.iter().all(|&v| v == 0.0));
    // Alpha is ignored.
    let other_alpha: Vec<_> = img.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
    assert_eq!(metrics::compare(&other_alpha, &img, w, h).unwrap(), m);
    // Identical images serialise with a `null` PSNR (serde_json's rendering of infinity).
    let json = serde_json::to_value(m).unwrap();
    assert_eq!(json, serde_json::json!({ "rmse": 0.0, "psnr": null, "mssim": 1.0, "flip": 0.0 }));
}

#[test]
fn mssim_is_symmetric() {
    let (w, h) = (29, 17);
    let (a, b) = (pattern(w, h, 0.0), pattern(w, h, 1.3));
    let ab = metrics::mssim(&a, &b, w, h).unwrap();
    let ba = metrics::mssim(&b, &a, w, h).unwrap();
    assert_eq!(ab, ba);
    assert!(ab < 1.0 && ab > -1.0);
    for (c, test, reference) in cases() {
        let ab = metrics::mssim(&test, &reference, c.width, c.height).unwrap();
        assert_eq!(ab, metrics::mssim(&reference, &test, c.width, c.height).unwrap());
    }
}

/// For constant images x = a and y = b every window has zero variance and covariance, so SSIM is the luminance term
/// alone: (2ab + C1) / (a^2 + b^2 + C1), with C1 = 0.01^2; the map is that value everywhere.
#[test]
fn mssim_of_constant_images_has_closed_form() {
    let c1 = 0.0001;
    let (w, h) = (11, 14);
    for (a, b) in [(0.2f32, 0.2f32), (0.0, 0.0), (0.0, 1.0), (0.5, 0.25), (0.9, 0.1), (0.02, 0.01)] {
        let (x, y) = (constant([a; 3], w, h), constant([b; 3], w, h));
        let (a, b) = (f64::from(a), f64::from(b));
        let expected = (2.0 * a * b + c1) / (a * a + b * b + c1);
        let map = metrics::ssim_map(&x, &y, w, h).unwrap();
        assert_eq!((map.width, map.height), (1, 4));
        for v in &map.values {
            assert!((v - expected).abs() < 1e-12, "{a} {b}: {v} vs {expected}");
        }
        assert!((map.mean - expected).abs() < 1e-12);
    }
    // Luminance of a grey is the grey itself (the weights sum to 1); channels are clamped first.
    assert!((metrics::luminance([0.3, 0.3, 0.3, 0.0]) - f64::from(0.3f32)).abs() < 1e-15);
    assert_eq!(metrics::luminance([2.0, -1.0, 5.0, 1.0]), 0.2126 + 0.0722);
    let (x, y) = (constant([3.0, 1.5, 9.0], w, h), constant([1.0; 3], w, h));
    assert_eq!(metrics::mssim(&x, &y, w, h).unwrap(), 1.0);
}

/// Equal means, structure only: y = 1 - x on a zero-mean-in-window pattern gives negative SSIM.
#[test]
fn mssim_of_inverted_pattern_is_negative() {
    let (w, h) = (24, 24);
    let x: Vec<f64> = (0..w * h).map(|i| if (i % w + i / w) % 2 == 0 { 0.8 } else { 0.2 }).collect();
    let y: Vec<f64> = x.iter().map(|v| 1.0 - v).collect();
    let m = metrics::mssim_plane(&y, &x, w, h).unwrap();
    assert!(m < -0.9, "{m}");
    assert_eq!(metrics::mssim_plane(&x, &x, w, h).unwrap(), 1.0);
}

#[test]
fn rmse_psnr_closed_forms() {
    let (w, h) = (8, 5);
    let x = constant([0.25, 0.5, 0.75], w, h);
    // Offset by 0.1 in every channel, even past 1 (values as given, not clamped).
    let y = constant([0.35, 0.6, 0.85], w, h);
    let rmse = metrics::rmse(&y, &x, w, h).unwrap();
    assert!((rmse - 0.1).abs() < 1e-7, "{rmse}");
    assert!((metrics::psnr(&y, &x, w, h).unwrap() - 20.0).abs() < 1e-5);
    let hdr = constant([4.0, 0.5, 0.75], w, h);
    let rmse = metrics::rmse(&hdr, &x, w, h).unwrap();
    assert!((rmse - (3.75f64 * 3.75 / 3.0).sqrt()).abs() < 1e-12, "{rmse}");
    // One channel off by 1 in one pixel of 40.
    let mut z = x.clone();
    z[7][1] += 1.0;
    let expected = (1.0f64 / 120.0).sqrt();
    assert!((metrics::rmse(&z, &x, w, h).unwrap() - expected).abs() < 1e-12);
    assert!((metrics::psnr(&z, &x, w, h).unwrap() - 10.0 * 120f64.log10()).abs() < 1e-9);
    assert_eq!(metrics::psnr_from_rmse(0.0), f64::INFINITY);
    assert!((metrics::psnr_from_rmse(0.01) - 40.0).abs() < 1e-12);
}

#[test]
fn srgb_encoding() {
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(0.0), 0);
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(-3.0), 0);
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(1.0), 255);
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(7.0), 255);
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(0.5), 188); // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(0.18), 118); // middle grey
    assert_eq!(mrsl_lab::color::linear_to_srgb8_f64(0.002), 7); // linear segment: 12.92 * 0.002 * 255 = 6.59
}

/// Values chosen so that no Magma index falls on a rounding boundary.
#[test]
fn error_image_colour_maps_scaled_difference() {
    let (w, h) = (4, 2);
    let x = constant([0.5; 3], w, h);
    let mut y = x.clone();
    y[1] = [0.6, 0.6, 0.6, 0.0]; // mean |d| 0.1: saturates at scale 10
    y[2] = [0.56, 0.5, 0.5, 1.0]; // mean |d| 0.02: index round(0.2 * 255) = 51
    y[3] = [0.4, 0.6, 0.5, 1.0]; // signs do not cancel: mean |d| 0.2 / 3, index 170
    let img = metrics::error_image(&y, &x, w, h, metrics::DEFAULT_ERROR_SCALE).unwrap();
    assert_eq!(img.len(), 4 * 8);
    let px = |i: usize| &img[4 * i..4 * i + 4];
    let magma = |i: usize| {
        let [r, g, b] = flip_rs::MAGMA[i].map(|c| (c * 255.0 + 0.5) as u8);
        [r, g, b, 255]
    };
    assert_eq!(px(0), magma(0));
    assert_eq!(px(1), magma(255));
    assert_eq!(px(2), magma(51));
    assert_eq!(px(3), magma(170));
    assert!(img.chunks_exact(4).all(|p| p[3] == 255));
    // Darkest for no error, brightest for saturated error.
    let sum = |p: &[u8]| p[..3].iter().map(|&v| u32::from(v)).sum::<u32>();
    assert!(sum(px(0)) < sum(px(2)) && sum(px(2)) < sum(px(3)) && sum(px(3)) < sum(px(1)));
    // Scale 2: the 0.1 difference lands a fifth of the way up.
    let img = metrics::error_image(&y, &x, w, h, 2.0).unwrap();
    assert_eq!(&img[4..8], magma(51));
    for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(metrics::error_image(&y, &x, w, h, bad), Err(MetricsError::InvalidScale(_))));
    }
    // The FLIP heatmap uses the same table.
    let map = metrics::FlipMap { width: 2, height: 1, values: vec![0.0, 1.0], mean: 0.5 };
    assert_eq!(map.to_rgba8(), [magma(0), magma(255)].concat());
}

#[test]
fn errors_instead_of_panics() {
    let (w, h) = (12, 12);
    let x = constant([0.5; 3], w, h);
    let short = constant([0.5; 3], w, h - 1);
    let err = metrics::compare(&short, &x, w, h).unwrap_err();
    assert_eq!(err, MetricsError::LengthMismatch { image: "test", width: 12, height: 12, expected: 144, found: 132 });
    assert!(matches!(metrics::rmse(&x, &short, w, h), Err(MetricsError::LengthMismatch { image: "reference", .. })));
    assert!(matches!(metrics::flip(&x, &short, w, h), Err(MetricsError::LengthMismatch { .. })));
    assert!(matches!(metrics::error_image(&x, &short, w, h, 10.0), Err(MetricsError::LengthMismatch { .. })));
    assert!(matches!(metrics::mssim(&x, &x, 13, 12), Err(MetricsError::LengthMismatch { .. })));

    assert_eq!(metrics::rmse(&[], &[], 0, 5), Err(MetricsError::InvalidSize { width: 0, height: 5 }));
    assert!(matches!(metrics::compare(&[], &[], 3, 0), Err(MetricsError::InvalidSize { .. })));

    let mut nan = x.clone();
    nan[13][2] = f32::NAN;
    assert_eq!(
        metrics::compare(&x, &nan, w, h).unwrap_err(),
        MetricsError::NonFinite { image: "reference", index: 13, x: 1, y: 1 }
    );
    let mut inf = x.clone();
    inf[0][0] = f32::INFINITY;
    assert!(matches!(metrics::psnr(&inf, &x, w, h), Err(MetricsError::NonFinite { image: "test", index: 0, .. })));
    // A NaN in alpha is ignored like the rest of alpha.
    let mut alpha = x.clone();
    alpha[5][3] = f32::NAN;
    assert_eq!(metrics::compare(&alpha, &x, w, h).unwrap().mssim, 1.0);

    // Below the 11x11 window: SSIM and compare refuse, the rest still work.
    for (w, h) in [(10, 40), (40, 10), (1, 1)] {
        let (a, b) = (pattern(w, h, 0.0), pattern(w, h, 1.0));
        let too_small = MetricsError::TooSmallForSsim { width: w, height: h };
        assert_eq!(metrics::mssim(&a, &b, w, h), Err(too_small.clone()));
        assert_eq!(metrics::ssim_map(&a, &b, w, h), Err(too_small.clone()));
        assert_eq!(metrics::compare(&a, &b, w, h), Err(too_small));
        assert!(metrics::rmse(&a, &b, w, h).unwrap() > 0.0);
        assert!(metrics::flip(&a, &b, w, h).unwrap().mean >= 0.0);
    }
    let exactly = pattern(11, 11, 0.0);
    assert_eq!(metrics::ssim_map(&exactly, &exactly, 11, 11).unwrap().values, vec![1.0]);

    let plane = vec![0.5; 144];
    assert!(matches!(metrics::mssim_plane(&plane, &plane[1..], w, h), Err(MetricsError::LengthMismatch { .. })));
    let mut bad = plane.clone();
    bad[143] = f64::NAN;
    assert!(matches!(metrics::mssim_plane(&plane, &bad, w, h), Err(MetricsError::NonFinite { x: 11, y: 11, .. })));

    // Messages name the problem.
    assert_eq!(
        MetricsError::TooSmallForSsim { width: 8, height: 8 }.to_string(),
        "SSIM needs images of at least 11x11 pixels (its window), got 8x8"
    );
}

#[test]
fn compare_agrees_with_parts() {
    for (c, test, reference) in cases() {
        let m = metrics::compare(&test, &reference, c.width, c.height).unwrap();
        assert_eq!(m.rmse, metrics::rmse(&test, &reference, c.width, c.height).unwrap());
        assert_eq!(m.psnr, metrics::psnr(&test, &reference, c.width, c.height).unwrap());
        assert_eq!(m.mssim, metrics::mssim(&test, &reference, c.width, c.height).unwrap());
        assert_eq!(m.flip, f64::from(metrics::flip(&test, &reference, c.width, c.height).unwrap().mean));
        let json = serde_json::to_value(m).unwrap();
        assert_eq!(json["mssim"].as_f64(), Some(m.mssim));
    }
}
