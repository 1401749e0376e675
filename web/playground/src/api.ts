// The playground server's API (docs/serve.md): examples, scenes, compiling
// a program, and exporting a scene's G-buffer for it.

import type { GBufferManifest, Kernel } from '../../src/index.js';

export interface Example {
  name: string;
  file: string;
  scene: string;
  source: string;
}

export interface Label {
  /** UTF-8 byte offsets into the source. */
  start: number;
  end: number;
  line: number;
  column: number;
  message: string;
  primary: boolean;
}

export interface Diagnostic {
  severity: 'error' | 'warning';
  code: string;
  message: string;
  labels: Label[];
  notes: string[];
  rendered: string;
}

export interface Compiled {
  ok: boolean;
  diagnostics: Diagnostic[];
  kernels: (Kernel & { file: string })[];
  layout: object | null;
}

export interface Export {
  key: string;
  manifest: GBufferManifest;
  base: string;
}

async function json<T>(response: Response): Promise<T> {
  const body = await response.json();
  if (!response.ok) throw new Error(body?.error ?? `${response.status} ${response.statusText}`);
  return body as T;
}

const post = (path: string, body: object) =>
  fetch(path, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });

export const examples = async (): Promise<Example[]> => json(await fetch('/api/examples'));
export const scenes = async (): Promise<string[]> => json(await fetch('/api/scenes'));
export const compile = async (source: string): Promise<Compiled> => json(await post('/api/compile', { source }));
export const exportGBuffer = async (scene: string, size: [number, number], source: string): Promise<Export> =>
  json(await post('/api/gbuffer', { scene, size, source }));

/** A position as the language server protocol counts it: 0-based line, UTF-16 column. */
export interface Position {
  line: number;
  character: number;
}

/** The language server's hover (`textDocument/hover`). */
export interface Hover {
  contents: { kind: string; value: string };
  range?: { start: Position; end: Position };
}

/** A language server completion item (the fields the playground shows). */
export interface CompletionItem {
  label: string;
  kind?: number;
  detail?: string;
  documentation?: string | { kind: string; value: string };
}

export const hover = async (source: string, at: Position): Promise<Hover | null> =>
  json(await post('/api/hover', { source, ...at }));
export const complete = async (source: string, at: Position): Promise<CompletionItem[]> =>
  json(await post('/api/complete', { source, ...at }));

/** A file of an export, as bytes. */
export async function exportFile(base: string, file: string): Promise<ArrayBuffer> {
  const response = await fetch(base + file);
  if (!response.ok) throw new Error(`${base}${file}: ${response.status} ${response.statusText}`);
  return response.arrayBuffer();
}
