// The refine mask for a page: `Shader.refineMask()` is a texture its own
// passes can sample (TEXTURE_BINDING), `decodeRefineMask` says which
// effects a pixel evaluated (and agrees with the statistics' counts), and
// `refineHeatmap` paints it as the playground does.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { applyUniforms, decodeRefineMask, loadGBuffer, loadProgram, readTexture, refineHeatmap, refineMaskBit, Shader } from '../dist/index.js';
import { testDevice } from './support/gpu.mjs';
import { mrslc } from './support/mrslc.mjs';
import { SIZE, bytes } from './support/fixtures.mjs';

let gpu;
let dir;
let shader;
let gbuffer;
let rendered;

before(async () => {
  gpu = await testDevice();
  if (gpu.skip) return;
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-mask-'));
  mrslc(['compile', 'examples/demo.mrsl', '--mode', 'coarse4x4', '-o', join(dir, 'kernels')]);
  mrslc(['gbuffer', '--scene', 'demo', '--size', `${SIZE[0]}x${SIZE[1]}`, '-o', join(dir, 'gbuffer'), 'examples/demo.mrsl']);
  shader = await Shader.create(gpu.device, await loadProgram((f) => readFile(join(dir, 'kernels', f), 'utf8'), 'demo'));
  const manifest = JSON.parse(await readFile(join(dir, 'gbuffer', 'gbuffer.json'), 'utf8'));
  gbuffer = await loadGBuffer(gpu.device, manifest, (f) => bytes(join(dir, 'gbuffer', f)));
  applyUniforms(shader, manifest);
  const color = gpu.device.createTexture({ size: SIZE, format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC });
  const encoder = gpu.device.createCommandEncoder();
  shader.encode(encoder, { size: SIZE, channels: gbuffer.channels, textures: gbuffer.textures, samplers: gbuffer.samplers, outputs: { color } }, { mode: 'coarse4x4' });
  gpu.device.queue.submit([encoder.finish()]);
  const mask = shader.refineMask();
  rendered = { stats: await shader.readStats(), mask, maskTexels: await readTexture(gpu.device, mask), image: await readTexture(gpu.device, color) };
});
after(() => dir && rmSync(dir, { recursive: true, force: true }));

const skip = (t) => gpu.skip && (t.skip(gpu.skip), true);

test('a pass of the page samples the refine mask: the texels it reads are the mask', async (t) => {
  if (skip(t)) return;
  const device = gpu.device;
  const [w, h] = SIZE;
  assert.ok(rendered.mask.usage & GPUTextureUsage.TEXTURE_BINDING, 'the refine mask has TEXTURE_BINDING');
  const module = device.createShaderModule({
    code: `@group(0) @binding(0) var mask: texture_2d<u32>;
@group(0) @binding(1) var<storage, read_write> out: array<vec2u>;
@compute @workgroup_size(8, 8) fn main(@builtin(global_invocation_id) id: vec3u) {
  if (id.x < ${w}u && id.y < ${h}u) { out[id.y * ${w}u + id.x] = textureLoad(mask, id.xy, 0).xy; }
}`,
  });
  const pipeline = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: 'main' } });
  const out = device.createBuffer({ size: 8 * w * h, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC });
  const read = device.createBuffer({ size: 8 * w * h, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
  device.pushErrorScope('validation');
  const group = device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries: [{ binding: 0, resource: rendered.mask.createView() }, { binding: 1, resource: { buffer: out } }] });
  const encoder = device.createCommandEncoder();
  const pass = encoder.beginComputePass();
  pass.setPipeline(pipeline);
  pass.setBindGroup(0, group);
  pass.dispatchWorkgroups(Math.ceil(w / 8), Math.ceil(h / 8));
  pass.end();
  encoder.copyBufferToBuffer(out, 0, read, 0, 8 * w * h);
  device.queue.submit([encoder.finish()]);
  const error = await device.popErrorScope();
  assert.equal(error, null, `the device refused sampling the mask: ${error?.message}`);
  await read.mapAsync(GPUMapMode.READ);
  assert.deepEqual(new Uint8Array(read.getMappedRange().slice(0)), rendered.maskTexels);
  read.unmap();
});

test('decoded, the mask counts per effect the pixels the statistics count', (t) => {
  if (skip(t)) return;
  const layout = shader.layout;
  const words = new Uint32Array(rendered.maskTexels.buffer, rendered.maskTexels.byteOffset, rendered.maskTexels.byteLength / 4);
  const perPixel = new Map();
  let background = 0;
  for (let i = 0; i < words.length; i += 2) {
    const texel = decodeRefineMask(layout, [words[i], words[i + 1]]);
    if (texel.background) background++;
    else for (const name of texel.perPixel) perPixel.set(name, (perPixel.get(name) ?? 0) + 1);
  }
  const coarse = rendered.stats.effects.filter((e) => e.rate === 'coarse');
  assert.ok(coarse.length > 0 && coarse.some((e) => e.pixelEvaluations > 0), 'the demo refines some coarse effect');
  for (const e of coarse) assert.equal(perPixel.get(e.name) ?? 0, e.pixelEvaluations, `${e.name}: pixels with its bit against its counter`);
  assert.equal(background, rendered.stats.backgroundPixels, 'background texels against the background counter');
  const name = layout.stats.counters[0];
  assert.deepEqual(decodeRefineMask(layout, [1 << refineMaskBit(layout, name), 0]), { background: false, perPixel: [name], from2x2: [] });
  assert.deepEqual(decodeRefineMask(layout, layout.plan.constants.background_mark), { background: true });
  assert.equal(refineMaskBit(layout, 'no such effect'), null);
});

test('the heatmap: red where every coarse effect was evaluated per pixel, grey on the background', (t) => {
  if (skip(t)) return;
  const layout = shader.layout;
  const heat = refineHeatmap(layout, rendered.maskTexels, rendered.image);
  assert.equal(heat.length, 4 * SIZE[0] * SIZE[1]);
  const words = new Uint32Array(rendered.maskTexels.buffer, rendered.maskTexels.byteOffset, rendered.maskTexels.byteLength / 4);
  const all = (1 << layout.stats.counters.length) - 1;
  const mark = layout.plan.constants.background_mark;
  let checked = 0;
  for (let i = 0; i < words.length / 2; i++) {
    const rgba = [...heat.subarray(4 * i, 4 * i + 4)];
    if (words[2 * i] === mark[0] && words[2 * i + 1] === mark[1]) assert.deepEqual(rgba, [150, 150, 150, 255]);
    else if (words[2 * i] === all) assert.deepEqual(rgba, [255, 0, 0, 255]);
    else continue;
    checked++;
  }
  assert.ok(checked > 0, 'some pixels are background or refined in every coarse effect');
});
