//! Image-quality metrics: RMSE, PSNR, MSSIM and FLIP of a test image against a reference, and a colour-mapped error image.
//!
//! # Inputs
//!
//! Every function takes the **test** image first and the **reference** second, as `&[[f32; 4]]`: linear RGB plus
//! alpha, row-major, top row first, `width * height` pixels (the layout [`crate::gpu::Gpu::read_rgba32f`] returns).
//! Alpha is ignored everywhere. Both images share one `width` and `height`; nothing panics on bad input, every entry
//! point validates it first and returns a [`MetricsError`]:
//!
//! * [`MetricsError::InvalidSize`] for a zero width or height (or a pixel count that does not fit in `usize`);
//! * [`MetricsError::LengthMismatch`] when either slice does not hold exactly `width * height` pixels, which is
//!   also how two images of different sizes show up;
//! * [`MetricsError::NonFinite`] for a NaN or infinite R, G or B value: a metric that silently absorbed a NaN from a
//!   broken shader would hide the bug, so it is reported with the pixel's index instead;
//! * [`MetricsError::TooSmallForSsim`] from the SSIM functions (and [`compare`]) for images narrower or lower than
//!   the 11-pixel window; see below.
//!
//! # RMSE and PSNR
//!
//! [`rmse`] is the root of the mean squared difference over the R, G and B channels of all pixels (`3 * width *
//! height` terms), on the values as given: neither clamped nor encoded, so HDR values count at full weight. [`psnr`]
//! is `10 log10(peak^2 / MSE)` with peak 1.0 (the top of the LDR range), i.e. `-20 log10(rmse)`. For identical
//! images the MSE is 0 and the PSNR is reported as `f64::INFINITY`; note that `serde_json` writes a non-finite
//! float as `null`, so a serialised [`Metrics`] of two identical images has `"psnr": null`.
//!
//! # MSSIM
//!
//! [`mssim`] is the mean structural similarity exactly as Wang, Bovik, Sheikh and Simoncelli, "Image quality
//! assessment: from error visibility to structural similarity", IEEE TIP 13(4), 2004, and their reference
//! implementation `ssim_index.m` define it:
//!
//! * it is computed on one channel, the relative luminance `Y = 0.2126 R + 0.7152 G + 0.0722 B` (Rec. 709 / sRGB
//!   primaries) of the **linear** values, each channel first clamped to `[0, 1]` so that the dynamic range is exactly
//!   `L = 1` ([`luminance`]). This is linear-light luminance, not gamma-encoded luma: all metrics here but FLIP see
//!   the same linear signal. [`mssim_plane`] accepts any other single-channel plane (e.g. sRGB-encoded luma);
//! * the window is the 11x11 Gaussian with sigma 1.5, normalised to sum 1 (`fspecial('gaussian', 11, 1.5)`),
//!   applied separably as two 11-tap passes (the 2D window is the outer product of the normalised 1D one, so this
//!   is the same filter);
//! * `K1 = 0.01`, `K2 = 0.03`, `L = 1`, `C1 = (K1 L)^2`, `C2 = (K2 L)^2`; variances and the covariance are the
//!   window-weighted population moments (`filter(x*x) - mu_x^2`, no `N/(N-1)` correction);
//! * filtering is MATLAB's `filter2(..., 'valid')`: no padding, so the SSIM map has `(width-10) x (height-10)`
//!   entries, one per window that lies entirely inside the image ([`ssim_map`]), and MSSIM is their plain mean;
//! * there is no automatic downsampling (Wang's later `ssim.m` downsamples by `round(min(W, H) / 256)`;
//!   `ssim_index.m`, the 2004 reference, does not).
//!
//! Images smaller than 11x11 in either dimension have no valid window. `ssim_index.m` returns `-Inf` there; this
//! module returns [`MetricsError::TooSmallForSsim`] instead of shrinking the window, since a smaller window would
//! be a different metric. All arithmetic is in `f64`.
//!
//! It is hand-written because no crate was found that implements this definition faithfully: `dssim`, the best
//! known, is AGPL-licensed and computes a multi-scale variant in L\*a\*b\*, which gives different numbers.
//! `tests/metrics.rs` checks this one against values computed with scikit-image and with a direct transcription of
//! `ssim_index.m`, to within 1e-5.
//!
//! # FLIP
//!
//! [`flip`] is NVIDIA's LDR-FLIP (Andersson et al., HPG 2020; v1.7) through the `flip-rs` crate, a pure-Rust port
//! verified against NVIDIA's C++ code. LDR-FLIP expects sRGB-encoded 8-bit images, so both images are first
//! converted as a display would show them ([`linear_to_srgb8_f64`]: the PNGs' encoding, evaluated in `f64`): each
//! linear channel clamped to `[0, 1]`, encoded with the sRGB transfer function, and rounded to the nearest of 256
//! levels. Values above 1 therefore count as 1 (use HDR-FLIP for HDR comparisons; not exposed here). The viewing
//! condition is FLIP's default, [`DEFAULT_PPD`] (about 67 pixels per degree: a 0.7 m wide 3840-pixel monitor at
//! 0.7 m); [`flip_with_ppd`] takes another. The result is the per-pixel error map ([`FlipMap`], values in `[0, 1]`)
//! and its mean, pooled as FLIP's tool does (in `f32`). `flip-rs` is used without its `parallel` feature, so it
//! runs on one thread.
//!
//! # Error image
//!
//! [`error_image`] is a visualisation, not a metric: per pixel, the mean absolute difference over R, G and B (values
//! as given), multiplied by `scale` ([`DEFAULT_ERROR_SCALE`] = 10, so a difference of 0.1 saturates), clamped to
//! `[0, 1]` and mapped through the Magma colour map (black, purple, orange, pale yellow; the table FLIP's heatmaps
//! use). The result is RGBA8 bytes, sRGB-encoded, opaque, `4 * width * height` long, ready for a PNG encoder.
//! [`FlipMap::to_rgba8`] renders the FLIP error map with the same colour map, unscaled.
//!
//! # All at once
//!
//! [`compare`] validates once and returns a serialisable [`Metrics`] with RMSE, PSNR, MSSIM and mean FLIP.

use crate::color::linear_to_srgb8_f64;
use serde::Serialize;

/// FLIP's default viewing condition in pixels per degree (about 67.02).
pub const DEFAULT_PPD: f32 = flip_rs::DEFAULT_PPD;

/// The default gain of [`error_image`]: a mean absolute difference of 0.1 maps to the top of the colour map.
pub const DEFAULT_ERROR_SCALE: f32 = 10.0;

/// Side of the SSIM window.
pub const SSIM_WINDOW: usize = 11;
const SSIM_RADIUS: usize = SSIM_WINDOW / 2;
const SSIM_SIGMA: f64 = 1.5;
const SSIM_K1: f64 = 0.01;
const SSIM_K2: f64 = 0.03;
const SSIM_L: f64 = 1.0;

/// Why a comparison could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricsError {
    #[error("image size {width}x{height} is empty or too large")]
    InvalidSize { width: u32, height: u32 },
    #[error("the {image} image has {found} pixels, but {width}x{height} needs {expected}")]
    LengthMismatch { image: &'static str, width: u32, height: u32, expected: usize, found: usize },
    #[error("the {image} image has a non-finite value at pixel {index} (x {x}, y {y})")]
    NonFinite { image: &'static str, index: usize, x: u32, y: u32 },
    #[error("SSIM needs images of at least 11x11 pixels (its window), got {width}x{height}")]
    TooSmallForSsim { width: u32, height: u32 },
    #[error("error-image scale must be finite and positive, got {0}")]
    InvalidScale(f32),
    #[error("FLIP failed: {0}")]
    Flip(String),
}

/// All metrics of one comparison; see the module documentation for each definition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Metrics {
    /// Root mean squared difference over linear R, G, B.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB, peak 1.0; `f64::INFINITY` (JSON `null`) for identical images.
    pub psnr: f64,
    /// Mean SSIM (Wang et al. 2004) of the linear luminance.
    pub mssim: f64,
    /// Mean LDR-FLIP error of the sRGB 8-bit encodings, in `[0, 1]`.
    pub flip: f64,
}

/// Computes every metric of `test` against `reference`.
///
/// Fails like its parts: on invalid sizes, lengths or values, and with [`MetricsError::TooSmallForSsim`] for images
/// smaller than 11x11 (use [`rmse`], [`psnr`] and [`flip`] separately for those).
pub fn compare(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<Metrics, MetricsError> {
    compare_with_flip_map(test, reference, width, height).map(|(metrics, _)| metrics)
}

/// [`compare`], also returning the FLIP map (for its histogram and weighted quartiles).
pub fn compare_with_flip_map(
    test: &[[f32; 4]],
    reference: &[[f32; 4]],
    width: u32,
    height: u32,
) -> Result<(Metrics, FlipMap), MetricsError> {
    let pair = Pair::new(test, reference, width, height)?;
    let rmse = pair.rmse();
    let mssim = ssim_planes(&luminance_plane(pair.test), &luminance_plane(pair.reference), width, height, |_| {})?;
    let flip = pair.flip(DEFAULT_PPD)?;
    Ok((Metrics { rmse, psnr: psnr_from_rmse(rmse), mssim, flip: f64::from(flip.mean) }, flip))
}

/// Root mean squared difference over R, G and B, values as given.
pub fn rmse(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<f64, MetricsError> {
    Ok(Pair::new(test, reference, width, height)?.rmse())
}

/// PSNR in dB with peak 1.0; `f64::INFINITY` for identical images.
pub fn psnr(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<f64, MetricsError> {
    Ok(psnr_from_rmse(rmse(test, reference, width, height)?))
}

/// PSNR in dB (peak 1.0) of a given RMSE: `-20 log10(rmse)`, `f64::INFINITY` for 0.
pub fn psnr_from_rmse(rmse: f64) -> f64 {
    if rmse == 0.0 { f64::INFINITY } else { 10.0 * (1.0 / (rmse * rmse)).log10() }
}

/// The single channel SSIM is computed on: relative luminance of the linear RGB channels, each clamped to `[0, 1]`.
pub fn luminance(pixel: [f32; 4]) -> f64 {
    let c = |v: f32| f64::from(v.clamp(0.0, 1.0));
    0.2126 * c(pixel[0]) + 0.7152 * c(pixel[1]) + 0.0722 * c(pixel[2])
}

/// Mean SSIM of the [`luminance`] planes (Wang et al. 2004, `ssim_index.m`, `L = 1`).
pub fn mssim(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<f64, MetricsError> {
    let pair = Pair::new(test, reference, width, height)?;
    ssim_planes(&luminance_plane(pair.test), &luminance_plane(pair.reference), width, height, |_| {})
}

/// The SSIM map: one value per window position, `(width - 10) x (height - 10)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SsimMap {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first; entry `(x, y)` is the SSIM of the window whose top-left pixel is `(x, y)`.
    pub values: Vec<f64>,
    /// The mean of `values`: MSSIM.
    pub mean: f64,
}

/// The full SSIM map of the [`luminance`] planes, whose mean is [`mssim`].
pub fn ssim_map(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<SsimMap, MetricsError> {
    let pair = Pair::new(test, reference, width, height)?;
    ssim_map_planes(&luminance_plane(pair.test), &luminance_plane(pair.reference), width, height)
}

/// Mean SSIM of two single-channel planes (row-major, `width * height` values, dynamic range `L = 1`, used as given).
pub fn mssim_plane(test: &[f64], reference: &[f64], width: u32, height: u32) -> Result<f64, MetricsError> {
    let n = pixel_count(width, height)?;
    check_plane("test", test, n, width, height)?;
    check_plane("reference", reference, n, width, height)?;
    ssim_planes(test, reference, width, height, |_| {})
}

/// The SSIM map of two single-channel planes; see [`mssim_plane`].
pub fn ssim_map_plane(test: &[f64], reference: &[f64], width: u32, height: u32) -> Result<SsimMap, MetricsError> {
    let n = pixel_count(width, height)?;
    check_plane("test", test, n, width, height)?;
    check_plane("reference", reference, n, width, height)?;
    ssim_map_planes(test, reference, width, height)
}

/// A FLIP error map and its mean.
#[derive(Debug, Clone, PartialEq)]
pub struct FlipMap {
    pub width: u32,
    pub height: u32,
    /// One error per pixel in `[0, 1]`, row-major, top row first.
    pub values: Vec<f32>,
    /// The mean error, pooled in `f32` as NVIDIA's tool does.
    pub mean: f32,
}

impl FlipMap {
    /// The map through the Magma colour map, as opaque sRGB RGBA8 bytes (FLIP's own heatmap).
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.values.iter().flat_map(|&v| magma_rgba8(v)).collect()
    }

    /// How many pixels fall in each of `bins` equal bins over `[0, 1]` (the
    /// last bin includes 1): the histogram NVIDIA's FLIP tool and VALAR plot.
    pub fn histogram(&self, bins: usize) -> Vec<u64> {
        let mut counts = vec![0u64; bins.max(1)];
        for &v in &self.values {
            let bin = ((v.clamp(0.0, 1.0) * bins as f32) as usize).min(counts.len() - 1);
            counts[bin] += 1;
        }
        counts
    }

    /// The weighted quartiles of the errors, as FLIP's tool reports them
    /// (each pixel weighted by its own error, so the quartiles describe where
    /// the error mass lies rather than the many error-free pixels): the
    /// errors below which 25%, 50% and 75% of the summed error lies. All 0
    /// for identical images.
    pub fn weighted_quartiles(&self) -> [f32; 3] {
        let mut sorted: Vec<f32> = self.values.iter().copied().filter(|v| *v > 0.0).collect();
        sorted.sort_by(f32::total_cmp);
        let total: f64 = sorted.iter().map(|&v| f64::from(v)).sum();
        if total == 0.0 {
            return [0.0; 3];
        }
        let mut out = [0.0f32; 3];
        let mut sum = 0.0f64;
        let mut next = 0;
        for &v in &sorted {
            sum += f64::from(v);
            while next < 3 && sum >= total * (next as f64 + 1.0) / 4.0 {
                out[next] = v;
                next += 1;
            }
        }
        out
    }
}

/// LDR-FLIP of the sRGB 8-bit encodings of `test` and `reference` at [`DEFAULT_PPD`].
pub fn flip(test: &[[f32; 4]], reference: &[[f32; 4]], width: u32, height: u32) -> Result<FlipMap, MetricsError> {
    flip_with_ppd(test, reference, width, height, DEFAULT_PPD)
}

/// LDR-FLIP at `ppd` pixels per degree (see `flip_rs::pixels_per_degree`).
pub fn flip_with_ppd(
    test: &[[f32; 4]],
    reference: &[[f32; 4]],
    width: u32,
    height: u32,
    ppd: f32,
) -> Result<FlipMap, MetricsError> {
    Pair::new(test, reference, width, height)?.flip(ppd)
}

/// The colour-mapped error image: per pixel `clamp(scale * mean_c |test_c - reference_c|, 0, 1)` through Magma,
/// as opaque sRGB RGBA8 bytes (`4 * width * height`).
pub fn error_image(
    test: &[[f32; 4]],
    reference: &[[f32; 4]],
    width: u32,
    height: u32,
    scale: f32,
) -> Result<Vec<u8>, MetricsError> {
    if !scale.is_finite() || scale <= 0.0 {
        return Err(MetricsError::InvalidScale(scale));
    }
    let pair = Pair::new(test, reference, width, height)?;
    Ok(pair
        .test
        .iter()
        .zip(pair.reference)
        .flat_map(|(t, r)| {
            let diff = (0..3).map(|c| (f64::from(t[c]) - f64::from(r[c])).abs()).sum::<f64>() / 3.0;
            magma_rgba8((diff * f64::from(scale)) as f32)
        })
        .collect())
}

/// The Magma colour of `v` in [0, 1] (clamped) as opaque RGBA8: the colour
/// scale of [`error_image`] and [`FlipMap::to_rgba8`], for drawing their keys.
pub fn magma_rgba8(v: f32) -> [u8; 4] {
    // As flip_rs::ErrorMap::colorize: NaN clamps to NaN and `as usize` maps it to 0.
    let [r, g, b] = flip_rs::MAGMA[(v.clamp(0.0, 1.0) * 255.0 + 0.5) as usize];
    let byte = |c: f32| (c * 255.0 + 0.5) as u8;
    [byte(r), byte(g), byte(b), 255]
}

/// A validated test/reference pair.
struct Pair<'a> {
    test: &'a [[f32; 4]],
    reference: &'a [[f32; 4]],
    width: u32,
    height: u32,
}

impl<'a> Pair<'a> {
    fn new(test: &'a [[f32; 4]], reference: &'a [[f32; 4]], width: u32, height: u32) -> Result<Self, MetricsError> {
        let n = pixel_count(width, height)?;
        for (image, pixels) in [("test", test), ("reference", reference)] {
            if pixels.len() != n {
                return Err(MetricsError::LengthMismatch { image, width, height, expected: n, found: pixels.len() });
            }
            if let Some(index) = pixels.iter().position(|p| !p[..3].iter().all(|v| v.is_finite())) {
                return Err(non_finite(image, index, width));
            }
        }
        Ok(Pair { test, reference, width, height })
    }

    fn rmse(&self) -> f64 {
        let sum: f64 = self
            .test
            .iter()
            .zip(self.reference)
            .flat_map(|(t, r)| (0..3).map(move |c| (f64::from(t[c]) - f64::from(r[c])).powi(2)))
            .sum();
        (sum / (3 * self.test.len()) as f64).sqrt()
    }

    fn flip(&self, ppd: f32) -> Result<FlipMap, MetricsError> {
        let (w, h) = (self.width as usize, self.height as usize);
        let srgb8 = |pixels: &[[f32; 4]]| {
            let bytes = pixels.iter().flat_map(|p| [p[0], p[1], p[2]].map(linear_to_srgb8_f64)).collect();
            flip_rs::RgbImage::new(w, h, bytes).map_err(flip_error)
        };
        let map = flip_rs::ldr_flip(&srgb8(self.reference)?, &srgb8(self.test)?, ppd).map_err(flip_error)?;
        let mean = map.statistics().mean;
        Ok(FlipMap { width: self.width, height: self.height, values: map.into_pixels(), mean })
    }
}

fn luminance_plane(pixels: &[[f32; 4]]) -> Vec<f64> {
    pixels.iter().map(|&p| luminance(p)).collect()
}

fn flip_error(e: flip_rs::FlipError) -> MetricsError {
    MetricsError::Flip(e.to_string())
}

fn pixel_count(width: u32, height: u32) -> Result<usize, MetricsError> {
    (width as usize)
        .checked_mul(height as usize)
        .filter(|&n| n > 0 && n.checked_mul(std::mem::size_of::<[f32; 4]>()).is_some())
        .ok_or(MetricsError::InvalidSize { width, height })
}

fn non_finite(image: &'static str, index: usize, width: u32) -> MetricsError {
    let w = width as usize;
    MetricsError::NonFinite { image, index, x: (index % w) as u32, y: (index / w) as u32 }
}

fn check_plane(image: &'static str, plane: &[f64], n: usize, width: u32, height: u32) -> Result<(), MetricsError> {
    if plane.len() != n {
        return Err(MetricsError::LengthMismatch { image, width, height, expected: n, found: plane.len() });
    }
    match plane.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(non_finite(image, index, width)),
        None => Ok(()),
    }
}

fn ssim_map_planes(a: &[f64], b: &[f64], width: u32, height: u32) -> Result<SsimMap, MetricsError> {
    let mut values = Vec::new();
    let mean = ssim_planes(a, b, width, height, |row| values.extend_from_slice(row))?;
    let side = |s: u32| s - (SSIM_WINDOW as u32 - 1);
    Ok(SsimMap { width: side(width), height: side(height), values, mean })
}

/// The 1D window: Gaussian taps at offsets -5..=5 with sigma 1.5, normalised to sum 1. Its outer product with itself
/// is `fspecial('gaussian', 11, 1.5)` normalised to sum 1, as in `ssim_index.m`.
fn gaussian_window() -> [f64; SSIM_WINDOW] {
    let taps: [f64; SSIM_WINDOW] = std::array::from_fn(|i| {
        let x = i as f64 - SSIM_RADIUS as f64;
        (-(x * x) / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp()
    });
    let sum: f64 = taps.iter().sum();
    taps.map(|t| t / sum)
}

/// SSIM over validated planes `a` (test) and `b` (reference) of `width * height` values: hands each row of the
/// `(width-10) x (height-10)` SSIM map to `row` and returns the mean.
///
/// Separable 'valid' filtering: each input row is filtered horizontally once for the five moments (`a`, `b`, `a*a`,
/// `b*b`, `a*b`) into a ring of the last 11 rows; each output row is the vertical filter over that ring. Memory is
/// `O(11 * width)`; the formula and the order of operations on the filtered moments follow `ssim_index.m`.
fn ssim_planes(
    a: &[f64],
    b: &[f64],
    width: u32,
    height: u32,
    mut row: impl FnMut(&[f64]),
) -> Result<f64, MetricsError> {
    let (w, h) = (width as usize, height as usize);
    if w < SSIM_WINDOW || h < SSIM_WINDOW {
        return Err(MetricsError::TooSmallForSsim { width, height });
    }
    let g = gaussian_window();
    let c1 = (SSIM_K1 * SSIM_L).powi(2);
    let c2 = (SSIM_K2 * SSIM_L).powi(2);
    let (ow, oh) = (w - (SSIM_WINDOW - 1), h - (SSIM_WINDOW - 1));
    // ring[slot][x] holds the five horizontally filtered moments of input row `y` with `y % 11 == slot`.
    let mut ring = vec![[0.0f64; 5]; SSIM_WINDOW * ow];
    let filter_row = |y: usize, ring: &mut [[f64; 5]]| {
        let (ra, rb) = (&a[y * w..(y + 1) * w], &b[y * w..(y + 1) * w]);
        let slot = &mut ring[(y % SSIM_WINDOW) * ow..][..ow];
        for (x, out) in slot.iter_mut().enumerate() {
            let mut s = [0.0f64; 5];
            for (k, &gk) in g.iter().enumerate() {
                let (p, q) = (ra[x + k], rb[x + k]);
                s[0] += gk * p;
                s[1] += gk * q;
                s[2] += gk * (p * p);
                s[3] += gk * (q * q);
                s[4] += gk * (p * q);
            }
            *out = s;
        }
    };
    for y in 0..SSIM_WINDOW - 1 {
        filter_row(y, &mut ring);
    }
    let mut out = vec![0.0f64; ow];
    let mut sum = 0.0f64;
    for oy in 0..oh {
        filter_row(oy + SSIM_WINDOW - 1, &mut ring);
        let slots: [usize; SSIM_WINDOW] = std::array::from_fn(|k| ((oy + k) % SSIM_WINDOW) * ow);
        for (x, value) in out.iter_mut().enumerate() {
            let mut s = [0.0f64; 5];
            for (k, &gk) in g.iter().enumerate() {
                let m = ring[slots[k] + x];
                for (acc, v) in s.iter_mut().zip(m) {
                    *acc += gk * v;
                }
            }
            let [mu1, mu2, e11, e22, e12] = s;
            let (mu1_sq, mu2_sq, mu1_mu2) = (mu1 * mu1, mu2 * mu2, mu1 * mu2);
            let sigma1_sq = e11 - mu1_sq;
            let sigma2_sq = e22 - mu2_sq;
            let sigma12 = e12 - mu1_mu2;
            *value =
                ((2.0 * mu1_mu2 + c1) * (2.0 * sigma12 + c2)) / ((mu1_sq + mu2_sq + c1) * (sigma1_sq + sigma2_sq + c2));
        }
        sum += out.iter().sum::<f64>();
        row(&out);
    }
    Ok(sum / (ow * oh) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flip_histograms_and_weighted_quartiles() {
        let map = FlipMap { width: 4, height: 2, values: vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.2, 0.6], mean: 0.125 };
        assert_eq!(map.histogram(10), vec![4, 2, 1, 0, 0, 0, 1, 0, 0, 0]);
        // Summed error 1.0, sorted 0.1, 0.1, 0.2, 0.6: the running sums 0.1, 0.2, 0.4, 1.0 pass
        // a quarter at the 0.2 and half and three quarters at the 0.6, which holds most of it.
        assert_eq!(map.weighted_quartiles(), [0.2, 0.6, 0.6]);
        let zero = FlipMap { width: 1, height: 1, values: vec![0.0], mean: 0.0 };
        assert_eq!(zero.weighted_quartiles(), [0.0; 3]);
        assert_eq!(zero.histogram(4), vec![1, 0, 0, 0]);
    }
}
