// What a page binds wrong gets a typed MrslError naming the binding at
// fault, thrown before anything is recorded into its encoder.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, unlinkSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { loadProgram, MODES, MrslError, parseLayout, Shader } from '../dist/index.js';
import { freshAdapter, testDevice } from './support/gpu.mjs';
import { mrslc } from './support/mrslc.mjs';

const SIZE = [40, 24];
let gpu;
let dir;
let shader;
let referenceOnly;
let packed;

before(async () => {
  gpu = await testDevice();
  if (gpu.skip) return;
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-errors-'));
  mrslc(['compile', 'examples/demo.mrsl', '-o', join(dir, 'all')]);
  mrslc(['compile', 'examples/demo.mrsl', '--mode', 'reference', '-o', join(dir, 'reference')]);
  const load = (sub) => loadProgram((f) => readFile(join(dir, sub, f), 'utf8'), 'demo');
  shader = await Shader.create(gpu.device, await load('all'));
  referenceOnly = await Shader.create(gpu.device, await load('reference'));
  mrslc(['compile', 'examples/demo.mrsl', '--packed-records', '-o', join(dir, 'packed')]);
  packed = await Shader.create(gpu.device, await load('packed'));
});
after(() => dir && rmSync(dir, { recursive: true, force: true }));

const usage = { sampled: GPUTextureUsage.TEXTURE_BINDING, storage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC };

/** Bindings that are right for the demo program at SIZE, with `change` applied. */
function bindings(change = {}) {
  const device = gpu.device;
  const channels = {};
  for (const c of shader.layout.channels) channels[c.name] = device.createTexture({ size: SIZE, format: c.format, usage: usage.sampled });
  const outputs = {};
  for (const o of shader.layout.outputs) outputs[o.name] = device.createTexture({ size: SIZE, format: o.format, usage: usage.storage });
  const shadingRate = device.createTexture({ size: [5, 3], format: 'r8uint', usage: usage.sampled });
  return { size: SIZE, channels, outputs, shadingRate, ...change(channels, outputs) };
}

/** Asserts that `encode` throws an MrslError of `kind` mentioning `words`, and records nothing. */
async function refused(s, b, options, kind, words) {
  const device = gpu.device;
  const encoder = device.createCommandEncoder();
  device.pushErrorScope('validation');
  assert.throws(
    () => s.encode(encoder, b, options),
    (e) => e instanceof MrslError && e.kind === kind && words.every((w) => e.message.includes(w)) && (console.log(`  ${kind}: ${e.message}`), true),
  );
  device.queue.submit([encoder.finish()]);
  assert.equal(await device.popErrorScope(), null, 'the encoder is still valid: nothing was recorded');
}

const skip = (t) => gpu.skip && (t.skip(gpu.skip), true);

test('a right binding renders', async (t) => {
  if (skip(t)) return;
  const encoder = gpu.device.createCommandEncoder();
  gpu.device.pushErrorScope('validation');
  shader.encode(encoder, bindings(() => ({})), { mode: 'coarse4x4' });
  gpu.device.queue.submit([encoder.finish()]);
  assert.equal(await gpu.device.popErrorScope(), null);
  const stats = await shader.readStats();
  assert.equal(stats.mode, 'coarse4x4');
  assert.ok(stats.coarseSamples > 0);
});

test('a missing channel is named', async (t) => {
  if (skip(t)) return;
  const b = bindings((channels) => (delete channels.normal, {}));
  await refused(shader, b, { mode: 'reference' }, 'missing-channel', ['`normal`']);
});

test('a channel of the wrong format says which formats it takes', async (t) => {
  if (skip(t)) return;
  const position = gpu.device.createTexture({ size: SIZE, format: 'r32float', usage: usage.sampled });
  const b = bindings((channels) => ({ channels: { ...channels, position } }));
  await refused(shader, b, { mode: 'reference' }, 'channel-format', ['`position`', 'r32float', 'rgba32float', 'exactly 4']);
  const depth = gpu.device.createTexture({ size: SIZE, format: 'depth32float', usage: usage.sampled });
  await refused(shader, bindings((channels) => ({ channels: { ...channels, position: depth } })), { mode: 'reference' }, 'channel-format', ['depth']);
});

test('a channel without TEXTURE_BINDING, or of another size, is refused', async (t) => {
  if (skip(t)) return;
  const copyOnly = gpu.device.createTexture({ size: SIZE, format: 'rgba32float', usage: GPUTextureUsage.COPY_DST });
  await refused(shader, bindings((c) => ({ channels: { ...c, normal: copyOnly } })), { mode: 'reference' }, 'channel-usage', ['`normal`', 'TEXTURE_BINDING']);
  const small = gpu.device.createTexture({ size: [8, 8], format: 'rgba32float', usage: usage.sampled });
  await refused(shader, bindings((c) => ({ channels: { ...c, normal: small } })), { mode: 'reference' }, 'size-mismatch', ['`normal`', '8x8', '40x24']);
});

test('outputs: the layout format and STORAGE_BINDING', async (t) => {
  if (skip(t)) return;
  const rgba8 = gpu.device.createTexture({ size: SIZE, format: 'rgba8unorm', usage: usage.storage });
  await refused(shader, bindings(() => ({ outputs: { color: rgba8 } })), { mode: 'reference' }, 'output-format', ['`color`', 'rgba32float', 'rgba8unorm']);
  const sampledOnly = gpu.device.createTexture({ size: SIZE, format: 'rgba32float', usage: usage.sampled });
  await refused(shader, bindings(() => ({ outputs: { color: sampledOnly } })), { mode: 'reference' }, 'output-usage', ['STORAGE_BINDING']);
  await refused(shader, bindings(() => ({ outputs: {} })), { mode: 'reference' }, 'missing-output', ['`color`']);
});

test('sizes: empty, past the largest side', async (t) => {
  if (skip(t)) return;
  await refused(shader, bindings(() => ({ size: [0, 24] })), { mode: 'reference' }, 'bad-size', ['empty']);
  const side = shader.layout.plan.constants.max_side;
  await refused(shader, bindings(() => ({ size: [side + 1, 24] })), { mode: 'reference' }, 'bad-size', [`${side}`]);
  const deviceSide = gpu.device.limits.maxTextureDimension2D;
  if (deviceSide < side) {
    const over = [deviceSide + 1, 24];
    await refused(shader, bindings(() => ({ size: over })), { mode: 'reference' }, 'bad-size', ['maxTextureDimension2D', `${deviceSide}`]);
  }
});

test('modes: unknown, and not compiled', async (t) => {
  if (skip(t)) return;
  await refused(shader, bindings(() => ({})), { mode: 'coarse8x8' }, 'unknown-mode', ['coarse8x8', 'coarse4x4']);
  await refused(referenceOnly, bindings(() => ({})), { mode: 'coarse4x4' }, 'unsupported-mode', ['coarse4x4', 'plan']);
  assert.deepEqual(referenceOnly.modes(), ['reference']);
  assert.deepEqual(shader.modes(), MODES);
});

test('packed records: the hierarchical mode needs texture-formats-tier2, and the other modes run without it', async (t) => {
  if (skip(t)) return;
  if (gpu.device.features.has('texture-formats-tier2')) {
    packed.supports('hierarchical');
    return;
  }
  const words = ['hierarchical', 'texture-formats-tier2', '--packed-records'];
  await refused(packed, bindings(() => ({})), { mode: 'hierarchical' }, 'unsupported-mode', words);
  assert.deepEqual(packed.modes(), MODES.filter((m) => m !== 'hierarchical'));
});

test('the rate-image mode: its image bound, of the right size and format, and a tile size it has', async (t) => {
  if (skip(t)) return;
  await refused(shader, bindings(() => ({ shadingRate: undefined })), { mode: 'rate-image' }, 'missing-shading-rate', ['shading-rate image']);
  const wrong = gpu.device.createTexture({ size: [4, 3], format: 'r8uint', usage: usage.sampled });
  await refused(shader, bindings(() => ({ shadingRate: wrong })), { mode: 'rate-image' }, 'rate-image-size', ['4x3', '5x3']);
  const float = gpu.device.createTexture({ size: [5, 3], format: 'r32float', usage: usage.sampled });
  await refused(shader, bindings(() => ({ shadingRate: float })), { mode: 'rate-image' }, 'rate-format', ['r32float']);
  await refused(shader, bindings(() => ({})), { mode: 'rate-image', rateTile: 4 }, 'bad-tile-size', ['4']);
});

test('uniforms: the name, the count and each value are checked', (t) => {
  if (skip(t)) return;
  const kind = (f) => {
    try {
      f();
    } catch (e) {
      assert.ok(e instanceof MrslError, String(e));
      return [e.kind, e.message];
    }
    assert.fail('no error');
  };
  assert.deepEqual(kind(() => shader.setUniform('nope', 1)), ['unknown-uniform', 'the program has no uniform `nope`']);
  assert.equal(kind(() => shader.setUniform('camera_pos', [1, 2]))[0], 'uniform-components');
  assert.match(kind(() => shader.setUniform('ambient', NaN))[1], /`ambient` is `float`, but its value NaN is not a finite number/);
  assert.match(kind(() => shader.setUniform('sun_dir', [0, 1e39, 0]))[1], /component 1, 1e\+39, is beyond the range/);
  shader.setUniform('ambient', 0.5);
  assert.deepEqual(shader.uniform('ambient'), [0.5]);
});

test('statistics off: readStats says so', async (t) => {
  if (skip(t)) return;
  const encoder = gpu.device.createCommandEncoder();
  shader.encode(encoder, bindings(() => ({})), { mode: 'reference', statistics: false });
  gpu.device.queue.submit([encoder.finish()]);
  await assert.rejects(shader.readStats(), (e) => e.kind === 'statistics-off');
});

test('a layout without a plan is refused', () => {
  assert.throws(() => parseLayout('{"format": "mrsl-layout/5"}'), (e) => e instanceof MrslError && /current mrslc/.test(e.message));
});

test('a view where a texture goes, and a size as {width, height}, say how to pass them', async (t) => {
  if (skip(t)) return;
  const view = (c) => ({ channels: { ...c, normal: c.normal.createView() } });
  await refused(shader, bindings(view), { mode: 'reference' }, 'not-a-texture', ['`normal`', 'GPUTextureView', 'GPUTexture itself']);
  const outputView = (c, o) => ({ outputs: { color: o.color.createView() } });
  await refused(shader, bindings(outputView), { mode: 'reference' }, 'not-a-texture', ['`color`', 'GPUTextureView']);
  const object = () => ({ size: { width: SIZE[0], height: SIZE[1] } });
  await refused(shader, bindings(object), { mode: 'reference' }, 'bad-size', ['[width, height]', '{width, height}']);
});

test('encode without options, or without a mode, names the option', async (t) => {
  if (skip(t)) return;
  await refused(shader, bindings(() => ({})), undefined, 'bad-option', ['mode', "{ mode: 'reference' }"]);
  await refused(shader, bindings(() => ({})), {}, 'bad-option', ['no `mode`']);
});

test('an output of another format gets the `@format` declaration that writes it', async (t) => {
  if (skip(t)) return;
  const half = gpu.device.createTexture({ size: SIZE, format: 'rgba16float', usage: usage.storage });
  await refused(shader, bindings(() => ({ outputs: { color: half } })), { mode: 'reference' }, 'output-format', [
    'rgba32float',
    '`@format(rgba16float) fine out float4 color`',
  ]);
  const bgra = gpu.device.createTexture({ size: SIZE, format: 'bgra8unorm', usage: usage.storage });
  await refused(shader, bindings(() => ({ outputs: { color: bgra } })), { mode: 'reference' }, 'output-format', ['create it as rgba32float', 'rgba16float, rgba8unorm']);
});

test('a program past the device\'s storage-texture limit: supports names the limit', async (t) => {
  if (skip(t)) return;
  mrslc(['compile', 'examples/demo.mrsl', '--storage-channels', '--mode', 'reference,coarse4x4', '-o', join(dir, 'storage')]);
  const storage = await Shader.create(gpu.device, await loadProgram((f) => readFile(join(dir, 'storage', f), 'utf8'), 'demo'));
  const limit = gpu.device.limits.maxStorageTexturesPerShaderStage;
  for (const mode of ['reference', 'coarse4x4']) {
    assert.throws(
      () => storage.supports(mode),
      (e) => e instanceof MrslError && e.kind === 'unsupported-mode' && e.message.includes(`maxStorageTexturesPerShaderStage, ${limit}`) && /--storage-channels/.test(e.message),
    );
  }
  assert.deepEqual(storage.modes(), []);
});

test('a texture of another device: encode\'s promise rejects with foreign-device', async (t) => {
  if (skip(t)) return;
  const other = await (await freshAdapter()).requestDevice();
  try {
    const normal = other.createTexture({ size: SIZE, format: 'rgba32float', usage: usage.sampled });
    const b = bindings((c) => ({ channels: { ...c, normal } }));
    const encoder = gpu.device.createCommandEncoder();
    await assert.rejects(shader.encode(encoder, b, { mode: 'reference' }), (e) => e instanceof MrslError && e.kind === 'foreign-device' && /Shader.create/.test(e.message));
  } finally {
    other.destroy();
  }
  // A right encode still resolves.
  const encoder = gpu.device.createCommandEncoder();
  await shader.encode(encoder, bindings(() => ({})), { mode: 'reference' });
  gpu.device.queue.submit([encoder.finish()]);
});

/** Serves `root` over HTTP (404 for what is not there); resolves with its base URL and a close function. */
async function serveFiles(root) {
  const server = createServer(async (request, response) => {
    try {
      const body = await readFile(join(root, decodeURIComponent(new URL(request.url, 'http://x').pathname)));
      response.writeHead(200).end(body);
    } catch {
      response.writeHead(404, { 'content-type': 'text/html' }).end('<!DOCTYPE html><title>404 Not Found</title>');
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { url: `http://127.0.0.1:${server.address().port}/`, close: () => server.close() };
}

test('loadProgram: a wrong stem, a missing kernel or an error page name the file and the HTTP status', async (t) => {
  if (skip(t)) return;
  const fails = (promise, words) =>
    assert.rejects(promise, (e) => e instanceof MrslError && e.kind === 'program-file' && words.every((w) => e.message.includes(w)) && (console.log(`  program-file: ${e.message}`), true));
  mrslc(['compile', 'examples/demo.mrsl', '--mode', 'reference,coarse4x4', '-o', join(dir, 'served')]);
  unlinkSync(join(dir, 'served', 'demo.tile.b4.wgsl'));
  const server = await serveFiles(dir);
  try {
    const program = await loadProgram(`${server.url}all`, 'demo');
    assert.ok(program.kernels.length > 0, 'a served directory loads by its URL');
    await fails(loadProgram(`${server.url}served/`, 'demo'), ['`demo.tile.b4.wgsl`', 'HTTP 404', 'coarse4x4', '--mode']);
    await fails(loadProgram(`${server.url}all/`, 'dem'), ['`dem.layout.json`', 'HTTP 404', 'the stem']);
    await fails(loadProgram((f) => fetch(`${server.url}all/${f}`), 'dem'), ['HTTP 404']);
    // The text of a server's error page, as `fetch(...).then((r) => r.text())` gives it.
    await fails(loadProgram((f) => fetch(`${server.url}all/${f}`).then((r) => r.text()), 'dem'), ['`dem.layout.json`', 'HTML page']);
    await fails(loadProgram((f) => readFile(join(dir, 'all', f), 'utf8'), 'dem'), ['`dem.layout.json`', 'ENOENT']);
  } finally {
    server.close();
  }
});
