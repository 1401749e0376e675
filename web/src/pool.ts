// The runtime-owned resources of a program's plan, made from their
// descriptors the first time a mode needs them and made again only when the
// image size changes what they hold: one cache for every mode, keyed by
// resource id.

import type { Plan, ResourceDesc, ResourceId } from './contract.js';
import { resourceKey } from './contract.js';
import { extentCount, extentGrid, type Size } from './geometry.js';
import { resourceUses, type Uses } from './plan.js';

type Made =
  | { kind: 'buffer'; buffer: GPUBuffer; bytes: number }
  | { kind: 'texture'; texture: GPUTexture; view: GPUTextureView; extent: [number, number, number] };

export class ResourcePool {
  readonly #uses: Map<string, Uses>;
  readonly #made = new Map<string, Made>();
  /** Read-back copies of buffers (`readback` steps), by resource. */
  readonly #readbacks = new Map<string, GPUBuffer>();

  constructor(
    private readonly device: GPUDevice,
    private readonly plan: Plan,
  ) {
    this.#uses = resourceUses(plan);
  }

  /** Makes the resource for a `size` image unless what exists already fits it. */
  ensure(desc: ResourceDesc, size: Size): void {
    const key = resourceKey(desc.id);
    const uses = this.#uses.get(key) ?? { cleared: false, readBack: false, indirect: false, sampled: false };
    const label = `mrsl ${desc.what.replace(/^the /, '')}`;
    const shape = desc.shape;
    if (shape.type === 'buffer') {
      const bytes = Math.max(extentCount(this.plan.constants, shape.elements, size) * shape.words * 4, 4);
      const made = this.#made.get(key);
      if (made?.kind === 'buffer' && made.bytes === bytes) return;
      if (made?.kind === 'buffer') made.buffer.destroy();
      let usage = GPUBufferUsage.STORAGE;
      if (uses.cleared) usage |= GPUBufferUsage.COPY_DST;
      if (uses.readBack) usage |= GPUBufferUsage.COPY_SRC;
      if (uses.indirect) usage |= GPUBufferUsage.INDIRECT;
      this.#made.set(key, { kind: 'buffer', buffer: this.device.createBuffer({ label, size: bytes, usage }), bytes });
      return;
    }
    const [w, h] = shape.type === 'texture_array' ? (extentGrid(shape.texels, size) ?? [1, 1]) : size;
    const layers = shape.type === 'texture_array' ? Math.max(shape.layers, 1) : 1;
    const made = this.#made.get(key);
    if (made?.kind === 'texture' && made.extent.join() === [w, h, layers].join()) return;
    if (made?.kind === 'texture') made.texture.destroy();
    let usage = GPUTextureUsage.STORAGE_BINDING;
    if (uses.sampled) usage |= GPUTextureUsage.TEXTURE_BINDING;
    if (desc.readable) usage |= GPUTextureUsage.COPY_SRC;
    const texture = this.device.createTexture({ label, size: [w, h, layers], format: shape.format, usage });
    const view = texture.createView({ dimension: shape.type === 'texture_array' ? '2d-array' : '2d' });
    this.#made.set(key, { kind: 'texture', texture, view, extent: [w, h, layers] });
  }

  /** A buffer made by `ensure`. */
  buffer(id: ResourceId): GPUBuffer {
    const made = this.#made.get(resourceKey(id));
    if (made?.kind !== 'buffer') throw new Error(`${resourceKey(id)} is a buffer made before the steps that use it`);
    return made.buffer;
  }

  /** Resource `id` as a bind group entry's resource. */
  binding(id: ResourceId): GPUBindingResource {
    const made = this.#made.get(resourceKey(id));
    if (!made) throw new Error(`${resourceKey(id)} is made before the steps that use it`);
    return made.kind === 'buffer' ? { buffer: made.buffer } : made.view;
  }

  /** A texture, if it was made. */
  texture(id: ResourceId): GPUTexture | null {
    const made = this.#made.get(resourceKey(id));
    return made?.kind === 'texture' ? made.texture : null;
  }

  /** Records a copy of `bytes` (or all) of buffer `id` into its read-back buffer. */
  copyOut(encoder: GPUCommandEncoder, id: ResourceId, bytes: number | null): void {
    const key = resourceKey(id);
    const made = this.#made.get(key);
    if (made?.kind !== 'buffer') throw new Error(`${key} is a buffer made before it is read back`);
    let readback = this.#readbacks.get(key);
    if (!readback || readback.size !== made.bytes) {
      readback?.destroy();
      readback = this.device.createBuffer({
        label: 'mrsl readback',
        size: made.bytes,
        usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST,
      });
      this.#readbacks.set(key, readback);
    }
    encoder.copyBufferToBuffer(made.buffer, 0, readback, 0, bytes ?? made.bytes);
  }

  /** The read-back buffer of `id`, if it was ever copied out. */
  readback(id: ResourceId): GPUBuffer | null {
    return this.#readbacks.get(resourceKey(id)) ?? null;
  }

  /** Frees every resource. */
  destroy(): void {
    for (const made of this.#made.values()) (made.kind === 'buffer' ? made.buffer : made.texture).destroy();
    for (const b of this.#readbacks.values()) b.destroy();
    this.#made.clear();
    this.#readbacks.clear();
  }
}
