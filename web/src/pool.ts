// The runtime-owned resources of a program's plan, one set per image size:
// made from their descriptors the first time a mode needs them at that
// size, and shared by every mode that names them. Several `encode`s of one
// Shader into one submission may use several sizes (views, split screens,
// probes); each keeps its set, so none is destroyed while recorded commands
// still use it, and views that keep their sizes make nothing anew frame
// after frame. The sets of the `KEPT_SIZES` sizes used last are kept; an
// older one is destroyed once the queue has finished the work submitted by
// the end of the task that retired it.

import type { Plan, ResourceDesc, ResourceId } from './contract.js';
import { resourceKey } from './contract.js';
import { extentCount, extentGrid, type Size } from './geometry.js';
import { resourceUses, type Uses } from './plan.js';

/** How many image sizes keep their resources (the sizes encoded last). */
export const KEPT_SIZES = 4;

type Made =
  | { kind: 'buffer'; buffer: GPUBuffer; bytes: number }
  | { kind: 'texture'; texture: GPUTexture; view: GPUTextureView };

/** The resources of one image size. */
export class ResourceSet {
  readonly #made = new Map<string, Made>();

  constructor(
    private readonly device: GPUDevice,
    private readonly plan: Plan,
    private readonly uses: Map<string, Uses>,
    readonly size: Size,
  ) {}

  /** Makes the resource unless it was made. */
  ensure(desc: ResourceDesc): void {
    const key = resourceKey(desc.id);
    if (this.#made.has(key)) return;
    const uses = this.uses.get(key) ?? { cleared: false, readBack: false, indirect: false, sampled: false };
    const label = `mrsl ${desc.what.replace(/^the /, '')}`;
    const shape = desc.shape;
    if (shape.type === 'buffer') {
      const bytes = Math.max(extentCount(this.plan.constants, shape.elements, this.size) * shape.words * 4, 4);
      let usage = GPUBufferUsage.STORAGE;
      if (uses.cleared) usage |= GPUBufferUsage.COPY_DST;
      if (uses.readBack) usage |= GPUBufferUsage.COPY_SRC;
      if (uses.indirect) usage |= GPUBufferUsage.INDIRECT;
      this.#made.set(key, { kind: 'buffer', buffer: this.device.createBuffer({ label, size: bytes, usage }), bytes });
      return;
    }
    const [w, h] = shape.type === 'texture_array' ? (extentGrid(shape.texels, this.size) ?? [1, 1]) : this.size;
    const layers = shape.type === 'texture_array' ? Math.max(shape.layers, 1) : 1;
    let usage = GPUTextureUsage.STORAGE_BINDING;
    // A readable texture (the refine mask) is for the page: to copy, and to sample in its own passes.
    if (uses.sampled || desc.readable) usage |= GPUTextureUsage.TEXTURE_BINDING;
    if (desc.readable) usage |= GPUTextureUsage.COPY_SRC;
    const texture = this.device.createTexture({ label, size: [w, h, layers], format: shape.format, usage });
    const view = texture.createView({ dimension: shape.type === 'texture_array' ? '2d-array' : '2d' });
    this.#made.set(key, { kind: 'texture', texture, view });
  }

  /** A buffer made by `ensure`. */
  buffer(id: ResourceId): GPUBuffer {
    const made = this.#made.get(resourceKey(id));
    if (made?.kind !== 'buffer') throw new Error(`${resourceKey(id)} is a buffer made before the steps that use it`);
    return made.buffer;
  }

  /** The bytes of buffer `id`. */
  bytes(id: ResourceId): number {
    const made = this.#made.get(resourceKey(id));
    return made?.kind === 'buffer' ? made.bytes : 0;
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

  destroy(): void {
    for (const made of this.#made.values()) (made.kind === 'buffer' ? made.buffer : made.texture).destroy();
    this.#made.clear();
  }
}

/** The resource sets of the sizes encoded last. */
export class ResourcePool {
  readonly #uses: Map<string, Uses>;
  /** By size ("WxH"), the one encoded last at the end. */
  readonly #sets = new Map<string, ResourceSet>();

  constructor(
    private readonly device: GPUDevice,
    private readonly plan: Plan,
  ) {
    this.#uses = resourceUses(plan);
  }

  /** The set of `size`, made if it is not kept; it becomes the one used last. */
  at(size: Size): ResourceSet {
    const key = `${size[0]}x${size[1]}`;
    let set = this.#sets.get(key);
    this.#sets.delete(key);
    set ??= new ResourceSet(this.device, this.plan, this.#uses, [size[0], size[1]]);
    this.#sets.set(key, set);
    for (const [old, retired] of this.#sets) {
      if (this.#sets.size <= KEPT_SIZES) break;
      this.#sets.delete(old);
      this.#retire(retired);
    }
    return set;
  }

  /**
   * Destroys `set` once the queue has finished the work submitted by the end
   * of this task: an encoder that recorded it in this task (a page's frame
   * encodes and submits in one) is then submitted, and done with.
   */
  #retire(set: ResourceSet): void {
    const queue = this.device.queue;
    setTimeout(() => {
      queue.onSubmittedWorkDone().then(
        () => set.destroy(),
        () => set.destroy(),
      );
    }, 0);
  }

  /** Frees every set now. */
  destroy(): void {
    for (const set of this.#sets.values()) set.destroy();
    this.#sets.clear();
  }
}
