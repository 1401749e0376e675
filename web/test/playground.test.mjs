// The playground in a real browser: headless Chromium (Debian's package,
// driven by playwright-core) opens the page `mrslc serve` serves, waits for
// its first image, edits the program in the editor, and checks the canvas
// against the Rust runtime's PNG of the edited program; then breaks the
// program and checks its diagnostics show in the page. Also checks that
// the committed bundle (web/playground/dist/) is the one the sources build.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { execFileSync } from 'node:child_process';
import { PNG } from 'pngjs';
import { chromium } from 'playwright-core';
import { mrslc, mrslcPath, REPO } from './support/mrslc.mjs';
import { SWIFTSHADER_ICD } from './support/gpu.mjs';

const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
const SIZE = [320, 180];
let dir;
let server;
let browser;
let page;
let skip = null;

/** Starts `mrslc serve --port 0` and resolves with the address it prints. */
function serve() {
  const child = spawn(mrslcPath(), ['serve', '--port', '0'], { cwd: REPO, stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (chunk) => {
      out += chunk;
      const found = /playground: (http:\/\/127\.0\.0\.1:\d+\/)/.exec(out);
      if (found) resolve({ child, url: found[1] });
    });
    child.on('exit', (code) => reject(new Error(`mrslc serve exited (${code}) before listening: ${out}`)));
  });
}

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'mrsl-playground-'));
  if (!existsSync(CHROMIUM)) {
    skip = `no Chromium at ${CHROMIUM} (Debian's chromium package)`;
    if (process.env.CI === 'true') throw new Error(skip);
    console.log(`SKIPPED: ${skip}`);
    return;
  }
  server = await serve();
  // The flags that keep Chromium off the network (this machine has none) and give it WebGPU on SwiftShader.
  const args = ['--no-sandbox', '--enable-unsafe-webgpu', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'];
  browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args });
  page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
});

after(async () => {
  await browser?.close();
  server?.child.kill();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

const state = () => page.evaluate(() => ({ state: document.body.dataset.state, status: document.getElementById('status').textContent, renders: Number(document.body.dataset.renders ?? 0) }));

/** Waits until the page is in `wanted` (or fails with the state it is in), after at least `renders` images. */
async function settle(wanted, renders = 0) {
  await page
    .waitForFunction(
      ([w, r]) => document.body.dataset.state === w && Number(document.body.dataset.renders ?? 0) >= r,
      [wanted, renders],
      { timeout: 120_000, polling: 100 },
    )
    .catch(async () => assert.fail(`the page did not reach ${wanted}: ${JSON.stringify(await state())}`));
}

test('the committed playground bundle is the one its sources build', () => {
  const fresh = join(dir, 'dist');
  execFileSync(process.execPath, [join(REPO, 'web', 'playground', 'build.mjs'), fresh]);
  for (const file of ['index.html', 'playground.css', 'playground.js']) {
    const committed = readFileSync(join(REPO, 'web', 'playground', 'dist', file));
    assert.ok(committed.equals(readFileSync(join(fresh, file))), `web/playground/dist/${file} is stale: run \`npm run build:playground\` in web/`);
  }
});

test('the playground renders in WebGPU, and an edit renders as the Rust runtime does', async (t) => {
  if (skip) return t.skip(skip);
  await page.goto(server.url);
  await settle('rendered', 1);
  const first = await state();
  t.diagnostic(`first image: ${first.status}`);
  const demo = readFileSync(join(REPO, 'examples', 'demo.mrsl'), 'utf8');
  const edited = demo.replace('float3 sky_color = float3(0.35, 0.48, 0.7)', 'float3 sky_color = float3(0.8, 0.45, 0.3)').replace('float light_power = 1.4', 'float light_power = 2.2');
  assert.notEqual(edited, demo, 'the edit applies to examples/demo.mrsl');
  await page.locator('.cm-content').fill(edited);
  await settle('rendered', first.renders + 1);
  const pixels = await page.evaluate(() => {
    const canvas = document.getElementById('image');
    return Array.from(canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data);
  });
  const program = join(dir, 'edited.mrsl');
  writeFileSync(program, edited);
  const png = join(dir, 'edited.png');
  const env = existsSync(SWIFTSHADER_ICD) ? { VK_ICD_FILENAMES: SWIFTSHADER_ICD } : {};
  mrslc(['render', program, '--scene', 'demo', '--size', `${SIZE[0]}x${SIZE[1]}`, '--mode', 'coarse4x4', '-o', png, '--out', dir], env);
  const rust = PNG.sync.read(readFileSync(png));
  assert.deepEqual([rust.width, rust.height], SIZE);
  assert.equal(pixels.length, rust.data.length, 'the canvas is the image size');
  // The page encodes sRGB in double precision, the Rust CLI in single
  // (mrsl_lab::color::linear_to_srgb8): a value within rounding of a half
  // step rounds to neighbouring bytes; and Tint and naga may differ by an
  // ulp (web/README.md). Either moves a channel by at most 1.
  let differing = 0;
  let largest = 0;
  for (let i = 0; i < pixels.length; i++) {
    const d = Math.abs(pixels[i] - rust.data[i]);
    if (d > 0) differing++;
    largest = Math.max(largest, d);
  }
  t.diagnostic(`canvas against the Rust PNG: ${differing} of ${pixels.length} channels differ, by at most ${largest}`);
  assert.ok(largest <= 1, `the canvas differs from the Rust runtime's image by up to ${largest} in a channel`);
  if (process.env.MRSL_PLAYGROUND_SCREENSHOT) await page.screenshot({ path: process.env.MRSL_PLAYGROUND_SCREENSHOT });
});

test('hovering an effect shows its rate and cost; completion offers names and builtins', async (t) => {
  if (skip) return t.skip(skip);
  const demo = readFileSync(join(REPO, 'examples', 'demo.mrsl'), 'utf8');
  await page.locator('.cm-content').fill(demo);
  const where = (text, into) =>
    page.evaluate(([text, into]) => {
      const view = window.mrslEditor;
      const at = view.state.doc.toString().indexOf(text) + into;
      view.dispatch({ effects: [], scrollIntoView: true, selection: { anchor: at } });
      const box = view.coordsAtPos(at);
      return { x: (box.left + box.right) / 2 + 2, y: (box.top + box.bottom) / 2, at };
    }, [text, into]);
  const name = await where('coarse effect float3 lights', 'coarse effect float3 l'.length);
  await page.mouse.move(name.x, name.y);
  const tooltip = page.locator('.cm-tooltip-hover .mrsl-hover');
  await tooltip.waitFor({ timeout: 30_000 });
  const text = await tooltip.textContent();
  assert.match(text, /coarse effect float3 lights/, text);
  assert.match(text, /operations/, text);
  if (process.env.MRSL_HOVER_SCREENSHOT) await page.screenshot({ path: process.env.MRSL_HOVER_SCREENSHOT });
  await page.mouse.move(0, 0);
  // Typing `satu` offers the builtin `saturate`, with its doc.
  await page.evaluate(() => {
    const view = window.mrslEditor;
    const end = view.state.doc.length;
    view.dispatch({ changes: { from: end, insert: '\nconst float probe = satu' }, selection: { anchor: end + 25 } });
    view.focus();
  });
  await page.keyboard.press('Control+Space');
  const option = page.locator('.cm-tooltip-autocomplete li', { hasText: 'saturate' });
  await option.first().waitFor({ timeout: 30_000 });
  // Back to the demo, rendered, for the next test.
  await page.keyboard.press('Escape');
  const { renders } = await state();
  await page.locator('.cm-content').fill(demo);
  await settle('rendered', renders + 1);
});

test('a program that does not compile shows its diagnostics in the page', async (t) => {
  if (skip) return t.skip(skip);
  const broken = 'in float3 normal;\nfine out float4 color = float4(normal * undefined_name, 1.0);\n';
  await page.locator('.cm-content').fill(broken);
  await settle('error');
  const shown = await page.evaluate(() => ({
    panel: document.getElementById('diagnostics').textContent,
    marked: document.querySelectorAll('.cm-lintRange-error').length,
  }));
  assert.match(shown.panel, /error\[E\d{4}\]/, 'the rendered diagnostic is in the page');
  assert.match(shown.panel, /undefined_name/);
  assert.ok(shown.marked > 0, 'the editor underlines the span');
});
