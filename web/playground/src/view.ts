// What the playground shows of a render: the image (sRGB-encoded from the
// float output), the heatmap of where coarse effects were evaluated per
// pixel, the per-effect statistics and the per-mode timings.

import { linearToSrgb8, refineHeatmap, type Layout, type Mode, type Stats } from '../../src/index.js';
import type { Diagnostic } from './api.js';

/** Draws an rgba32float output, tightly packed, into the canvas. */
export function drawImage(canvas: HTMLCanvasElement, size: readonly [number, number], texels: Uint8Array): void {
  const floats = new Float32Array(texels.buffer, texels.byteOffset, texels.byteLength / 4);
  const image = new ImageData(size[0], size[1]);
  for (let i = 0; i < size[0] * size[1]; i++) {
    for (let c = 0; c < 3; c++) image.data[4 * i + c] = linearToSrgb8(floats[4 * i + c]!);
    image.data[4 * i + 3] = 255;
  }
  put(canvas, image);
}

/**
 * Draws the refine mask (rg32uint): the image dimmed where every coarse
 * effect was resampled, red by the share of coarse effects evaluated per
 * pixel, green where one came from the dynamic mode's 2x2 level, grey on
 * the background (where the background rule skipped the coarse effects).
 */
export function drawHeatmap(canvas: HTMLCanvasElement, layout: Layout, size: readonly [number, number], mask: Uint8Array, image: Uint8Array): void {
  put(canvas, new ImageData(refineHeatmap(layout, mask, image), size[0], size[1]));
}

function put(canvas: HTMLCanvasElement, image: ImageData): void {
  canvas.width = image.width;
  canvas.height = image.height;
  (canvas.getContext('2d') as CanvasRenderingContext2D).putImageData(image, 0, 0);
}

const percent = (f: number) => `${(100 * f).toFixed(1)}%`;

function rows(table: HTMLTableElement, head: string[], body: string[][]): void {
  table.replaceChildren();
  const tr = (cells: string[], tag: 'th' | 'td') => {
    const row = table.insertRow();
    for (const text of cells) {
      const cell = document.createElement(tag);
      cell.textContent = text;
      row.append(cell);
    }
  };
  tr(head, 'th');
  body.forEach((cells) => tr(cells, 'td'));
}

/** The per-effect statistics: how many pixels evaluated each effect, how many resampled it. */
export function showStats(table: HTMLTableElement, stats: Stats): void {
  const body = stats.effects.map((e) => [e.name, e.rate, String(e.coarseEvaluations), String(e.pixelEvaluations), String(e.resampled), percent(e.shadedFraction)]);
  body.push(['all effects', '', String(stats.coarseSamples), '', '', percent(stats.shadedFraction)]);
  rows(table, ['effect', 'rate', 'coarse', 'per-pixel', 'resampled', 'shaded'], body);
}

export interface ModeTiming {
  mode: Mode;
  /** From submission to completion of the frame's commands. */
  wallMs: number;
  /** The passes' span from timestamp queries, where the device has them. */
  gpuMs: number | null;
  shadedFraction: number;
}

/**
 * Each mode's times, and its speed against the reference's: by GPU time
 * where `gpuClock` (timestamps measure the shader work on a GPU, not on a
 * CPU adapter such as SwiftShader), else by wall time.
 */
export function showTimings(table: HTMLTableElement, timings: ModeTiming[], gpuClock: boolean): void {
  const time = (t: ModeTiming) => (gpuClock && t.gpuMs !== null ? t.gpuMs : t.wallMs);
  const reference = timings.find((t) => t.mode === 'reference');
  const body = timings.map((t) => [
    t.mode,
    t.gpuMs === null ? '' : `${t.gpuMs.toFixed(2)} ms`,
    `${t.wallMs.toFixed(2)} ms`,
    reference ? `${(time(reference) / time(t)).toFixed(2)}x` : '',
    percent(t.shadedFraction),
  ]);
  rows(table, ['mode', 'GPU time', 'wall time', `vs reference (${gpuClock ? 'GPU' : 'wall'})`, 'shaded'], body);
}

/** Compiler diagnostics as the compiler renders them. */
export function showDiagnostics(panel: HTMLElement, diagnostics: Diagnostic[], problem: string | null): void {
  panel.replaceChildren();
  for (const d of diagnostics) {
    const pre = document.createElement('pre');
    pre.className = d.severity;
    pre.textContent = d.rendered;
    panel.append(pre);
  }
  if (problem) {
    const pre = document.createElement('pre');
    pre.textContent = problem;
    panel.append(pre);
  }
}

/** The kernels' WGSL, one at a time, and the layout. */
export function showProgram(select: HTMLSelectElement, wgsl: HTMLElement, layoutPre: HTMLElement, kernels: { file: string; wgsl: string }[], layout: Layout): void {
  const chosen = select.value;
  select.replaceChildren(...kernels.map((k) => new Option(k.file, k.file)));
  if (kernels.some((k) => k.file === chosen)) select.value = chosen;
  const show = () => (wgsl.textContent = kernels.find((k) => k.file === select.value)?.wgsl ?? '');
  select.onchange = show;
  show();
  layoutPre.textContent = JSON.stringify(layout, null, 2);
}
