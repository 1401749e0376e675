// Every example in every mode, rendered by the web runtime on Dawn over the
// G-buffer `mrslc gbuffer` exported, against the Rust runtime's image of the
// same kernels and G-buffer (`mrslc render --raw`); and in every adaptive
// mode, forced refinement against the web runtime's own reference.
import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFile } from 'node:fs/promises';
import { join } from 'node:path';
import { applyUniforms, loadGBuffer, loadProgram, MODES, readTexture, Shader, uniformRateImage } from '../dist/index.js';
import { testDevice } from './support/gpu.mjs';
import { SIZE, UNIFORM_RATE, bytes, cleanup, examples, fixturesRoot, makeFixtures } from './support/fixtures.mjs';
import { compareImages, TOLERANCE } from './support/compare.mjs';

const list = examples();
let gpu;
let root;

before(async () => {
  gpu = await testDevice();
  if (!gpu.skip) root = fixturesRoot();
});
after(() => cleanup(root));

/** Renders `mode` and reads every output back, by name. */
async function render(device, shader, gbuffer, mode, forceRefine) {
  const outputs = {};
  for (const o of shader.layout.outputs) {
    outputs[o.name] = device.createTexture({ size: SIZE, format: o.format, usage: GPUTextureUsage.STORAGE_BINDING | GPUTextureUsage.COPY_SRC });
  }
  const bindings = {
    size: SIZE,
    channels: gbuffer.channels,
    textures: gbuffer.textures,
    samplers: gbuffer.samplers,
    outputs,
    shadingRate: uniformRateImage(device, SIZE, 8, UNIFORM_RATE),
  };
  const encoder = device.createCommandEncoder();
  shader.encode(encoder, bindings, { mode, forceRefine });
  device.queue.submit([encoder.finish()]);
  const images = {};
  for (const o of shader.layout.outputs) {
    images[o.name] = await readTexture(device, outputs[o.name]);
    outputs[o.name].destroy();
  }
  return { images, stats: await shader.readStats() };
}

for (const { name, scene } of list) {
  describe(`${name} over ${scene}`, () => {
    let shader;
    let gbuffer;
    let rustStats;
    let reference;
    let instead;
    const dir = () => join(root, name);

    // Each example's fixtures in its own hook, so that one example's
    // failure fails its tests and not every example's.
    before(async () => {
      if (gpu.skip) return;
      ({ instead } = makeFixtures(root, { name, scene }));
      const program = await loadProgram((f) => readFile(join(dir(), 'kernels', f), 'utf8'), name);
      const manifest = JSON.parse(await readFile(join(dir(), 'gbuffer', 'gbuffer.json'), 'utf8'));
      gbuffer = await loadGBuffer(gpu.device, manifest, (f) => bytes(join(dir(), 'gbuffer', f)));
      shader = await Shader.create(gpu.device, program);
      applyUniforms(shader, manifest);
      rustStats = JSON.parse(await readFile(join(dir(), 'rust', `${name}.stats.json`), 'utf8'));
    });

    for (const mode of MODES) {
      test(`${mode} matches the Rust runtime`, async (t) => {
        if (gpu.skip) return t.skip(gpu.skip);
        if (instead) t.diagnostic(instead);
        const { images, stats } = await render(gpu.device, shader, gbuffer, mode, false);
        if (mode === 'reference') reference = images;
        for (const o of shader.layout.outputs) {
          const rust = new Uint8Array(await bytes(join(dir(), 'rust', `${name}.${mode}.${o.name}.bin`)));
          const report = compareImages(images[o.name], rust, o.format);
          t.diagnostic(`${o.name}: ${report.summary}`);
          assert.ok(report.withinTolerance, `${name} ${mode} ${o.name}: ${report.summary}; tolerance ${TOLERANCE.describe}`);
        }
        const rust = rustStats.find((s) => s.mode === mode);
        assert.ok(rust, `the Rust statistics have ${mode}`);
        t.diagnostic(`shaded fraction web ${stats.shadedFraction.toFixed(4)}, Rust ${rust.shaded_fraction.toFixed(4)}`);
      });

      if (mode === 'reference') continue;
      test(`${mode} forced equals the reference`, async (t) => {
        if (gpu.skip) return t.skip(gpu.skip);
        assert.ok(reference, 'the reference rendered first');
        const { images } = await render(gpu.device, shader, gbuffer, mode, true);
        for (const o of shader.layout.outputs) {
          const differing = countDiffering(images[o.name], reference[o.name]);
          assert.equal(differing, 0, `${name} ${mode} forced: ${differing} bytes of ${o.name} differ from the reference`);
          const rust = new Uint8Array(await bytes(join(dir(), 'rust-forced', `${name}.${mode}.${o.name}.bin`)));
          const report = compareImages(images[o.name], rust, o.format);
          assert.ok(report.withinTolerance, `${name} ${mode} forced vs Rust forced: ${report.summary}`);
        }
      });
    }
  });
}

function countDiffering(a, b) {
  assert.equal(a.length, b.length);
  let n = 0;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) n++;
  return n;
}
