//! Why a mode is slow here: after a mode's statistics, `render` prints, per
//! coarse effect, the compiler's count of operations for one evaluation
//! against what resampling a pixel costs, how much of the drawn image it
//! refined, and a one-line verdict.
//!
//! The model is the compiler's cost model (`EffectLayout::operations`: the
//! operations one evaluation executes, texture reads weighted 4) and a
//! resampling cost in the same units: per component of the value, four
//! corner reads, four multiplications and three additions (11), and per
//! pixel the refine-flag and key tests (4). An effect whose per-pixel
//! evaluation costs no more than that cannot gain from coarse shading,
//! whatever refines; otherwise it saves its cost less the resampling at
//! each resampled pixel and pays its coarse evaluations. The model leaves
//! out what a device adds (dispatches, barriers, memory traffic: the plan
//! summary above gives those), so it ranks effects and explains a loss
//! rather than predicting time.

use mrsl_abi::{Layout, Rate};
use mrsl_runtime::Stats;

/// Operations to resample one component of a value: four corner reads,
/// four multiplications, three additions.
const RESAMPLE_PER_COMPONENT: u64 = 11;
/// Operations per resampled pixel besides the blend: its flag and key tests.
const RESAMPLE_PER_PIXEL: u64 = 4;

/// The "why" block for `stats`, a run of `layout`'s program; empty for a run
/// without coarse effects or without coarse samples (the reference).
pub fn verdicts(layout: &Layout, stats: &Stats) -> String {
    let drawn = (u64::from(stats.width) * u64::from(stats.height)).saturating_sub(stats.background_pixels).max(1);
    let mut lines = vec![];
    for effect in stats.effects.iter().filter(|e| e.rate == Rate::Coarse) {
        let Some(declared) = layout.effects.iter().find(|d| d.name == effect.name) else { continue };
        let (Some(operations), Some(value)) = (declared.operations, declared.value_operations) else { continue };
        let resample = RESAMPLE_PER_COMPONENT * u64::from(declared.ty.components()) + RESAMPLE_PER_PIXEL;
        let refined = effect.pixel_evaluations as f64 / drawn as f64;
        // What coarse shading saved against evaluating every drawn pixel.
        let saved = effect.resampled as f64 * (value as f64 - resample as f64)
            - effect.coarse_evaluations as f64 * operations as f64;
        let verdict = if value <= resample {
            "costs no more than resampling it: expect no gain from shading it coarsely".to_string()
        } else if saved <= 0.0 {
            "refines too much here to pay for its coarse samples".to_string()
        } else {
            format!("saves about {:.0}% of its per-pixel work", 100.0 * saved / (drawn as f64 * value as f64))
        };
        lines.push(format!(
            "  {:<20} {:>6} ops, resampling {:>3}; refined {:>5.1}% of drawn pixels: {verdict}",
            effect.name,
            value,
            resample,
            100.0 * refined
        ));
    }
    if lines.is_empty() || stats.coarse_samples == 0 {
        return String::new();
    }
    format!(
        "why: per coarse effect, the compiler's operations per evaluation against resampling a pixel \
         ({RESAMPLE_PER_COMPONENT} per component + {RESAMPLE_PER_PIXEL})\n{}\n",
        lines.join("\n")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cheap effect is told it cannot gain; a costly one that rarely
    /// refines saves most of its work; one that refines everywhere does not pay.
    #[test]
    fn verdicts_follow_the_cost_model() {
        let source = "in float3 normal;\nin float2 uv;\n\
            coarse effect float cheap = normal.y;\n\
            coarse effect float costly {\n    float s = 0.0;\n    for (int i = 0; i < 16; i++) { s += sin(uv.x * float(i)) * cos(uv.y); }\n    costly = s;\n}\n\
            fine out float4 color = float4(cheap, costly, 0.0, 1.0);\n";
        let program = mrsl::compile(source, &mrsl::Options::default()).expect("compiles");
        let effect = |name: &str, coarse: u64, pixels: u64, resampled: u64| mrsl_runtime::EffectStats {
            name: name.into(),
            rate: Rate::Coarse,
            coarse_evaluations: coarse,
            pixel_evaluations: pixels,
            resampled,
            shaded_fraction: 0.0,
        };
        let stats = |effects| Stats {
            mode: "coarse4x4".into(),
            force_refine: false,
            width: 64,
            height: 64,
            coarse_samples: 289,
            effects,
            shaded_fraction: 0.0,
            coarse_shaded_fraction: 0.0,
            timings: None,
            work_lists: vec![],
            lane_utilisation: None,
            background_pixels: 0,
            background_samples: 0,
        };
        let rare =
            verdicts(&program.layout, &stats(vec![effect("cheap", 289, 100, 3996), effect("costly", 289, 100, 3996)]));
        let lines: Vec<&str> = rare.lines().collect();
        assert!(lines[0].starts_with("why:"), "{rare}");
        assert!(lines[1].contains("cheap") && lines[1].contains("expect no gain"), "{rare}");
        assert!(lines[2].contains("costly") && lines[2].contains("saves about"), "{rare}");
        assert!(lines[2].contains("refined   2.4% of drawn pixels"), "{rare}");
        let everywhere = verdicts(&program.layout, &stats(vec![effect("costly", 289, 4096, 0)]));
        assert!(everywhere.contains("refines too much here"), "{everywhere}");
        assert_eq!(verdicts(&program.layout, &stats(vec![])), "");
    }
}
