// The refine mask that `Shader.refineMask()` returns (rg32uint, one texel
// per pixel), decoded: which coarse effects a pixel evaluated itself (x),
// which it took from the dynamic mode's 2x2 level (y), or the background
// mark. The Rust runtime's `Layout::decode_refine_mask`, and the heatmap the
// playground and `mrslc render` draw of it.

import type { Layout } from './contract.js';

/** One texel of the refine mask, decoded: effect names in declaration order (that of `Stats.effects`). */
export type RefineMaskTexel = { background: true } | { background: false; perPixel: string[]; from2x2: string[] };

/**
 * The mask bit of coarse effect `effect`, the same in x and y: its index in
 * `layout.stats.counters` (dependency order, not declaration order); `null`
 * for a name that is not a live coarse effect, or one past the 32 bits.
 */
export function refineMaskBit(layout: Layout, effect: string): number | null {
  const bit = layout.stats.counters.indexOf(effect);
  return bit >= 0 && bit < 32 ? bit : null;
}

/** Decodes one texel `[x, y]` of the refine mask. */
export function decodeRefineMask(layout: Layout, [x, y]: readonly [number, number]): RefineMaskTexel {
  const mark = layout.plan.constants.background_mark;
  if (x === mark[0] && y === mark[1]) return { background: true };
  const set = (word: number) =>
    layout.effects.flatMap((e) => {
      const bit = refineMaskBit(layout, e.name);
      return bit !== null && ((word >>> bit) & 1) === 1 ? [e.name] : [];
    });
  return { background: false, perPixel: set(x), from2x2: set(y) };
}

/** A linear value as an sRGB byte: clamped, encoded, rounded half up (the lab's `linear_to_srgb8`). */
export function linearToSrgb8(v: number): number {
  if (!Number.isFinite(v)) return 0;
  const c = Math.min(Math.max(v, 0), 1);
  const s = c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055;
  return Math.floor(s * 255 + 0.5);
}

/** What `mrslc render`'s heatmaps paint the background (cli/src/legend.rs). */
const BACKGROUND_GREY = 150;

function popcount(n: number): number {
  let count = 0;
  for (let v = n >>> 0; v; v &= v - 1) count++;
  return count;
}

/**
 * The heatmap of a refine mask as RGBA8 texels (an `ImageData`'s data):
 * red by the share of coarse effects evaluated per pixel, green where one
 * came from the dynamic mode's 2x2 level, grey on the background; elsewhere
 * the image dimmed, where `image` (an rgba32float output, tightly packed, as
 * `readTexture` gives it) is given. `mask` is the mask's texels as
 * `readTexture` gives them.
 */
export function refineHeatmap(layout: Layout, mask: Uint8Array, image?: Uint8Array): Uint8ClampedArray<ArrayBuffer> {
  const words = new Uint32Array(mask.buffer, mask.byteOffset, mask.byteLength / 4);
  const floats = image ? new Float32Array(image.buffer, image.byteOffset, image.byteLength / 4) : null;
  const pixels = words.length / 2;
  const mark = layout.plan.constants.background_mark;
  const coarse = Math.max(layout.stats.counters.length, 1);
  const out = new Uint8ClampedArray(4 * pixels);
  for (let i = 0; i < pixels; i++) {
    out[4 * i + 3] = 255;
    if (words[2 * i] === mark[0] && words[2 * i + 1] === mark[1]) {
      out.fill(BACKGROUND_GREY, 4 * i, 4 * i + 3);
      continue;
    }
    const evaluated = popcount(words[2 * i]!) / coarse;
    const fromLevel2 = words[2 * i + 1]! !== 0;
    const srgb = (c: number) => (floats ? linearToSrgb8(floats[4 * i + c]!) : 0);
    const base = 0.35 * (0.3 * srgb(0) + 0.4 * srgb(1) + 0.1 * srgb(2));
    out[4 * i] = Math.round(base + evaluated * (255 - base));
    out[4 * i + 1] = Math.round(fromLevel2 ? 200 : base * (1 - evaluated));
    out[4 * i + 2] = Math.round(base * (1 - evaluated));
  }
  return out;
}
