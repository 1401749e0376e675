//! What the rate source is asked to do: VALAR's presets and constants, the
//! combiners and the foveation source, the options and inputs of one rate
//! computation, and VALAR's frame-budget rule for the sensitivity.

use crate::Error;
use crate::controller::{Target, ThresholdController};
use mrsl_abi::shading_rate::{DEFAULT_RATE_TILE, RATE_TILE_SIZES, ShadingRate};

/// VALAR's quarter-rate sensitivity K (NAS's fitted ratio of quarter- to half-rate error).
pub const DEFAULT_K: f32 = 2.13;
/// VALAR's environment luminance l_env (Eq. 15).
pub const DEFAULT_ENV_LUMA: f32 = 0.05;
/// VALAR's Weber–Fechner constant (the brightness sensitivity's scale).
pub const DEFAULT_WEBER_FECHNER_CONSTANT: f32 = 1.0;
/// The smallest Weber–Fechner divisor (`WEBER_FLOOR` in rate_source.wgsl):
/// keeps a zero constant over black pixels finite.
pub const WEBER_FLOOR: f32 = 1.0e-4;

/// The range a [`ThresholdController`] keeps the sensitivity t in: from
/// far finer than Quality to well past Performance (at t = 4 only tiles whose
/// error exceeds four times the JND threshold keep full rate).
pub const SENSITIVITY_RANGE: (f64, f64) = (0.01, 4.0);

/// VALAR's sensitivity presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// t = 0.25.
    Quality,
    /// t = 0.5.
    Balanced,
    /// t = 0.75.
    Performance,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Quality, Preset::Balanced, Preset::Performance];

    /// The sensitivity threshold t.
    pub fn sensitivity(self) -> f32 {
        match self {
            Preset::Quality => 0.25,
            Preset::Balanced => 0.5,
            Preset::Performance => 0.75,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Preset::Quality => "quality",
            Preset::Balanced => "balanced",
            Preset::Performance => "performance",
        }
    }
}

/// How a second rate (an engine's rate image, the foveation source) combines
/// with the rate computed so far, per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Combiner {
    /// The finer of the two on each axis.
    Min,
    /// The coarser of the two on each axis.
    Max,
    /// The second rate wins.
    Override,
}

impl Combiner {
    pub const ALL: [Combiner; 3] = [Combiner::Min, Combiner::Max, Combiner::Override];

    /// The combiner's code in `Params::combiners`.
    pub(super) fn code(self) -> u32 {
        match self {
            Combiner::Min => 0,
            Combiner::Max => 1,
            Combiner::Override => 2,
        }
    }

    /// The shader's name for [`Combiner::code`].
    pub(super) fn wgsl_name(self) -> &'static str {
        match self {
            Combiner::Min => "COMBINE_MIN",
            Combiner::Max => "COMBINE_MAX",
            Combiner::Override => "COMBINE_OVERRIDE",
        }
    }

    /// The combined rate, as the GPU computes it (4x1 and 1x4 clamped, as
    /// [`ShadingRate::clamp_size`]).
    pub fn apply(self, current: ShadingRate, other: ShadingRate) -> ShadingRate {
        match self {
            Combiner::Min => current.finer(other),
            Combiner::Max => current.coarser(other),
            Combiner::Override => other,
        }
    }
}

/// The built-in foveation source: full rate around the gaze, coarser with
/// distance. A tile's distance is that of its point nearest to the gaze.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foveation {
    /// The gaze point in pixels (x right, y down).
    pub gaze: [f32; 2],
    /// Tiles within this distance (pixels) are 1x1.
    pub inner_radius: f32,
    /// Tiles within this distance (and beyond the inner radius) are 2x2; farther ones 4x4.
    pub outer_radius: f32,
    /// How the foveation rate combines with the content-adaptive one.
    pub combiner: Combiner,
}

impl Foveation {
    /// The foveation rate of the tile of `tile` pixels per side at tile
    /// coordinates `(tx, ty)` of an image of `size` pixels (what the GPU computes).
    pub fn rate(&self, size: (u32, u32), tile: u32, (tx, ty): (u32, u32)) -> ShadingRate {
        let lo = [(tx * tile) as f32, (ty * tile) as f32];
        let hi = [((tx + 1) * tile).min(size.0) as f32, ((ty + 1) * tile).min(size.1) as f32];
        let nearest = [self.gaze[0].clamp(lo[0], hi[0]), self.gaze[1].clamp(lo[1], hi[1])];
        let d = ((nearest[0] - self.gaze[0]).powi(2) + (nearest[1] - self.gaze[1]).powi(2)).sqrt();
        if d <= self.inner_radius {
            ShadingRate::R1x1
        } else if d <= self.outer_radius {
            ShadingRate::R2x2
        } else {
            ShadingRate::R4x4
        }
    }
}

/// The rate source's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateOptions {
    /// Pixels per tile side: one of [`RATE_TILE_SIZES`] (8 or 16).
    pub tile: u32,
    /// The sensitivity threshold t of the JND threshold τ = t · (L̄ + l_env)
    /// (Eq. 15); larger is coarser. See [`Preset`].
    pub sensitivity: f32,
    /// K, the quarter-rate error's factor over the half-rate one (Eq. 14, 21);
    /// lower keeps more tiles from 4x.
    pub k: f32,
    /// l_env, the environment luminance added to the tile's mean (Eq. 15).
    pub env_luma: f32,
    /// Weber–Fechner differences instead of Eq. 2's |ΔL| / 2.
    pub weber_fechner: bool,
    /// The Weber–Fechner brightness sensitivity's scale.
    pub weber_fechner_constant: f32,
    /// Lower rates where the tile moves (Eq. 20, 21, from the tile's minimum
    /// speed): needs [`RateInputs::velocity`].
    pub motion: bool,
    /// Reproject the decisions along the motion vectors when they are given.
    pub reproject: bool,
    /// Temporal damping: a tile coarsens only when its last three decisions agree.
    pub hysteresis: bool,
    /// The built-in foveation source, if any.
    pub foveation: Option<Foveation>,
}

impl RateOptions {
    /// VALAR's defaults at a preset's sensitivity: 8x8 tiles, K = 2.13,
    /// l_env = 0.05, approximate differences, no motion terms, reprojection
    /// and hysteresis on.
    pub fn preset(preset: Preset) -> RateOptions {
        RateOptions {
            tile: DEFAULT_RATE_TILE,
            sensitivity: preset.sensitivity(),
            k: DEFAULT_K,
            env_luma: DEFAULT_ENV_LUMA,
            weber_fechner: false,
            weber_fechner_constant: DEFAULT_WEBER_FECHNER_CONSTANT,
            motion: false,
            reproject: true,
            hysteresis: true,
            foveation: None,
        }
    }

    pub(super) fn validate(&self) -> Result<(), Error> {
        if !RATE_TILE_SIZES.contains(&self.tile) {
            return Err(Error::BadTileSize(self.tile));
        }
        let mut values = vec![
            ("sensitivity", self.sensitivity),
            ("k", self.k),
            ("env_luma", self.env_luma),
            ("weber_fechner_constant", self.weber_fechner_constant),
        ];
        if let Some(f) = &self.foveation {
            values.extend([
                ("foveation.gaze[0]", f.gaze[0]),
                ("foveation.gaze[1]", f.gaze[1]),
                ("foveation.inner_radius", f.inner_radius),
                ("foveation.outer_radius", f.outer_radius),
            ]);
        }
        for (name, value) in values {
            // A gaze may lie off screen (negative), but must be a number.
            let negative_ok = name.starts_with("foveation.gaze");
            if !value.is_finite() || (value < 0.0 && !negative_ok) {
                return Err(Error::BadRateOption { name, value });
            }
        }
        Ok(())
    }
}

impl Default for RateOptions {
    /// [`Preset::Balanced`].
    fn default() -> RateOptions {
        RateOptions::preset(Preset::Balanced)
    }
}

/// An engine's own rate image and how it combines with the computed rates.
#[derive(Debug, Clone, Copy)]
pub struct ExternalRates<'a> {
    /// One texel per tile, D3D12/Vulkan codes, `R8Uint` (or `R16Uint`,
    /// `R32Uint`), created with `TEXTURE_BINDING`. Codes outside the seven
    /// are clamped per axis (3 reads as 4x) and 4x1/1x4 become 2x1/1x2.
    pub texture: &'a wgpu::Texture,
    pub combiner: Combiner,
}

/// What one rate computation reads.
#[derive(Debug, Clone, Copy)]
pub struct RateInputs<'a> {
    /// The previous frame's output, with `TEXTURE_BINDING`; its size is the
    /// image size. Linear RGB in `Rgba32Float` or `Rgba16Float` (luminance:
    /// Rec.709), or a one- or two-channel float output (`R32Float`,
    /// `R16Float`: the value; `Rg32Float`, `Rg16Float`: the mean of the two).
    pub color: &'a wgpu::Texture,
    /// Motion vectors of that frame: current minus previous position in
    /// pixels, `Rg16Float` or `Rg32Float` (or the RGBA float formats: x and
    /// y are read), the colour's size.
    pub velocity: Option<&'a wgpu::Texture>,
    /// An engine's rate image, combined last.
    pub external: Option<ExternalRates<'a>>,
}

impl<'a> RateInputs<'a> {
    pub fn new(color: &'a wgpu::Texture) -> RateInputs<'a> {
        RateInputs { color, velocity: None, external: None }
    }
}

/// VALAR's dynamic threshold: t = GPU time / (1000 / FPS target), the
/// fraction of the frame budget the GPU took, clamped to [0, 1] (VALAR's
/// slider range). `None` for a non-finite or negative time or a target that
/// is not a positive frame rate.
pub fn valar_sensitivity(gpu_time_ms: f64, fps_target: f64) -> Option<f64> {
    let valid = gpu_time_ms.is_finite() && gpu_time_ms >= 0.0 && fps_target.is_finite() && fps_target > 0.0;
    valid.then(|| (gpu_time_ms / (1000.0 / fps_target)).clamp(0.0, 1.0))
}

/// A [`ThresholdController`] whose knob is the sensitivity t (within
/// [`SENSITIVITY_RANGE`]), starting at `initial`: the shaded fraction and the
/// pass time both fall as t rises, as the controller assumes. Measure the
/// fraction of a frame's rates with [`rate_fraction`] and set
/// [`RateOptions::sensitivity`] to `threshold()` each frame.
pub fn sensitivity_controller(target: Target, initial: f32) -> ThresholdController {
    ThresholdController::new(target, f64::from(initial), SENSITIVITY_RANGE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valars() {
        let t: Vec<f32> = Preset::ALL.iter().map(|p| p.sensitivity()).collect();
        assert_eq!(t, [0.25, 0.5, 0.75]);
        let o = RateOptions::default();
        assert_eq!((o.tile, o.sensitivity, o.k, o.env_luma, o.weber_fechner_constant), (8, 0.5, 2.13, 0.05, 1.0));
    }

    #[test]
    fn budget_rule_is_valars() {
        // 10 ms of a 30 FPS budget (33.3 ms) is t = 0.3.
        assert!((valar_sensitivity(10.0, 30.0).unwrap() - 0.3).abs() < 1e-12);
        assert_eq!(valar_sensitivity(50.0, 30.0), Some(1.0));
        assert_eq!(valar_sensitivity(0.0, 60.0), Some(0.0));
        assert_eq!(valar_sensitivity(5.0, 0.0), None);
        assert_eq!(valar_sensitivity(f64::NAN, 60.0), None);
        assert_eq!(valar_sensitivity(-1.0, 60.0), None);
    }

    #[test]
    fn options_are_validated_without_panicking() {
        let bad = |o: RateOptions| o.validate().unwrap_err();
        assert_eq!(bad(RateOptions { tile: 4, ..Default::default() }), Error::BadTileSize(4));
        assert!(matches!(
            bad(RateOptions { sensitivity: f32::NAN, ..Default::default() }),
            Error::BadRateOption { name: "sensitivity", .. }
        ));
        assert_eq!(bad(RateOptions { k: -1.0, ..Default::default() }), Error::BadRateOption { name: "k", value: -1.0 });
        let fovea =
            Foveation { gaze: [-5.0, 3.0], inner_radius: 1.0, outer_radius: f32::INFINITY, combiner: Combiner::Min };
        assert_eq!(
            bad(RateOptions { foveation: Some(fovea), ..Default::default() }),
            Error::BadRateOption { name: "foveation.outer_radius", value: f32::INFINITY }
        );
        let fovea = Foveation { outer_radius: 2.0, ..fovea };
        assert_eq!(RateOptions { foveation: Some(fovea), tile: 16, ..Default::default() }.validate(), Ok(()));
    }

    #[test]
    fn foveation_rings_are_measured_from_the_nearest_point_of_a_tile() {
        let f = Foveation { gaze: [20.0, 20.0], inner_radius: 4.0, outer_radius: 12.0, combiner: Combiner::Override };
        // The gaze's own tile, a tile whose edge lies 4 px away, then 12 and 20 px.
        assert_eq!(f.rate((64, 64), 8, (2, 2)), ShadingRate::R1x1);
        assert_eq!(f.rate((64, 64), 8, (3, 2)), ShadingRate::R1x1);
        assert_eq!(f.rate((64, 64), 8, (4, 2)), ShadingRate::R2x2);
        assert_eq!(f.rate((64, 64), 8, (5, 2)), ShadingRate::R4x4);
    }

    #[test]
    fn combiners_are_those_of_the_abi() {
        use ShadingRate::*;
        assert_eq!(Combiner::Min.apply(R4x2, R2x4), R2x2);
        assert_eq!(Combiner::Max.apply(R4x2, R1x2), R4x2);
        assert_eq!(Combiner::Override.apply(R4x4, R1x2), R1x2);
    }
}
