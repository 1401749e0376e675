//! What a dispatch shaded: per effect, how many pixels took the coarse value
//! and how many re-evaluated it, and the work relative to the reference.

use crate::shader::DispatchOptions;
use mrsl_abi::geometry::sample_grid;
use mrsl_abi::plan::{Counts, Evaluations, SampleCount};
use mrsl_abi::{Layout, Rate};

/// GPU time of the passes, from timestamp queries.
///
/// `total_ms` spans from the first pass's beginning to the last pass's end.
/// All of it is only as good as the device's timestamps: on a GPU it is the
/// passes' time, the number to compare between modes; on a CPU device such
/// as lavapipe, which writes a timestamp when its queue thread reaches it
/// while the dispatches run on its worker threads, it does not measure the
/// shader work (a 7 ms pass can read as 0.05 ms). Measure wall time there
/// (docs/runtime.md, section 9).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Timings {
    pub coarse_ms: f64,
    /// The dynamic mode's 2x2 coarse pass (0 in other modes).
    pub coarse2_ms: f64,
    pub fine_ms: f64,
    pub total_ms: f64,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EffectStats {
    pub name: String,
    pub rate: Rate,
    /// Evaluations in the coarse kernel (one per coarse sample).
    pub coarse_evaluations: u64,
    /// Pixels that evaluated the effect themselves.
    pub pixel_evaluations: u64,
    /// Pixels that took a resampled coarse value.
    pub resampled: u64,
    /// Evaluations relative to the reference (one per pixel).
    pub shaded_fraction: f64,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stats {
    pub mode: String,
    pub force_refine: bool,
    pub width: u32,
    pub height: u32,
    pub coarse_samples: u64,
    pub effects: Vec<EffectStats>,
    /// Effect evaluations relative to the reference's (pixels x live effects).
    pub shaded_fraction: f64,
    /// The same over the coarse effects only: the part of the shading that
    /// adapts (fine effects run once per pixel in every mode). The analogue
    /// of DACS's "shading rate"; 1 in a program without coarse effects.
    pub coarse_shaded_fraction: f64,
    pub timings: Option<Timings>,
    /// Hierarchical mode: pixels queued for shading at levels 1 to 4.
    pub work_lists: Vec<u64>,
    /// Hierarchical mode: queued pixels / lanes dispatched to shade them.
    pub lane_utilisation: Option<f64>,
    /// With a background rule: the pixels it made background (their coarse
    /// effects neither evaluated nor resampled: they read as zero).
    pub background_pixels: u64,
    /// With a background rule: the coarse samples that fell on the
    /// background (not evaluated; subtracted from the coarse evaluations).
    pub background_samples: u64,
}

impl Stats {
    pub(crate) fn new(
        layout: &Layout,
        counts: &Counts,
        options: DispatchOptions,
        size: (u32, u32),
        counters: &[u32],
        timings: Option<Timings>,
        listed_samples: u64,
    ) -> Stats {
        let pixels = size.0 as u64 * size.1 as u64;
        let counter = |k: usize| counters.get(k).copied().unwrap_or(0) as u64;
        let samples = match counts.samples {
            SampleCount::None => 0,
            SampleCount::Grid { block, counter: extra } => {
                let (nx, ny) = sample_grid(size, block);
                // The dynamic mode adds the 2x2 samples its second level shaded, counted by its kernel.
                nx as u64 * ny as u64 + extra.map(counter).unwrap_or(0)
            }
            // The rate-image mode shades the samples its tiles listed (read back from its counter).
            SampleCount::Listed { .. } => listed_samples,
            // The grids of the levels that have live coarse effects (per effect, below).
            SampleCount::Levels => {
                let mut blocks: Vec<u32> = layout
                    .effects
                    .iter()
                    .enumerate()
                    .filter(|(_, e)| e.live && e.rate == Rate::Coarse)
                    .filter_map(|(k, _)| layout.levels.as_ref().map(|l| l.block[k]))
                    .collect();
                blocks.sort_unstable();
                blocks.dedup();
                blocks
                    .into_iter()
                    .map(|b| {
                        let (nx, ny) = sample_grid(size, b);
                        nx as u64 * ny as u64
                    })
                    .sum()
            }
        };
        // The multi-rate mode: each coarse effect's samples are those of its own grid.
        let samples_of = |block: u32| {
            let (nx, ny) = sample_grid(size, block);
            nx as u64 * ny as u64
        };
        let level_samples = |k: usize| samples_of(layout.levels.as_ref().map_or(1, |l| l.block[k]));
        let background_pixels = counts.background.map_or(0, |b| counter(b.pixels));
        let background_samples = counts.background.and_then(|b| b.samples).map_or(0, counter);
        let mut effects = vec![];
        for (k, e) in layout.effects.iter().enumerate().filter(|(_, e)| e.live) {
            let counted = || layout.stats.counters.iter().position(|c| *c == e.name).map(counter).unwrap_or(0);
            let (samples, background_samples) = match counts.samples {
                // Its background samples are counted at the 2x2 level (`LevelsLayout`).
                SampleCount::Levels if level_samples(k) != samples_of(2) => (level_samples(k), 0),
                SampleCount::Levels => (level_samples(k), background_samples),
                _ => (samples, background_samples),
            };
            let evaluated_samples = samples - background_samples.min(samples);
            let (coarse_evaluations, pixel_evaluations) = match (counts.evaluations, e.rate) {
                (Evaluations::Counted, Rate::Coarse) => (0, counted()),
                (Evaluations::SamplesAndCounted, Rate::Coarse) => (evaluated_samples, counted()),
                _ => (0, pixels),
            };
            // A background pixel neither evaluates nor resamples its coarse effects.
            let skipped = if e.rate == Rate::Coarse { background_pixels } else { 0 };
            effects.push(EffectStats {
                name: e.name.clone(),
                rate: e.rate,
                coarse_evaluations,
                pixel_evaluations,
                resampled: pixels - (pixel_evaluations + skipped).min(pixels),
                shaded_fraction: (coarse_evaluations + pixel_evaluations) as f64 / pixels as f64,
            });
        }
        let total: u64 = effects.iter().map(|e| e.coarse_evaluations + e.pixel_evaluations).sum();
        let shaded_fraction =
            if effects.is_empty() { 1.0 } else { total as f64 / (pixels * effects.len() as u64) as f64 };
        let coarse: Vec<&EffectStats> = effects.iter().filter(|e| e.rate == Rate::Coarse).collect();
        let coarse_shaded_fraction = if coarse.is_empty() {
            1.0
        } else {
            coarse.iter().map(|e| e.shaded_fraction).sum::<f64>() / coarse.len() as f64
        };
        Stats {
            mode: options.mode.name().into(),
            force_refine: options.force_refine,
            width: size.0,
            height: size.1,
            coarse_samples: samples,
            effects,
            shaded_fraction,
            coarse_shaded_fraction,
            timings,
            work_lists: vec![],
            lane_utilisation: None,
            background_pixels,
            background_samples,
        }
    }

    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} {}x{}{}: {} coarse samples, shaded fraction {:.1}% of the reference ({:.1}% of its coarse effects)\n",
            self.mode,
            self.width,
            self.height,
            if self.force_refine { " (forced refine)" } else { "" },
            self.coarse_samples,
            100.0 * self.shaded_fraction,
            100.0 * self.coarse_shaded_fraction
        );
        out.push_str(&format!(
            "  {:<20} {:>6} {:>12} {:>12} {:>12} {:>8}\n",
            "effect", "rate", "coarse", "per-pixel", "resampled", "shaded"
        ));
        for e in &self.effects {
            let rate = match e.rate {
                Rate::Coarse => "coarse",
                Rate::Fine => "fine",
                Rate::Out => "out",
            };
            out.push_str(&format!(
                "  {:<20} {:>6} {:>12} {:>12} {:>12} {:>7.1}%\n",
                e.name,
                rate,
                e.coarse_evaluations,
                e.pixel_evaluations,
                e.resampled,
                100.0 * e.shaded_fraction
            ));
        }
        if self.background_pixels > 0 || self.background_samples > 0 {
            out.push_str(&format!(
                "  background: {} pixels, {} coarse samples (coarse effects read as zero there)\n",
                self.background_pixels, self.background_samples
            ));
        }
        if !self.work_lists.is_empty() {
            out.push_str(&format!(
                "  work lists (levels 1-4): {:?} pixels, lane utilisation {:.1}%\n",
                self.work_lists,
                100.0 * self.lane_utilisation.unwrap_or(0.0)
            ));
        }
        if let Some(t) = self.timings {
            out.push_str(&format!(
                "  GPU time: {:.3} ms (coarse {:.3} ms, coarse 2x2 {:.3} ms, fine {:.3} ms)\n",
                t.total_ms, t.coarse_ms, t.coarse2_ms, t.fine_ms
            ));
        }
        out
    }
}
