// What a dispatch shaded: per effect, how many pixels took the coarse value
// and how many re-evaluated it, and the work relative to the reference,
// from the counters the plan reads back (the Rust runtime's `Stats`).

import type { Counts, Layout, Mode, Rate } from './contract.js';
import { sampleGrid, type Size } from './geometry.js';

export interface EffectStats {
  name: string;
  rate: Rate;
  /** Evaluations in the coarse kernel (one per coarse sample). */
  coarseEvaluations: number;
  /** Pixels that evaluated the effect themselves. */
  pixelEvaluations: number;
  /** Pixels that took a resampled coarse value. */
  resampled: number;
  /** Evaluations relative to the reference (one per pixel). */
  shadedFraction: number;
}

/** GPU time of the passes in milliseconds, from timestamp queries, summed by stage. */
export interface Timings {
  coarseMs: number;
  coarse2Ms: number;
  fineMs: number;
  /** From the first pass's beginning to the last pass's end. */
  totalMs: number;
}

export interface Stats {
  mode: Mode;
  forceRefine: boolean;
  width: number;
  height: number;
  coarseSamples: number;
  effects: EffectStats[];
  /** Effect evaluations relative to the reference's (pixels x live effects). */
  shadedFraction: number;
  /** The same over the coarse effects only (1 without coarse effects). */
  coarseShadedFraction: number;
  timings: Timings | null;
  /** Hierarchical mode: pixels queued for shading at levels 1 to 4. */
  workLists: number[];
  /** Hierarchical mode: queued pixels / lanes dispatched to shade them. */
  laneUtilisation: number | null;
  backgroundPixels: number;
  backgroundSamples: number;
}

export interface Counted {
  counters: Uint32Array;
  /** The rate-image mode's listed samples. */
  listedSamples: number;
  /** Per-level work-list lengths, where the mode has work lists. */
  workLists: number[];
}

const gridSamples = (size: Size, block: number) => {
  const [nx, ny] = sampleGrid(size, block);
  return nx * ny;
};

/** Effect `k`'s level in the multi-rate mode (1 without levels). */
const levelBlock = (layout: Layout, k: number) => layout.levels?.block[k] ?? 1;

/** The statistics of one dispatch from its counters. */
export function makeStats(layout: Layout, counts: Counts, mode: Mode, forceRefine: boolean, size: Size, counted: Counted, timings: Timings | null): Stats {
  const pixels = size[0] * size[1];
  const counter = (k: number) => counted.counters[k] ?? 0;
  let samples = 0;
  if (counts.samples.kind === 'grid') {
    const [nx, ny] = sampleGrid(size, counts.samples.block);
    samples = nx * ny + (counts.samples.counter === null ? 0 : counter(counts.samples.counter));
  } else if (counts.samples.kind === 'listed') {
    samples = counted.listedSamples;
  } else if (counts.samples.kind === 'levels') {
    // The grids of the levels that have live coarse effects.
    const blocks = new Set(layout.effects.flatMap((e, k) => (e.live && e.rate === 'coarse' ? [levelBlock(layout, k)] : [])));
    samples = [...blocks].reduce((sum, b) => sum + gridSamples(size, b), 0);
  }
  const backgroundPixels = counts.background ? counter(counts.background.pixels) : 0;
  const backgroundSamples = counts.background?.samples != null ? counter(counts.background.samples) : 0;
  const effects: EffectStats[] = layout.effects
    .map((e, k) => ({ e, k }))
    .filter(({ e }) => e.live)
    .map(({ e, k }) => {
      const index = layout.stats.counters.indexOf(e.name);
      const countedHere = index < 0 ? 0 : counter(index);
      // The multi-rate mode: an effect's samples are its own level's; the
      // background samples are counted at the 2x2 level.
      const levels = counts.samples.kind === 'levels';
      const own = levels ? gridSamples(size, levelBlock(layout, k)) : samples;
      const ownBackground = levels && levelBlock(layout, k) !== 2 ? 0 : backgroundSamples;
      const evaluatedSamples = own - Math.min(ownBackground, own);
      let [coarseEvaluations, pixelEvaluations] = [0, pixels];
      if (e.rate === 'coarse' && counts.evaluations === 'counted') [coarseEvaluations, pixelEvaluations] = [0, countedHere];
      if (e.rate === 'coarse' && counts.evaluations === 'samples_and_counted') {
        [coarseEvaluations, pixelEvaluations] = [evaluatedSamples, countedHere];
      }
      const skipped = e.rate === 'coarse' ? backgroundPixels : 0;
      return {
        name: e.name,
        rate: e.rate,
        coarseEvaluations,
        pixelEvaluations,
        resampled: pixels - Math.min(pixelEvaluations + skipped, pixels),
        shadedFraction: (coarseEvaluations + pixelEvaluations) / pixels,
      };
    });
  const total = effects.reduce((sum, e) => sum + e.coarseEvaluations + e.pixelEvaluations, 0);
  const coarse = effects.filter((e) => e.rate === 'coarse');
  const workLists = counted.workLists;
  const lanes = counts.work_lists?.lanes ?? 1;
  const dispatched = workLists.reduce((sum, c) => sum + Math.ceil(c / lanes) * lanes, 0);
  const queued = workLists.reduce((sum, c) => sum + c, 0);
  return {
    mode,
    forceRefine,
    width: size[0],
    height: size[1],
    coarseSamples: samples,
    effects,
    shadedFraction: effects.length === 0 ? 1 : total / (pixels * effects.length),
    coarseShadedFraction: coarse.length === 0 ? 1 : coarse.reduce((s, e) => s + e.shadedFraction, 0) / coarse.length,
    timings,
    workLists,
    laneUtilisation: counts.work_lists ? (dispatched === 0 ? 1 : queued / dispatched) : null,
    backgroundPixels,
    backgroundSamples,
  };
}
