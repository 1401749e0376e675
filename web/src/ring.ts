// The read-back buffers of the statistics, as a ring: each `encode` copies
// its counters (and timestamps) into a slot that no read is mapping, and
// `readStats` maps the slot of the last `encode`. A page may so call
// `readStats()` every frame without waiting for it: the next frame's copies
// go to another slot, never into a buffer with a map pending (which fails
// the submit).

/** One set of read-back buffers, by resource key. */
export class ReadbackSlot {
  readonly #buffers = new Map<string, GPUBuffer>();
  /** Set while a read maps this slot's buffers; no `encode` copies into it then. */
  reading: Promise<unknown> | null = null;

  constructor(private readonly device: GPUDevice) {}

  /** Records a copy of the first `bytes` of `source` (of `size` bytes) into this slot's buffer for `key`. */
  copy(encoder: GPUCommandEncoder, key: string, source: GPUBuffer, bytes: number, size: number): void {
    let buffer = this.#buffers.get(key);
    if (!buffer || buffer.size !== size) {
      // The one replaced may be in an encoder not yet submitted: it is
      // dropped, not destroyed, and freed once nothing uses it.
      buffer = this.device.createBuffer({ label: 'mrsl readback', size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
      this.#buffers.set(key, buffer);
    }
    encoder.copyBufferToBuffer(source, 0, buffer, 0, bytes);
  }

  /** The buffer copied into for `key`, if any. */
  buffer(key: string): GPUBuffer | null {
    return this.#buffers.get(key) ?? null;
  }

  destroy(): void {
    for (const b of this.#buffers.values()) b.destroy();
    this.#buffers.clear();
  }
}

/** The slots; there are as many as reads overlap, plus one. */
export class ReadbackRing {
  readonly #slots: ReadbackSlot[] = [];

  constructor(private readonly device: GPUDevice) {}

  /** A slot no read is mapping, made when every slot is being read. */
  take(): ReadbackSlot {
    let slot = this.#slots.find((s) => s.reading === null);
    if (!slot) this.#slots.push((slot = new ReadbackSlot(this.device)));
    return slot;
  }

  destroy(): void {
    for (const s of this.#slots) s.destroy();
    this.#slots.length = 0;
  }
}

/** The words of `buffer`'s first `bytes` (all of it without), mapped and copied out, then unmapped. */
export async function readWords(buffer: GPUBuffer, bytes?: number): Promise<ArrayBuffer> {
  await (bytes === undefined ? buffer.mapAsync(GPUMapMode.READ) : buffer.mapAsync(GPUMapMode.READ, 0, bytes));
  const words = (bytes === undefined ? buffer.getMappedRange() : buffer.getMappedRange(0, bytes)).slice(0);
  buffer.unmap();
  return words;
}
