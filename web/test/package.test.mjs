// mrsl-web as a page gets it: `npm pack`'s tarball (built by `prepare`)
// holds the modules, their types and the sources their maps point at; a
// TypeScript project typechecks against it with @webgpu/types and is told
// to install that without; and the complete page of web/README.md's
// "Getting started in a page", with no bundler (an import map), runs 300
// frames in headless Chromium calling readStats() every frame, with no
// error, its canvas the Rust runtime's image.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { extname, join } from 'node:path';
import { PNG } from 'pngjs';
import { chromium } from 'playwright-core';
import { mrslc, REPO } from './support/mrslc.mjs';
import { SWIFTSHADER_ICD } from './support/gpu.mjs';

const WEB = join(REPO, 'web');
const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
/** The size the README's commands export the G-buffer at. */
const SIZE = [320, 180];
let dir;
let packed;

before(() => {
  dir = mkdtempSync(join(tmpdir(), 'mrsl-web-package-'));
  // Runs `prepare` (the build), then packs what `files` lists.
  const out = execFileSync('npm', ['pack', '--json', '--loglevel=error', '--pack-destination', dir], { cwd: WEB, encoding: 'utf8' });
  [packed] = JSON.parse(out.slice(out.indexOf('[')));
});
after(() => dir && rmSync(dir, { recursive: true, force: true }));

/** A project directory with the tarball unpacked as node_modules/mrsl-web. */
function project(name) {
  const root = join(dir, name);
  const into = join(root, 'node_modules', 'mrsl-web');
  mkdirSync(into, { recursive: true });
  execFileSync('tar', ['xzf', join(dir, packed.filename), '-C', into, '--strip-components=1']);
  return root;
}

test('the tarball holds the built modules, their types and the sources their maps point at', () => {
  const files = packed.files.map((f) => f.path);
  for (const file of ['dist/index.js', 'dist/index.d.ts', 'dist/shader.js.map', 'src/shader.ts', 'package.json', 'README.md']) {
    assert.ok(files.includes(file), `${file} is packed (${files.length} files)`);
  }
  assert.ok(!files.some((f) => f.startsWith('test/') || f.startsWith('playground/')), 'neither the tests nor the playground are packed');
  const types = readFileSync(join(WEB, 'dist', 'index.d.ts'), 'utf8');
  assert.match(types, /\/\/\/ <reference types="@webgpu\/types"/, 'the types name the WebGPU types they use');
});

test('a TypeScript project typechecks against the package with @webgpu/types, and is told to install it without', () => {
  const root = project('typescript');
  writeFileSync(
    join(root, 'page.ts'),
    `import { MrslError, Shader, type Bindings } from 'mrsl-web';
export async function frame(device: GPUDevice, shader: Shader, bindings: Bindings): Promise<number> {
  const encoder = device.createCommandEncoder();
  try {
    void shader.encode(encoder, bindings, { mode: 'coarse4x4' });
  } catch (e) {
    if (e instanceof MrslError) console.error(e.kind);
  }
  device.queue.submit([encoder.finish()]);
  return (await shader.readStats()).shadedFraction;
}
`,
  );
  const options = { strict: true, target: 'ES2022', module: 'ES2022', moduleResolution: 'bundler', lib: ['ES2022', 'DOM'], noEmit: true, types: [] };
  writeFileSync(join(root, 'tsconfig.json'), JSON.stringify({ compilerOptions: options, files: ['page.ts'] }));
  const tsc = () => spawnSync(process.execPath, [join(WEB, 'node_modules', 'typescript', 'bin', 'tsc'), '-p', root], { encoding: 'utf8' });
  const without = tsc();
  assert.notEqual(without.status, 0, 'without @webgpu/types the project does not typecheck');
  assert.match(without.stdout, /Cannot find type definition file for '@webgpu\/types'/, 'the error names the package to install');
  mkdirSync(join(root, 'node_modules', '@webgpu'));
  symlinkSync(join(WEB, 'node_modules', '@webgpu', 'types'), join(root, 'node_modules', '@webgpu', 'types'));
  const typed = tsc();
  assert.equal(typed.status, 0, `with @webgpu/types it typechecks:\n${typed.stdout}`);
});

/** The page of README.md's "Getting started in a page": its one HTML block. */
function readmePage() {
  const readme = readFileSync(join(WEB, 'README.md'), 'utf8');
  const section = readme.slice(readme.indexOf('## Getting started in a page'));
  const found = /```html\n([\s\S]*?)```/.exec(section.slice(0, section.indexOf('\n## ', 5)));
  assert.ok(found, 'the section has an html block');
  return found[1];
}

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.json': 'application/json', '.map': 'application/json' };

/** Serves `root` over HTTP, with the content types module scripts need. */
async function serve(root) {
  const server = createServer(async (request, response) => {
    const path = decodeURIComponent(new URL(request.url, 'http://x').pathname);
    if (path === '/favicon.ico') return response.writeHead(204).end();
    try {
      const body = await readFile(join(root, path.endsWith('/') ? `${path}index.html` : path));
      response.writeHead(200, { 'content-type': TYPES[extname(path)] ?? (path.endsWith('/') ? 'text/html' : 'application/octet-stream') }).end(body);
    } catch {
      response.writeHead(404).end();
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { url: `http://127.0.0.1:${server.address().port}/`, close: () => server.close() };
}

test("the README's page runs in Chromium: 300 frames reading their statistics, no error, the Rust runtime's image", async (t) => {
  if (!existsSync(CHROMIUM)) {
    const reason = `no Chromium at ${CHROMIUM} (Debian's chromium package)`;
    if (process.env.CI === 'true') throw new Error(reason);
    return t.skip(reason);
  }
  const root = project('page');
  writeFileSync(join(root, 'index.html'), readmePage());
  // The README's commands.
  const program = join(root, 'demo.mrsl');
  writeFileSync(program, readFileSync(join(REPO, 'examples', 'demo.mrsl')));
  mrslc(['compile', program, '--mode', 'reference,coarse4x4', '-o', join(root, 'shader')]);
  mrslc(['gbuffer', '--scene', 'demo', '--size', `${SIZE[0]}x${SIZE[1]}`, '-o', join(root, 'gbuffer'), program]);
  const server = await serve(root);
  // The playground's flags, and those that let a WebGPU canvas present on
  // SwiftShader's Vulkan (without them, the canvas's swap chain finds no
  // shared-image backing and the GPU process drops the page's device).
  const offline = ['--no-sandbox', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'];
  const canvas = ['--enable-gpu', '--ignore-gpu-blocklist', '--enable-features=Vulkan', '--use-vulkan=swiftshader', '--use-angle=swiftshader'];
  const args = [...offline, '--enable-unsafe-webgpu', '--enable-unsafe-swiftshader', ...canvas];
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args });
  try {
    const page = await browser.newPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    page.on('console', (m) => ['error', 'warning'].includes(m.type()) && problems.push(`console ${m.type()}: ${m.text()}`));
    await page.goto(server.url);
    const status = () => page.evaluate(() => document.getElementById('status').textContent);
    await page
      .waitForFunction(() => Number(/^frame (\d+):/.exec(document.getElementById('status').textContent)?.[1] ?? 0) >= 300, null, { timeout: 300_000, polling: 200 })
      .catch(async () => assert.fail(`the page did not reach frame 300: ${await status()}; ${problems.join('; ')}`));
    t.diagnostic(await status());
    assert.deepEqual(problems, [], 'no page error, no WebGPU error or warning');
    const shot = PNG.sync.read(await page.locator('#canvas').screenshot());
    assert.deepEqual([shot.width, shot.height], SIZE, 'the canvas is the image size');
    const png = join(dir, 'rust.png');
    const env = existsSync(SWIFTSHADER_ICD) ? { VK_ICD_FILENAMES: SWIFTSHADER_ICD } : {};
    mrslc(['render', program, '--scene', 'demo', '--size', `${SIZE[0]}x${SIZE[1]}`, '--mode', 'coarse4x4', '-o', png, '--out', dir], env);
    const rust = PNG.sync.read(readFileSync(png));
    // As in the playground's test: sRGB encoded in the shader's single
    // precision here, Tint against naga: at most 1 in a channel.
    let largest = 0;
    let differing = 0;
    for (let i = 0; i < rust.data.length; i++) {
      const d = Math.abs(shot.data[i] - rust.data[i]);
      if (d > 0) differing++;
      largest = Math.max(largest, d);
    }
    t.diagnostic(`canvas against the Rust PNG: ${differing} of ${rust.data.length} channels differ, by at most ${largest}`);
    assert.ok(largest <= 1, `the canvas differs from the Rust runtime's image by up to ${largest} in a channel`);
  } finally {
    await browser.close();
    server.close();
  }
});
