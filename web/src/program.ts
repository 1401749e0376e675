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
  const layout = (typeof json === 'string' ? JSON.parse(json) : json) as Layout;
  if (typeof layout?.format !== 'string' || !layout.format.startsWith(LAYOUT_FORMAT_PREFIX) || !layout.plan?.constants) {
    throw new MrslError(
      'program',
      `not an mrsl layout with a pass plan (format ${JSON.stringify(layout?.format)}): compile the program with a current mrslc`,
    );
  }
  return layout;
}

/**
 * Loads what `mrslc compile -o DIR` wrote for `stem`, reading each file with
 * `read` (a `fetch` relative to DIR in a page, `fs.readFile` in Node).
 */
export async function loadProgram(read: (file: string) => Promise<string>, stem: string): Promise<CompiledProgram> {
  const layout = parseLayout(await read(`${stem}.layout.json`));
  const kernels = await Promise.all(
    planKernels(layout).map(async (k) => ({ ...k, wgsl: await read(kernelFileName(stem, k)) })),
  );
  return { layout, kernels };
}
