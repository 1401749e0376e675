// Loading a G-buffer that `mrslc gbuffer` exported (format "mrsl-gbuffer/1",
// docs/gbuffer-format.md): its channels, the textures and samplers a
// program binds, and the uniform values the scene set on that program.
// What a page renders over when it has no engine G-buffer of its own.

import { MrslError } from './errors.js';
import { formatInfo } from './formats.js';
import type { Size } from './geometry.js';
import type { Shader } from './shader.js';

export const GBUFFER_FORMAT = 'mrsl-gbuffer/1';

export interface GBufferManifest {
  format: string;
  scene: string;
  size: [number, number];
  channels: { name: string; format: GPUTextureFormat; file: string }[];
  program: string | null;
  uniforms: { name: string; type: string; values: number[] }[];
  textures: { name: string; format: GPUTextureFormat; size: [number, number]; mips: { file: string; size: [number, number] }[] }[];
  samplers: { name: string; address_mode: GPUAddressMode; mag_filter: GPUFilterMode; min_filter: GPUFilterMode; mipmap_filter: GPUMipmapFilterMode }[];
  warnings: string[];
}

export interface LoadedGBuffer {
  manifest: GBufferManifest;
  size: Size;
  channels: Record<string, GPUTexture>;
  textures: Record<string, GPUTexture>;
  samplers: Record<string, GPUSampler>;
}

/**
 * The colour formats WebGPU's core can bind as read-only storage textures:
 * a channel of one of them is made with STORAGE_BINDING too, so that it
 * binds to kernels compiled with storage channels as well as sampled ones.
 */
const STORAGE_READABLE: ReadonlySet<string> = new Set([
  'rgba8unorm', 'rgba8snorm', 'rgba8uint', 'rgba8sint', 'rgba16uint', 'rgba16sint', 'rgba16float',
  'r32uint', 'r32sint', 'r32float', 'rg32uint', 'rg32sint', 'rg32float', 'rgba32uint', 'rgba32sint', 'rgba32float',
]);

function upload(
  device: GPUDevice,
  label: string,
  format: GPUTextureFormat,
  mips: { data: ArrayBuffer; size: [number, number] }[],
  storage = false,
): GPUTexture {
  const info = formatInfo(format);
  if (!info || info.bytes === 0) throw new MrslError('program', `${label}: format ${format} cannot be uploaded as plain texels`);
  const [width, height] = mips[0]!.size;
  const texture = device.createTexture({
    label,
    size: [width, height],
    format,
    mipLevelCount: mips.length,
    usage:
      GPUTextureUsage.TEXTURE_BINDING |
      GPUTextureUsage.COPY_DST |
      GPUTextureUsage.COPY_SRC |
      (storage && STORAGE_READABLE.has(format) ? GPUTextureUsage.STORAGE_BINDING : 0),
  });
  mips.forEach(({ data, size: [w, h] }, level) => {
    const expected = w * h * info.bytes;
    if (data.byteLength !== expected) {
      throw new MrslError('program', `${label} (mip ${level}) has ${data.byteLength} bytes, but ${w}x${h} texels of ${format} are ${expected}`);
    }
    device.queue.writeTexture({ texture, mipLevel: level }, data, { bytesPerRow: w * info.bytes, rowsPerImage: h }, [w, h]);
  });
  return texture;
}

/**
 * Uploads an exported G-buffer: `read` fetches a file named in the manifest
 * (relative to the manifest's directory or URL).
 */
export async function loadGBuffer(device: GPUDevice, manifest: GBufferManifest, read: (file: string) => Promise<ArrayBuffer>): Promise<LoadedGBuffer> {
  if (manifest.format !== GBUFFER_FORMAT) {
    throw new MrslError('program', `not an mrsl G-buffer export (format ${JSON.stringify(manifest.format)}, expected ${GBUFFER_FORMAT})`);
  }
  const size: Size = [manifest.size[0], manifest.size[1]];
  const channels: Record<string, GPUTexture> = {};
  for (const ch of manifest.channels) {
    channels[ch.name] = upload(device, `channel ${ch.name}`, ch.format, [{ data: await read(ch.file), size: manifest.size }], true);
  }
  const textures: Record<string, GPUTexture> = {};
  for (const t of manifest.textures) {
    const mips = await Promise.all(t.mips.map(async (m) => ({ data: await read(m.file), size: m.size })));
    textures[t.name] = upload(device, `texture ${t.name}`, t.format, mips);
  }
  const samplers: Record<string, GPUSampler> = {};
  for (const s of manifest.samplers) {
    samplers[s.name] = device.createSampler({
      label: s.name,
      addressModeU: s.address_mode,
      addressModeV: s.address_mode,
      magFilter: s.mag_filter,
      minFilter: s.min_filter,
      mipmapFilter: s.mipmap_filter,
    });
  }
  return { manifest, size, channels, textures, samplers };
}

/** Sets the uniform values the export lists on `shader` (the others keep the program's defaults). */
export function applyUniforms(shader: Shader, manifest: GBufferManifest): void {
  for (const u of manifest.uniforms) shader.setUniform(u.name, u.values);
}
