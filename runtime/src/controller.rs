//! A frame-to-frame refinement-threshold controller: adjusts one threshold
//! (the hierarchical mode's `similarity`, or a program's tolerance uniform)
//! so that the measured shaded fraction or pass time approaches a target —
//! the dynamic threshold that the DACS and VALAR papers leave to future work.
//!
//! Both measures fall as the threshold rises, roughly as a power of it, so
//! the controller works in logarithms: each frame it estimates the local
//! slope d ln(measure) / d ln(threshold) from its last two frames (a secant
//! step; the first step assumes a slope of -1) and moves the threshold to
//! where that line meets the target, with the step limited to a factor of 4
//! and the threshold kept inside `range`. A secant step converges in a few
//! frames on a smooth response and the limit keeps it stable when the scene
//! changes under it; no PID tuning per workload is needed.

use crate::Stats;

/// What the controller aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Fraction of the reference's shading work (see [`Stats::shaded_fraction`]).
    ShadedFraction(f64),
    /// Milliseconds of GPU time for the shading passes ([`crate::Timings::total_ms`]):
    /// needs a GPU's timestamps (on lavapipe they do not measure the shader
    /// work; pass a wall time to `update` there).
    PassTimeMs(f64),
}

/// Steers one threshold towards a [`Target`].
#[derive(Debug, Clone, PartialEq)]
pub struct ThresholdController {
    target: Target,
    threshold: f64,
    range: (f64, f64),
    /// The previous frame's (ln threshold, ln measure), for the secant slope.
    previous: Option<(f64, f64)>,
}

/// Largest factor one frame may change the threshold by.
const MAX_STEP: f64 = 4.0;

impl ThresholdController {
    /// Starts at `initial`, clamped to `range` (both ends positive).
    pub fn new(target: Target, initial: f64, range: (f64, f64)) -> ThresholdController {
        let range = (range.0.max(f64::MIN_POSITIVE), range.1.max(range.0.max(f64::MIN_POSITIVE)));
        ThresholdController { target, threshold: initial.clamp(range.0, range.1), range, previous: None }
    }

    /// The threshold to use for the next frame.
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    pub fn target(&self) -> Target {
        self.target
    }

    /// The measure this controller steers, from a frame's statistics (`None`
    /// when a pass time is the target and the device has no timestamps).
    pub fn measure(&self, stats: &Stats) -> Option<f64> {
        match self.target {
            Target::ShadedFraction(_) => Some(stats.shaded_fraction),
            Target::PassTimeMs(_) => stats.timings.as_ref().map(|t| t.total_ms),
        }
    }

    /// Takes the frame's measured value (for the threshold last returned) and
    /// returns the threshold for the next frame.
    pub fn update(&mut self, measured: f64) -> f64 {
        let goal = match self.target {
            Target::ShadedFraction(f) | Target::PassTimeMs(f) => f,
        };
        if !(measured.is_finite() && measured > 0.0 && goal > 0.0) {
            return self.threshold;
        }
        let (x, y) = (self.threshold.ln(), measured.ln());
        let mut slope = -1.0;
        if let Some((px, py)) = self.previous {
            let dx = x - px;
            if dx.abs() > 1e-6 {
                let s = (y - py) / dx;
                // Only a falling response is believable; keep it away from 0
                // so that one flat secant does not send the threshold flying.
                if s < 0.0 {
                    slope = s.min(-0.05);
                }
            }
        }
        let step = ((goal.ln() - y) / slope).clamp(-MAX_STEP.ln(), MAX_STEP.ln());
        self.previous = Some((x, y));
        self.threshold = (x + step).exp().clamp(self.range.0, self.range.1);
        self.threshold
    }

    /// [`ThresholdController::update`] from a frame's statistics.
    pub fn update_from(&mut self, stats: &Stats) -> f64 {
        match self.measure(stats) {
            Some(m) => self.update(m),
            None => self.threshold,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plant whose shaded fraction falls as a power of the threshold, with a floor.
    fn plant(threshold: f64, scale: f64) -> f64 {
        (0.1 + 0.9 * (scale / (scale + threshold)).powf(0.7)).min(1.0)
    }

    #[test]
    fn converges_to_a_shaded_fraction_and_follows_a_change() {
        let mut c = ThresholdController::new(Target::ShadedFraction(0.4), 1e-3, (1e-7, 1e3));
        let mut scale = 0.01;
        let mut history = vec![];
        for frame in 0..40 {
            if frame == 20 {
                scale = 0.1; // the scene changes: ten times the threshold is needed
            }
            let f = plant(c.threshold(), scale);
            history.push(f);
            c.update(f);
        }
        for (frame, f) in history.iter().enumerate() {
            if (8..20).contains(&frame) || frame >= 28 {
                assert!((f - 0.4).abs() < 0.01, "frame {frame}: {f} ({history:?})");
            }
        }
    }

    #[test]
    fn stays_inside_its_range_when_the_target_is_unreachable() {
        let mut c = ThresholdController::new(Target::ShadedFraction(0.05), 1.0, (0.5, 10.0));
        for _ in 0..20 {
            let f = plant(c.threshold(), 1.0);
            c.update(f);
            assert!((0.5..=10.0).contains(&c.threshold()));
        }
        assert_eq!(c.threshold(), 10.0);
    }

    #[test]
    fn ignores_meaningless_measurements() {
        let mut c = ThresholdController::new(Target::PassTimeMs(10.0), 2.0, (1e-3, 1e3));
        assert_eq!(c.update(f64::NAN), 2.0);
        assert_eq!(c.update(0.0), 2.0);
    }
}
