// The fixtures the comparison tests read, made by the Rust side: for every
// example, its kernels (`mrslc compile`), the G-buffer of its scene with
// what the program binds (`mrslc gbuffer`), and the Rust runtime's image of
// every mode, adaptive and forced (`mrslc render --raw`), on the same
// driver as Dawn (SwiftShader) where it is installed. Written under a
// temporary directory, removed by `cleanup`.
import { mkdtempSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { mrslc, REPO } from './mrslc.mjs';
import { SWIFTSHADER_ICD } from './gpu.mjs';
import { existsSync } from 'node:fs';

/** The image size: odd on both axes, so every mode's partial tiles and blocks are exercised. */
export const SIZE = [61, 37];

/**
 * The scene each example is written for (README.md's per-example table, and
 * the playground's list in cli/src/serve/api.rs); the others run on the demo scene.
 */
const SCENES = { sponza_lights: 'sponza', pbr_deferred: 'dungeon', many_lights: 'sponza' };

/** The rate every tile of the rate-image mode gets (a uniform rate image, so both runtimes bind the same one). */
export const UNIFORM_RATE = [2, 2];

export function examples() {
  return readdirSync(join(REPO, 'examples'))
    .filter((f) => f.endsWith('.mrsl'))
    .map((f) => f.slice(0, -'.mrsl'.length))
    .sort()
    .map((name) => ({ name, scene: SCENES[name] ?? 'demo' }));
}

/** Makes every example's fixtures; returns the directory. */
export function makeFixtures(list) {
  const root = mkdtempSync(join(tmpdir(), 'mrsl-web-fixtures-'));
  const size = `${SIZE[0]}x${SIZE[1]}`;
  const env = existsSync(SWIFTSHADER_ICD) ? { VK_ICD_FILENAMES: SWIFTSHADER_ICD } : {};
  for (const { name, scene } of list) {
    const program = join('examples', `${name}.mrsl`);
    const dir = join(root, name);
    mrslc(['compile', program, '-o', join(dir, 'kernels')]);
    mrslc(['gbuffer', '--scene', scene, '--size', size, '-o', join(dir, 'gbuffer'), program], env);
    const render = ['render', program, '--scene', scene, '--size', size, '--mode', 'all', '--raw', '--uniform-rate', `${UNIFORM_RATE[0]}x${UNIFORM_RATE[1]}`];
    mrslc([...render, '--out', join(dir, 'rust')], env);
    mrslc([...render, '--force-refine', '--out', join(dir, 'rust-forced')], env);
  }
  return root;
}

export function cleanup(root) {
  if (root) rmSync(root, { recursive: true, force: true });
}
