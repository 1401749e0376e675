// Builds the playground into playground/dist/, the files `mrslc serve`
// embeds: the page, its style sheet, and one bundle of the page's code with
// the web runtime and CodeMirror (esbuild). The bundle is committed, since
// mrslc embeds it when it is built; `npm test` checks that it is current.
// Usage: node playground/build.mjs [OUTDIR]
import * as esbuild from 'esbuild';
import { copyFileSync, mkdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const out = process.argv[2] ?? join(here, 'dist');
mkdirSync(out, { recursive: true });
await esbuild.build({
  entryPoints: [join(here, 'src', 'main.ts')],
  bundle: true,
  format: 'esm',
  target: 'es2022',
  minify: true,
  legalComments: 'linked',
  outfile: join(out, 'playground.js'),
  logLevel: 'warning',
});
copyFileSync(join(here, 'index.html'), join(out, 'index.html'));
copyFileSync(join(here, 'playground.css'), join(out, 'playground.css'));
