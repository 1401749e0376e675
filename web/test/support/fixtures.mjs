// The fixtures the comparison tests read, made by the Rust side: for an
// example, its kernels (`mrslc compile`), the G-buffer of its scene with
// what the program binds (`mrslc gbuffer`), and the Rust runtime's image of
// every mode, adaptive and forced (`mrslc render --raw`), on the same
// driver as Dawn (SwiftShader) where it is installed. Written under a
// temporary directory, removed by `cleanup`.
import { existsSync, mkdtempSync, readdirSync, rmSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { mrslc, REPO } from './mrslc.mjs';
import { SWIFTSHADER_ICD } from './gpu.mjs';

/** A file's bytes as an `ArrayBuffer` (what `loadGBuffer` reads). */
export async function bytes(path) {
  const b = await readFile(path);
  return b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength);
}

/** The image size: odd on both axes, so every mode's partial tiles and blocks are exercised. */
export const SIZE = [61, 37];

/**
 * The scene each example is written for (README.md's per-example table, and
 * the playground's list in cli/src/serve/api.rs); the others run on the demo scene.
 */
const SCENES = { sponza_lights: 'sponza', pbr_deferred: 'dungeon', many_lights: 'sponza' };

/**
 * The scenes whose files are fetched separately (docs/scenes.md), with the
 * script that fetches each. Where one is not fetched, its examples run over
 * Sponza instead (a mesh scene too, so it binds the same light rig, and its
 * model comes with the cargo registry), and their tests say so: the
 * comparison is between two runtimes over one G-buffer, which any mesh scene
 * exercises, so an unfetched model narrows the scenes covered, not the examples.
 */
const FETCHED = { dungeon: 'scripts/fetch-dungeon.sh' };
const FETCHED_FALLBACK = 'sponza';

/** The rate every tile of the rate-image mode gets (a uniform rate image, so both runtimes bind the same one). */
export const UNIFORM_RATE = [2, 2];

export function examples() {
  return readdirSync(join(REPO, 'examples'))
    .filter((f) => f.endsWith('.mrsl'))
    .map((f) => f.slice(0, -'.mrsl'.length))
    .sort()
    .map((name) => ({ name, scene: SCENES[name] ?? 'demo' }));
}

/** A temporary directory for the fixtures. */
export function fixturesRoot() {
  return mkdtempSync(join(tmpdir(), 'mrsl-web-fixtures-'));
}

/**
 * Makes one example's fixtures under `root`/`name`. Returns the scene they
 * are over and, where that is not the example's own scene, why not.
 */
export function makeFixtures(root, { name, scene }) {
  const size = `${SIZE[0]}x${SIZE[1]}`;
  const env = existsSync(SWIFTSHADER_ICD) ? { VK_ICD_FILENAMES: SWIFTSHADER_ICD } : {};
  const program = join('examples', `${name}.mrsl`);
  const dir = join(root, name);
  mrslc(['compile', program, '-o', join(dir, 'kernels')]);
  const gbuffer = (over) => mrslc(['gbuffer', '--scene', over, '--size', size, '-o', join(dir, 'gbuffer'), program], env);
  let used = { scene, instead: null };
  try {
    gbuffer(scene);
  } catch (e) {
    const missing = notFetched(scene, e);
    if (!missing) throw e;
    used = { scene: FETCHED_FALLBACK, instead: `${missing}; over ${FETCHED_FALLBACK} instead` };
    gbuffer(FETCHED_FALLBACK);
  }
  const render = ['render', program, '--scene', used.scene, '--size', size, '--mode', 'all', '--raw', '--uniform-rate', `${UNIFORM_RATE[0]}x${UNIFORM_RATE[1]}`];
  mrslc([...render, '--out', join(dir, 'rust')], env);
  mrslc([...render, '--force-refine', '--out', join(dir, 'rust-forced')], env);
  return used;
}

/**
 * Why `scene` could not be loaded, where `error` (a failed mrslc) says it is
 * a separately fetched scene whose files are not there; null for any other
 * failure, which the test reports as it is.
 */
function notFetched(scene, error) {
  const script = FETCHED[scene];
  const stderr = String(error.stderr ?? '');
  // mrslc's message for a missing model names the script that fetches it.
  if (!script || !stderr.includes(`not found; run ${script}`)) return null;
  return `the ${scene} scene is not fetched (run ${script})`;
}

export function cleanup(root) {
  if (root) rmSync(root, { recursive: true, force: true });
}
