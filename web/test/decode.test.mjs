// Channels the kernels decode from what an engine stores: a position
// rebuilt from a depth texture (`@depth`), bound through its depth aspect,
// and checked to be a depth texture.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { loadProgram, MrslError, readTexture, Shader } from '../dist/index.js';
import { testDevice } from './support/gpu.mjs';
import { mrslc } from './support/mrslc.mjs';

const SIZE = [13, 7];
const PROGRAM = `uniform float4x4 inverse_view_proj;
@depth(inverse_view_proj) in float3 position;
fine out float4 color = float4(position, 1.0);
`;
let gpu;
let dir;
let shader;

before(async () => {
  gpu = await testDevice();
  if (gpu.skip) return;
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-decode-'));
  writeFileSync(join(dir, 'depth.mrsl'), PROGRAM);
  mrslc(['compile', join(dir, 'depth.mrsl'), '--mode', 'reference', '-o', join(dir, 'out')]);
  shader = await Shader.create(gpu.device, await loadProgram((f) => readFile(join(dir, 'out', f), 'utf8'), 'depth'));
});
after(() => dir && rmSync(dir, { recursive: true, force: true }));

/** A depth texture every texel of which is `depth` (a render pass's clear: WebGPU copies no data into depth32float). */
function depthTexture(device, format, depth) {
  const texture = device.createTexture({ size: SIZE, format, usage: GPUTextureUsage.TEXTURE_BINDING | GPUTextureUsage.RENDER_ATTACHMENT });
  const encoder = device.createCommandEncoder();
  const stencil = format.includes('stencil') ? { stencilLoadOp: 'clear', stencilStoreOp: 'store', stencilClearValue: 0 } : {};
  encoder
    .beginRenderPass({ colorAttachments: [], depthStencilAttachment: { view: texture.createView(), depthClearValue: depth, depthLoadOp: 'clear', depthStoreOp: 'store', ...stencil } })
    .end();
  device.queue.submit([encoder.finish()]);
  return texture;
}

function output(device) {
  return device.createTexture({ size: SIZE, format: 'rgba32float', usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC });
}

test('a position rebuilt from depth is the pixel centre unprojected', async (t) => {
  if (gpu.skip) return t.skip(gpu.skip);
  // The identity as the inverse view-projection: the position is the clip-space point itself.
  shader.setUniform('inverse_view_proj', [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  for (const format of ['depth32float', 'depth24plus-stencil8']) {
    const color = output(gpu.device);
    const encoder = gpu.device.createCommandEncoder();
    shader.encode(encoder, { size: SIZE, channels: { position: depthTexture(gpu.device, format, 0.25) }, outputs: { color } }, { mode: 'reference' });
    gpu.device.queue.submit([encoder.finish()]);
    const texels = new Float32Array((await readTexture(gpu.device, color)).buffer);
    for (let y = 0; y < SIZE[1]; y++) {
      for (let x = 0; x < SIZE[0]; x++) {
        const i = 4 * (y * SIZE[0] + x);
        const expected = [(2 * (x + 0.5)) / SIZE[0] - 1, 1 - (2 * (y + 0.5)) / SIZE[1], 0.25];
        for (let c = 0; c < 3; c++) assert.ok(Math.abs(texels[i + c] - expected[c]) < 1e-6, `${format} pixel ${x},${y}: ${texels[i + c]} against ${expected[c]}`);
      }
    }
  }
});

test('a depth channel takes a depth texture', (t) => {
  if (gpu.skip) return t.skip(gpu.skip);
  const colour = gpu.device.createTexture({ size: SIZE, format: 'r32float', usage: GPUTextureUsage.TEXTURE_BINDING });
  const encoder = gpu.device.createCommandEncoder();
  assert.throws(
    () => shader.encode(encoder, { size: SIZE, channels: { position: colour }, outputs: { color: output(gpu.device) } }, { mode: 'reference' }),
    (e) => e instanceof MrslError && e.kind === 'channel-format' && /rebuilt from depth/.test(e.message) && /r32float/.test(e.message),
  );
});
