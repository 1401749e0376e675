// Frame loops as an engine writes them: several `encode`s of one Shader
// into one submission (views of their own size, uniforms and mode), each
// bit for bit its render alone; and `readStats()` called every frame of a
// render loop, with no failed submit, its failures typed.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { loadGBuffer, loadProgram, MrslError, readTexture, Shader } from '../dist/index.js';
import { testDevice } from './support/gpu.mjs';
import { mrslc } from './support/mrslc.mjs';
import { bytes } from './support/fixtures.mjs';

/** A coarse effect that refines, and a uniform each view sets its own way (the Rust runtime's render test's program). */
const PROGRAM = `in float3 normal;
in float3 position;
uniform float3 tint = float3(1.0);
coarse effect float3 lit {
    lit = tint * saturate(normal.y * 0.5 + 0.5) * (0.5 + 0.5 * sin(position.x * 3.0));
    if (fwidth(lit.x) > 0.05) refine;
}
fine out float4 color = float4(lit, 1.0);
`;

/**
 * The first and the last view share a size and differ in `tint` (the second
 * one's values must not reach the first); the middle one has a size and a
 * mode of its own (its resources must not replace the first one's while
 * that one's commands use them).
 */
const VIEWS = [
  { size: [40, 24], tint: [1, 0.5, 0.25], mode: 'coarse4x4' },
  { size: [56, 40], tint: [0.2, 0.9, 0.4], mode: 'hierarchical' },
  { size: [40, 24], tint: [0.3, 0.3, 1], mode: 'dynamic' },
];

let gpu;
let dir;
let program;
const gbuffers = new Map();

before(async () => {
  gpu = await testDevice();
  if (gpu.skip) return;
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-loops-'));
  const source = join(dir, 'views.mrsl');
  writeFileSync(source, PROGRAM);
  mrslc(['compile', source, '--mode', 'coarse4x4,hierarchical,dynamic', '-o', join(dir, 'kernels')]);
  program = await loadProgram((f) => readFile(join(dir, 'kernels', f), 'utf8'), 'views');
  for (const [w, h] of new Set(VIEWS.map((v) => v.size)).values()) {
    if (gbuffers.has(`${w}x${h}`)) continue;
    const out = join(dir, `gbuffer-${w}x${h}`);
    mrslc(['gbuffer', '--scene', 'demo', '--size', `${w}x${h}`, '-o', out, source]);
    const manifest = JSON.parse(await readFile(join(out, 'gbuffer.json'), 'utf8'));
    gbuffers.set(`${w}x${h}`, await loadGBuffer(gpu.device, manifest, (f) => bytes(join(out, f))));
  }
});
after(() => dir && rmSync(dir, { recursive: true, force: true }));

const skip = (t) => gpu.skip && (t.skip(gpu.skip), true);

/** Errors the device reports while `f` runs, and those it reports uncaptured. */
async function deviceErrors(f) {
  const device = gpu.device;
  const uncaptured = [];
  const listener = (e) => uncaptured.push(e.error?.message ?? String(e));
  device.addEventListener('uncapturederror', listener);
  device.pushErrorScope('validation');
  try {
    await f();
  } finally {
    const scoped = await device.popErrorScope();
    await device.queue.onSubmittedWorkDone();
    device.removeEventListener('uncapturederror', listener);
    if (scoped) uncaptured.unshift(scoped.message);
  }
  return uncaptured;
}

/** Encodes `views` into one encoder, submits once, and reads each view's output back. */
async function renderViews(shader, views) {
  const device = gpu.device;
  const outputs = views.map(({ size }) =>
    device.createTexture({ size, format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC }),
  );
  const encoder = device.createCommandEncoder();
  views.forEach((view, k) => {
    shader.setUniform('tint', view.tint);
    const g = gbuffers.get(view.size.join('x'));
    shader.encode(encoder, { size: view.size, channels: g.channels, outputs: { color: outputs[k] } }, { mode: view.mode });
  });
  device.queue.submit([encoder.finish()]);
  return Promise.all(outputs.map((o) => readTexture(device, o)));
}

const differing = (a, b) => a.reduce((n, byte, i) => n + (byte !== b[i] ? 1 : 0), 0);

test('views of their own size, uniforms and mode in one submission are each their render alone, bit for bit', async (t) => {
  if (skip(t)) return;
  const shader = await Shader.create(gpu.device, program);
  let alone;
  let together;
  const errors = await deviceErrors(async () => {
    alone = [];
    for (const view of VIEWS) alone.push(...(await renderViews(shader, [view])));
    together = await renderViews(shader, VIEWS);
  });
  assert.deepEqual(errors, [], 'the device reported no error');
  VIEWS.forEach((view, k) => {
    const n = differing(alone[k], together[k]);
    assert.equal(n, 0, `view ${k} (${view.mode}, ${view.size.join('x')}): ${n} of ${alone[k].length} bytes differ from its render alone`);
  });
  assert.ok(differing(alone[0], alone[2]) > 0, 'the two views of one size differ, or the test would mean nothing');
  const stats = await shader.readStats();
  assert.deepEqual([stats.mode, stats.width, stats.height], ['dynamic', 40, 24], 'readStats reports the last encode');
  shader.destroy();
});

test('readStats() every frame of a 300-frame render loop: no failed submit, every frame counted', async (t) => {
  if (skip(t)) return;
  const device = gpu.device;
  const shader = await Shader.create(device, program);
  const g = gbuffers.get('40x24');
  const color = device.createTexture({ size: [40, 24], format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING });
  const bindings = { size: [40, 24], channels: g.channels, outputs: { color } };
  const frames = 300;
  const read = [];
  const errors = await deviceErrors(async () => {
    for (let frame = 0; frame < frames; frame++) {
      // Every third frame a view of its own mode, so that consecutive statistics differ.
      const mode = frame % 3 === 2 ? 'hierarchical' : 'coarse4x4';
      const encoder = device.createCommandEncoder();
      shader.encode(encoder, bindings, { mode });
      device.queue.submit([encoder.finish()]);
      // As a page's loop does: read, and do not wait for it before the next frame.
      read.push(shader.readStats().then((stats) => ({ mode, stats })));
      // The next "animation frame": a macrotask later, as requestAnimationFrame's are.
      await new Promise((resolve) => setTimeout(resolve, 0));
    }
    const settled = await Promise.allSettled(read);
    const failed = settled.filter((s) => s.status === 'rejected').map((s) => String(s.reason));
    assert.deepEqual(failed.slice(0, 3), [], `${failed.length} of ${frames} readStats() failed`);
    for (const { value } of settled) {
      assert.equal(value.stats.mode, value.mode, 'each frame reads its own statistics');
      if (value.mode === 'coarse4x4') assert.ok(value.stats.coarseSamples > 0, 'coarse4x4 counts its samples');
      else assert.ok(value.stats.workLists.some((n) => n > 0), 'hierarchical counts its work lists');
    }
  });
  assert.deepEqual(errors.slice(0, 3), [], `the device reported ${errors.length} errors`);
  shader.destroy();
});

test('readStats: before any encode and after destroy, typed errors', async (t) => {
  if (skip(t)) return;
  const device = gpu.device;
  const shader = await Shader.create(device, program);
  await assert.rejects(shader.readStats(), (e) => e instanceof MrslError && e.kind === 'readback' && /encode/.test(e.message));
  const g = gbuffers.get('40x24');
  const color = device.createTexture({ size: [40, 24], format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING });
  const encoder = device.createCommandEncoder();
  shader.encode(encoder, { size: [40, 24], channels: g.channels, outputs: { color } }, { mode: 'coarse4x4' });
  device.queue.submit([encoder.finish()]);
  const pending = shader.readStats();
  shader.destroy();
  await assert.rejects(pending, (e) => e instanceof MrslError && e.kind === 'readback' && /destroy/.test(e.message));
});
