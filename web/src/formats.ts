// What the binding checks need to know of a WebGPU texture format: its
// components, how a shader reads it, and the bytes of one texel. WebGPU
// exposes none of this on a GPUTexture, so it is tabled here for the
// formats a G-buffer, an output or a shading-rate image can have.

export type ReadAs = 'float' | 'uint' | 'sint' | 'depth';

export interface FormatInfo {
  components: number;
  readAs: ReadAs;
  /** Bytes per texel, for uploads and read-backs (0: not copyable as plain texels). */
  bytes: number;
}

const table: Record<string, FormatInfo> = {};
function add(readAs: ReadAs, components: number, bytes: number, ...names: string[]): void {
  for (const name of names) table[name] = { components, readAs, bytes };
}
add('float', 1, 1, 'r8unorm', 'r8snorm');
add('uint', 1, 1, 'r8uint');
add('sint', 1, 1, 'r8sint');
add('float', 1, 2, 'r16float', 'r16unorm', 'r16snorm');
add('uint', 1, 2, 'r16uint');
add('sint', 1, 2, 'r16sint');
add('float', 2, 2, 'rg8unorm', 'rg8snorm');
add('uint', 2, 2, 'rg8uint');
add('sint', 2, 2, 'rg8sint');
add('float', 1, 4, 'r32float');
add('uint', 1, 4, 'r32uint');
add('sint', 1, 4, 'r32sint');
add('float', 2, 4, 'rg16float', 'rg16unorm', 'rg16snorm');
add('uint', 2, 4, 'rg16uint');
add('sint', 2, 4, 'rg16sint');
add('float', 4, 4, 'rgba8unorm', 'rgba8unorm-srgb', 'rgba8snorm', 'bgra8unorm', 'bgra8unorm-srgb', 'rgb10a2unorm');
add('uint', 4, 4, 'rgba8uint', 'rgb10a2uint');
add('sint', 4, 4, 'rgba8sint');
add('float', 3, 4, 'rgb9e5ufloat', 'rg11b10ufloat');
add('float', 2, 8, 'rg32float');
add('uint', 2, 8, 'rg32uint');
add('sint', 2, 8, 'rg32sint');
add('float', 4, 8, 'rgba16float', 'rgba16unorm', 'rgba16snorm');
add('uint', 4, 8, 'rgba16uint');
add('sint', 4, 8, 'rgba16sint');
add('float', 4, 16, 'rgba32float');
add('uint', 4, 16, 'rgba32uint');
add('sint', 4, 16, 'rgba32sint');
add('depth', 1, 0, 'depth16unorm', 'depth24plus', 'depth24plus-stencil8', 'depth32float', 'depth32float-stencil8', 'stencil8');

/** What the table knows of `format`, or `null` for a format it does not list (compressed ones). */
export function formatInfo(format: string): FormatInfo | null {
  return table[format] ?? null;
}
