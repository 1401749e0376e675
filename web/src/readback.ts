// Reading a 2D texture's texels back to the CPU, rows tightly packed: the
// outputs and the refine mask, for a page that shows them and for tests.

import { MrslError } from './errors.js';
import { formatInfo } from './formats.js';
import { rateImageSize } from './geometry.js';

/** Copies level 0 of `texture` (which needs COPY_SRC) into a new array, rows tightly packed. */
export async function readTexture(device: GPUDevice, texture: GPUTexture): Promise<Uint8Array> {
  const info = formatInfo(texture.format);
  if (!info || info.bytes === 0) throw new MrslError('readback', `reading results back failed: ${texture.format} is not read back as plain texels`);
  const { width, height } = texture;
  const row = width * info.bytes;
  // copyTextureToBuffer needs rows 256-byte aligned in the buffer.
  const paddedRow = Math.ceil(row / 256) * 256;
  const buffer = device.createBuffer({ label: 'mrsl texture readback', size: paddedRow * height, usage: GPUBufferUsage.COPY_DST | GPUBufferUsage.MAP_READ });
  const encoder = device.createCommandEncoder();
  encoder.copyTextureToBuffer({ texture }, { buffer, bytesPerRow: paddedRow }, [width, height]);
  device.queue.submit([encoder.finish()]);
  await buffer.mapAsync(GPUMapMode.READ);
  const mapped = new Uint8Array(buffer.getMappedRange());
  const out = new Uint8Array(row * height);
  for (let y = 0; y < height; y++) out.set(mapped.subarray(y * paddedRow, y * paddedRow + row), y * row);
  buffer.unmap();
  buffer.destroy();
  return out;
}

/** A rate image with every tile at the rate `width` x `height` (1, 2 or 4 each): texels `(log2 w << 2) | log2 h`, D3D12's encoding. */
export function uniformRateImage(device: GPUDevice, size: readonly [number, number], tile: number, [width, height]: readonly [number, number]): GPUTexture {
  const [tw, th] = rateImageSize(size, tile);
  const texture = device.createTexture({ label: 'mrsl uniform rate image', size: [tw, th], format: 'r8uint', usage: GPUTextureUsage.TEXTURE_BINDING | GPUTextureUsage.COPY_DST });
  const code = (Math.log2(width) << 2) | Math.log2(height);
  device.queue.writeTexture({ texture }, new Uint8Array(tw * th).fill(code), { bytesPerRow: tw }, [tw, th]);
  return texture;
}
