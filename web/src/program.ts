// A compiled program as `mrslc compile -o DIR` writes it: `STEM.layout.json`
// and one WGSL file per kernel, `STEM.KIND.bB.wgsl` for the kinds compiled
// per block size and `STEM.KIND.wgsl` for the others.

import type { KernelRef, Layout } from './contract.js';
import { MrslError } from './errors.js';

export interface Kernel extends KernelRef {
  wgsl: string;
}

export interface CompiledProgram {
  layout: Layout;
  kernels: Kernel[];
}

/** The layout format this runtime reads (`mrsl_abi::LAYOUT_FORMAT`'s family). */
const LAYOUT_FORMAT_PREFIX = 'mrsl-layout/';

/** The file name of a kernel, as `mrslc compile` writes it. */
export function kernelFileName(stem: string, k: KernelRef): string {
  return k.block === null ? `${stem}.${k.kind}.wgsl` : `${stem}.${k.kind}.b${k.block}.wgsl`;
}

/** The kernels the plan's modes use, each once. */
export function planKernels(layout: Layout): KernelRef[] {
  const seen = new Map<string, KernelRef>();
  for (const k of layout.plan.modes.flatMap((m) => m.kernels)) seen.set(`${k.kind}/${k.block}`, k);
  return [...seen.values()];
}

/** Parses a layout, refusing what is not one this runtime reads. */
export function parseLayout(json: string | object): Layout {
  let layout: Layout;
  try {
    layout = (typeof json === 'string' ? JSON.parse(json) : json) as Layout;
  } catch {
    const start = typeof json === 'string' ? json.trimStart().slice(0, 40) : '';
    const html = start.startsWith('<') ? ' but an HTML page (a server\'s error page for a file it does not have?)' : '';
    throw new MrslError('program', `not an mrsl layout: the text is not JSON${html}; it starts ${JSON.stringify(start)}`);
  }
  if (typeof layout?.format !== 'string' || !layout.format.startsWith(LAYOUT_FORMAT_PREFIX) || !layout.plan?.constants) {
    throw new MrslError(
      'program',
      `not an mrsl layout with a pass plan (format ${JSON.stringify(layout?.format)}): compile the program with a current mrslc`,
    );
  }
  return layout;
}

/**
 * Where `loadProgram` reads the files: the URL of the directory \`mrslc
 * compile -o DIR\` wrote (fetched, relative to the page), or a function that
 * reads one file by name and returns its text or the \`Response\` of a
 * \`fetch\` (whose HTTP status is then checked).
 */
export type ProgramFiles = string | URL | ((file: string) => Promise<string | Response>);

const isResponse = (r: unknown): r is Response =>
  typeof r === 'object' && r !== null && typeof (r as Response).text === 'function' && typeof (r as Response).ok === 'boolean';

function reader(files: ProgramFiles): (file: string) => Promise<string | Response> {
  if (typeof files === 'function') return files;
  const base = new URL(String(files), globalThis.location?.href);
  if (!base.pathname.endsWith('/')) base.pathname += '/';
  return (file) => fetch(new URL(file, base));
}

/** The text of `file`, or a `program-file` error saying why not and, in `fix`, what to check. */
async function readText(read: (file: string) => Promise<string | Response>, file: string, fix: string): Promise<string> {
  const failed = (why: string) => new MrslError('program-file', `\`${file}\` could not be read: ${why}; ${fix}`, file);
  let got: string | Response;
  try {
    got = await read(file);
  } catch (error) {
    throw failed(error instanceof Error ? error.message : String(error));
  }
  if (!isResponse(got)) return got;
  if (!got.ok) throw failed(`HTTP ${got.status}${got.statusText ? ` ${got.statusText}` : ''} at ${got.url || file}`);
  return got.text();
}

/**
 * Loads what `mrslc compile -o DIR` wrote for `stem` (`STEM.layout.json`
 * and the kernels its plan uses) from `files`: the URL of DIR in a page, or
 * a function reading one file (`fs.readFile` in Node). A file that cannot be
 * read is a `program-file` error naming it, with the HTTP status.
 */
export async function loadProgram(files: ProgramFiles, stem: string): Promise<CompiledProgram> {
  const read = reader(files);
  const layoutFile = `${stem}.layout.json`;
  const fix = `check the directory and the stem: \`mrslc compile ${stem}.mrsl -o DIR\` writes DIR/${layoutFile}`;
  const text = await readText(read, layoutFile, fix);
  let layout: Layout;
  try {
    layout = parseLayout(text);
  } catch (error) {
    throw new MrslError('program-file', `\`${layoutFile}\` is ${(error as Error).message}; ${fix}`, layoutFile);
  }
  const kernels = await Promise.all(
    planKernels(layout).map(async (k) => {
      const file = kernelFileName(stem, k);
      const modes = layout.plan.modes.filter((m) => m.kernels.some((mk) => mk.kind === k.kind && mk.block === k.block)).map((m) => m.mode);
      const kernelFix = `the layout's plan runs it in ${[...new Set(modes)].join(', ')}: serve every file \`mrslc compile\` wrote beside ${layoutFile}, or compile only the modes the page uses (\`mrslc compile --mode ...\`)`;
      const wgsl = await readText(read, file, kernelFix);
      if (wgsl.trimStart().startsWith('<')) {
        throw new MrslError('program-file', `\`${file}\` is an HTML page, not WGSL (a server's page for a file it does not have?); ${kernelFix}`, file);
      }
      return { ...k, wgsl };
    }),
  );
  return { layout, kernels };
}
