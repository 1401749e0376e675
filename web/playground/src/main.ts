// The mrsl playground: edit a program, see its diagnostics as you type
// (compiled by `mrslc serve`), its kernels and layout, and its image
// rendered in this browser's WebGPU by the web runtime over a scene's
// G-buffer, in any mode, with the heatmap, the statistics and the timings.
// `document.body.dataset.state` says where it is (loading, compiling,
// rendering, rendered, error, no-webgpu) and `dataset.renders` counts the
// images shown, for the browser test.

import { basicSetup, EditorView } from 'codemirror';
import { type Diagnostic as LintDiagnostic, lintGutter, setDiagnostics } from '@codemirror/lint';
import {
  applyUniforms,
  loadGBuffer,
  MODES,
  parseLayout,
  readTexture,
  Shader,
  uniformRateImage,
  type LoadedGBuffer,
  type Mode,
  type Stats,
} from '../../src/index.js';
import * as api from './api.js';
import { completion, hover } from './assist.js';
import { mrsl } from './language.js';
import { drawHeatmap, drawImage, showDiagnostics, showProgram, showStats, showTimings, type ModeTiming } from './view.js';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const ui = {
  example: $<HTMLSelectElement>('example'),
  scene: $<HTMLSelectElement>('scene'),
  size: $<HTMLSelectElement>('size'),
  mode: $<HTMLSelectElement>('mode'),
  view: $<HTMLSelectElement>('view'),
  forced: $<HTMLInputElement>('forced'),
  timeAll: $<HTMLButtonElement>('time-all'),
  status: $('status'),
  canvas: $<HTMLCanvasElement>('image'),
  note: $('image-note'),
  diagnostics: $('diagnostics'),
  stats: $<HTMLTableElement>('stats'),
  timings: $<HTMLTableElement>('timings'),
  kernel: $<HTMLSelectElement>('kernel'),
  wgsl: $('wgsl'),
  layout: $('layout'),
};

/** The rate-image mode's rate image here: every 8x8 tile at 2x2 (the playground has no rate source). */
const RATE = { tile: 8, rate: [2, 2] as const };

type State = 'loading' | 'compiling' | 'rendering' | 'rendered' | 'error' | 'no-webgpu';
function setState(state: State, message: string): void {
  document.body.dataset.state = state;
  ui.status.textContent = message;
}

let device: GPUDevice | null = null;
/** Whether timestamps measure the shader work: a GPU's do, a CPU adapter's (SwiftShader, a fallback adapter) do not. */
let gpuClock = false;
let shader: Shader | null = null;
let gbuffer: { key: string; loaded: LoadedGBuffer } | null = null;
/** Bumped by every edit: a compile or render that finds it changed stops. */
let generation = 0;

async function openDevice(): Promise<GPUDevice | null> {
  const adapter = await navigator.gpu?.requestAdapter();
  if (!adapter) return null;
  const info = adapter.info as GPUAdapterInfo & { isFallbackAdapter?: boolean };
  gpuClock = adapter.features.has('timestamp-query') && !info.isFallbackAdapter && !/swiftshader|llvmpipe|cpu/i.test(`${info.architecture} ${info.description} ${info.device}`);
  const requiredFeatures: GPUFeatureName[] = adapter.features.has('timestamp-query') ? ['timestamp-query'] : [];
  const opened = await adapter.requestDevice({ requiredFeatures });
  opened.lost.then((info) => setState('error', `the WebGPU device was lost: ${info.message}`));
  return opened;
}

/** UTF-8 byte offsets (the server's spans) to indices into the JS string. */
function byteOffsetsToIndices(source: string): (byte: number) => number {
  const starts: number[] = [];
  let bytes = 0;
  for (let i = 0; i < source.length; i++) {
    starts.push(bytes);
    const code = source.codePointAt(i)!;
    bytes += code < 0x80 ? 1 : code < 0x800 ? 2 : code < 0x10000 ? 3 : 4;
    if (code >= 0x10000) starts.push(bytes), i++;
  }
  return (byte) => {
    let lo = 0;
    let hi = starts.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (starts[mid]! < byte) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  };
}

function lint(view: EditorView, source: string, diagnostics: api.Diagnostic[]): void {
  const toIndex = byteOffsetsToIndices(source);
  const found: LintDiagnostic[] = diagnostics.flatMap((d) => {
    const label = d.labels.find((l) => l.primary) ?? d.labels[0];
    if (!label) return [];
    const from = Math.min(toIndex(label.start), source.length);
    const to = Math.min(Math.max(toIndex(label.end), from), source.length);
    const message = `${d.code}: ${d.message}${label.message ? ` (${label.message})` : ''}`;
    return [{ from, to, severity: d.severity, message }];
  });
  view.dispatch(setDiagnostics(view.state, found));
}

function size(): [number, number] {
  const [w, h] = ui.size.value.split('x').map(Number);
  return [w!, h!];
}

/** Compiles the editor's program, shows what the compiler says, and renders it. */
async function update(view: EditorView): Promise<void> {
  const mine = ++generation;
  const source = view.state.doc.toString();
  setState('compiling', 'compiling…');
  let compiled: api.Compiled;
  try {
    compiled = await api.compile(source);
  } catch (error) {
    return setState('error', `the server refused the program: ${(error as Error).message}`);
  }
  if (mine !== generation) return;
  lint(view, source, compiled.diagnostics);
  showDiagnostics(ui.diagnostics, compiled.diagnostics, null);
  if (!compiled.ok || !compiled.layout) {
    const errors = compiled.diagnostics.filter((d) => d.severity === 'error').length;
    return setState('error', `${errors} error${errors === 1 ? '' : 's'}: the image is the last program's`);
  }
  const program = { layout: parseLayout(compiled.layout), kernels: compiled.kernels };
  ui.timings.replaceChildren(); // the last program's
  showProgram(ui.kernel, ui.wgsl, ui.layout, compiled.kernels, program.layout);
  if (!device) return setState('no-webgpu', 'compiled; this browser has no WebGPU, so nothing is rendered');
  try {
    const next = await Shader.create(device, program);
    if (mine !== generation) return next.destroy();
    shader?.destroy();
    shader = next;
    await ensureGBuffer(source, program.layout);
    if (mine !== generation) return;
    await renderSelected(mine);
  } catch (error) {
    showDiagnostics(ui.diagnostics, compiled.diagnostics, (error as Error).message);
    setState('error', (error as Error).message);
  }
}

/** Exports the scene for this program unless the export at hand already binds what it declares. */
async function ensureGBuffer(source: string, layout: object): Promise<void> {
  const l = layout as { uniforms: unknown; textures: unknown; samplers: unknown };
  const key = JSON.stringify([ui.scene.value, ui.size.value, l.uniforms, l.textures, l.samplers]);
  if (gbuffer?.key === key) return;
  setState('rendering', `exporting the ${ui.scene.value} G-buffer at ${ui.size.value}…`);
  const exported = await api.exportGBuffer(ui.scene.value, size(), source);
  const loaded = await loadGBuffer(device!, exported.manifest, (file) => api.exportFile(exported.base, file));
  gbuffer = { key, loaded };
}

interface Rendered {
  stats: Stats;
  timing: ModeTiming;
  image: Uint8Array;
  mask: Uint8Array | null;
}

/** Renders `mode` twice (the first warms the pipelines) and times the second. */
async function render(mode: Mode, forced: boolean): Promise<Rendered> {
  const d = device!;
  const s = shader!;
  const g = gbuffer!.loaded;
  applyUniforms(s, g.manifest);
  const outputs: Record<string, GPUTexture> = {};
  for (const o of s.layout.outputs) {
    outputs[o.name] = d.createTexture({ size: g.size, format: o.format, usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC });
  }
  const shadingRate = uniformRateImage(d, g.size, RATE.tile, RATE.rate);
  const bindings = { size: g.size, channels: g.channels, textures: g.textures, samplers: g.samplers, outputs, shadingRate };
  let wallMs = 0;
  for (let run = 0; run < 2; run++) {
    const encoder = d.createCommandEncoder();
    s.encode(encoder, bindings, { mode, forceRefine: forced, rateTile: RATE.tile });
    const start = performance.now();
    d.queue.submit([encoder.finish()]);
    await d.queue.onSubmittedWorkDone();
    wallMs = performance.now() - start;
  }
  const stats = await s.readStats();
  const first = s.layout.outputs[0]!;
  const image = await readTexture(d, outputs[first.name]!);
  const maskTexture = s.refineMask();
  const mask = maskTexture && mode !== 'reference' ? await readTexture(d, maskTexture) : null;
  Object.values(outputs).forEach((t) => t.destroy());
  shadingRate.destroy();
  const timing: ModeTiming = { mode, wallMs, gpuMs: stats.timings?.totalMs ?? null, shadedFraction: stats.shadedFraction };
  return { stats, timing, image, mask };
}

async function renderSelected(mine = generation): Promise<void> {
  if (!shader || !gbuffer) return;
  const mode = ui.mode.value as Mode;
  setState('rendering', `rendering ${mode}…`);
  const r = await render(mode, ui.forced.checked);
  if (mine !== generation) return;
  if (ui.view.value === 'heatmap' && r.mask) drawHeatmap(ui.canvas, shader.layout, gbuffer.loaded.size, r.mask, r.image);
  else drawImage(ui.canvas, gbuffer.loaded.size, r.image);
  const heat = ui.view.value === 'heatmap' ? (r.mask ? 'heatmap: red by the share of coarse effects evaluated per pixel, green from the 2x2 level, grey the background; ' : 'no heatmap in this mode; ') : '';
  const rate = mode === 'rate-image' ? `; every ${RATE.tile}x${RATE.tile} tile at ${RATE.rate.join('x')}` : '';
  const ms = (t: ModeTiming) => (gpuClock && t.gpuMs !== null ? `${t.gpuMs.toFixed(2)} ms GPU time` : `${t.wallMs.toFixed(2)} ms wall time`);
  ui.note.textContent = `${heat}${mode}${ui.forced.checked ? ' (forced)' : ''} over ${gbuffer.loaded.manifest.scene} at ${ui.size.value}${rate}; ${ms(r.timing)}`;
  showStats(ui.stats, r.stats);
  document.body.dataset.renders = String(Number(document.body.dataset.renders ?? 0) + 1);
  setState('rendered', `${mode}: ${(100 * r.stats.shadedFraction).toFixed(1)}% shaded, ${ms(r.timing)}`);
}

async function timeEveryMode(): Promise<void> {
  if (!shader || !gbuffer) return;
  const mine = generation;
  const timings: ModeTiming[] = [];
  for (const mode of shader.modes()) {
    setState('rendering', `timing ${mode}…`);
    timings.push((await render(mode, false)).timing);
    if (mine !== generation) return;
    showTimings(ui.timings, timings, gpuClock);
  }
  setState('rendered', `timed ${timings.length} modes`);
}

async function start(): Promise<void> {
  ui.mode.replaceChildren(...MODES.map((m) => new Option(m, m, m === 'coarse4x4', m === 'coarse4x4')));
  const [examples, scenes] = await Promise.all([api.examples(), api.scenes()]);
  ui.example.replaceChildren(...examples.map((e) => new Option(`${e.name} (${e.scene})`, e.name)));
  ui.scene.replaceChildren(...scenes.map((s) => new Option(s, s)));
  device = await openDevice();
  let timer = 0;
  const view = new EditorView({
    parent: $('editor'),
    doc: examples[0]?.source ?? '',
    extensions: [
      basicSetup,
      mrsl,
      lintGutter(),
      hover,
      completion,
      EditorView.updateListener.of((u) => {
        if (!u.docChanged) return;
        clearTimeout(timer);
        timer = window.setTimeout(() => void update(view), 300);
      }),
    ],
  });
  // For the browser test: the editor, to find where a name is drawn.
  (window as unknown as { mrslEditor: EditorView }).mrslEditor = view;
  const pickExample = () => {
    const example = examples.find((e) => e.name === ui.example.value);
    if (!example) return;
    ui.scene.value = example.scene;
    gbuffer = null;
    view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: example.source } });
  };
  ui.example.onchange = pickExample;
  ui.scene.onchange = ui.size.onchange = () => void update(view);
  ui.mode.onchange = ui.view.onchange = ui.forced.onchange = () => void renderSelected().catch((e) => setState('error', (e as Error).message));
  ui.timeAll.onclick = () => void timeEveryMode().catch((e) => setState('error', (e as Error).message));
  ui.scene.value = examples[0]?.scene ?? 'demo';
  await update(view);
}

start().catch((error) => setState('error', `the playground did not start: ${(error as Error).message}`));
