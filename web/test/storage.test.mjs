// Kernels compiled with storage channels (`mrslc compile --storage-channels`)
// read the G-buffer through read-only storage bindings: on Dawn they render
// every mode byte for byte as the sampled kernels do over the same
// G-buffer, and a channel texture of another format, or without
// STORAGE_BINDING, is refused with a typed error before anything is recorded.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { applyUniforms, loadGBuffer, loadProgram, MODES, MrslError, readTexture, Shader, uniformRateImage } from '../dist/index.js';
import { freshAdapter, testDevice } from './support/gpu.mjs';
import { mrslc } from './support/mrslc.mjs';
import { SIZE, bytes } from './support/fixtures.mjs';

let gpu;
let device;
let dir;
let sampled;
let storage;
let gbuffer;

before(async () => {
  gpu = await testDevice();
  if (gpu.skip) return;
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-storage-'));
  mrslc(['compile', 'examples/demo.mrsl', '-o', join(dir, 'sampled')]);
  mrslc(['compile', 'examples/demo.mrsl', '--storage-channels', '-o', join(dir, 'storage')]);
  mrslc(['gbuffer', '--scene', 'demo', '--size', `${SIZE[0]}x${SIZE[1]}`, '-o', join(dir, 'gbuffer'), 'examples/demo.mrsl']);
  const load = (sub) => loadProgram((f) => readFile(join(dir, sub, f), 'utf8'), 'demo');
  const [sampledProgram, storageProgram] = [await load('sampled'), await load('storage')];
  // The storage kernels bind one storage texture more per channel than WebGPU's default limit allows.
  const wanted = storageProgram.layout.channels.length + gpu.device.limits.maxStorageTexturesPerShaderStage;
  const adapter = await freshAdapter();
  const granted = adapter.limits.maxStorageTexturesPerShaderStage;
  assert.ok(granted >= wanted, `the adapter allows ${granted} storage textures per stage; the storage kernels need up to ${wanted}`);
  device = await adapter.requestDevice({ requiredLimits: { maxStorageTexturesPerShaderStage: wanted } });
  const manifest = JSON.parse(await readFile(join(dir, 'gbuffer', 'gbuffer.json'), 'utf8'));
  gbuffer = await loadGBuffer(device, manifest, (f) => bytes(join(dir, 'gbuffer', f)));
  sampled = await Shader.create(device, sampledProgram);
  storage = await Shader.create(device, storageProgram);
  applyUniforms(sampled, manifest);
  applyUniforms(storage, manifest);
});
after(() => {
  device?.destroy();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

const skip = (t) => gpu.skip && (t.skip(gpu.skip), true);

function bindings(channels) {
  const color = device.createTexture({ size: SIZE, format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC });
  return { size: SIZE, channels, textures: gbuffer.textures, samplers: gbuffer.samplers, outputs: { color }, shadingRate: uniformRateImage(device, SIZE, 8, [2, 2]) };
}

async function render(shader, mode, forceRefine = false) {
  const b = bindings(gbuffer.channels);
  const encoder = device.createCommandEncoder();
  shader.encode(encoder, b, { mode, forceRefine });
  device.queue.submit([encoder.finish()]);
  const image = new Uint8Array(await readTexture(device, b.outputs.color));
  return { image, stats: await shader.readStats() };
}

test('the layouts say how each channel is bound', (t) => {
  if (skip(t)) return;
  assert.ok(storage.layout.channels.every((c) => c.access === 'storage'));
  assert.ok(sampled.layout.channels.every((c) => (c.access ?? 'sampled') === 'sampled'));
});

test('every mode renders the same bytes with storage channels, and forced refinement the reference', async (t) => {
  if (skip(t)) return;
  const reference = (await render(storage, 'reference')).image;
  for (const mode of MODES) {
    const [a, b] = [await render(sampled, mode), await render(storage, mode)];
    assert.deepEqual(b.image, a.image, `${mode}: storage channels change the image`);
    assert.equal(b.stats.shadedFraction, a.stats.shadedFraction, `${mode}: storage channels change the statistics`);
    if (mode === 'reference') continue;
    const forced = await render(storage, mode, true);
    assert.deepEqual(forced.image, reference, `${mode}: forced refinement differs from the reference`);
  }
});

async function refused(channels, kind, words) {
  const encoder = device.createCommandEncoder();
  device.pushErrorScope('validation');
  assert.throws(
    () => storage.encode(encoder, bindings(channels), { mode: 'coarse4x4' }),
    (e) => e instanceof MrslError && e.kind === kind && words.every((w) => e.message.includes(w)) && (console.log(`  ${kind}: ${e.message}`), true),
  );
  device.queue.submit([encoder.finish()]);
  assert.equal(await device.popErrorScope(), null, 'the encoder is still valid: nothing was recorded');
}

test('a storage channel takes exactly its format, with STORAGE_BINDING', async (t) => {
  if (skip(t)) return;
  const usage = GPUTextureUsage.TEXTURE_BINDING | GPUTextureUsage.STORAGE_BINDING;
  const half = device.createTexture({ size: SIZE, format: 'rgba16float', usage });
  await refused({ ...gbuffer.channels, normal: half }, 'channel-format', ['`normal`', 'rgba16float', 'rgba32float', 'storage binding']);
  const sampledOnly = device.createTexture({ size: SIZE, format: 'rgba32float', usage: GPUTextureUsage.TEXTURE_BINDING });
  await refused({ ...gbuffer.channels, normal: sampledOnly }, 'channel-usage', ['`normal`', 'STORAGE_BINDING']);
});
