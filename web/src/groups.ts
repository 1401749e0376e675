// Bind group layouts: group 0 (the control and uniform blocks, textures,
// samplers) and group 1 (the G-buffer) from the layout, group 2 (a
// kernel's stage group) from a pass of the plan, and group 3 (indirect
// arguments) for the entry points that write them. The group and binding
// numbers all come from the layout and the plan.

import type { BindingType, Layout, PassBinding } from './contract.js';

// Read when a layout is made, not at import: Node gets the WebGPU globals
// only once its binding is loaded.
const visibility = () => GPUShaderStage.COMPUTE;

export function resourcesLayout(device: GPUDevice, l: Layout): GPUBindGroupLayout {
  const entries: GPUBindGroupLayoutEntry[] = [{ binding: l.control.binding, visibility: visibility(), buffer: { type: 'uniform' } }];
  if (l.uniforms) entries.push({ binding: l.uniforms.binding, visibility: visibility(), buffer: { type: 'uniform' } });
  for (const t of l.textures) {
    entries.push({ binding: t.binding, visibility: visibility(), texture: { sampleType: 'float', viewDimension: '2d' } });
  }
  for (const s of l.samplers) entries.push({ binding: s.binding, visibility: visibility(), sampler: { type: 'filtering' } });
  return device.createBindGroupLayout({ label: 'mrsl resources', entries });
}

export function gbufferLayout(device: GPUDevice, l: Layout): GPUBindGroupLayout {
  const entries: GPUBindGroupLayoutEntry[] = l.channels.map((c) =>
    c.access === 'storage'
      ? { binding: c.binding, visibility: visibility(), storageTexture: { access: 'read-only', format: c.format, viewDimension: '2d' } }
      : { binding: c.binding, visibility: visibility(), texture: { sampleType: c.sample_type, viewDimension: '2d' } },
  );
  return device.createBindGroupLayout({ label: 'mrsl g-buffer', entries });
}

function entry(binding: number, ty: BindingType): GPUBindGroupLayoutEntry {
  const base = { binding, visibility: visibility() };
  switch (ty.kind) {
    case 'buffer':
      return { ...base, buffer: { type: ty.read_only ? 'read-only-storage' : 'storage' } };
    case 'storage_texture':
      return { ...base, storageTexture: { access: 'write-only', format: ty.format, viewDimension: '2d' } };
    case 'uint_texture':
      return { ...base, texture: { sampleType: 'uint', viewDimension: '2d' } };
    case 'record_texture':
      return { ...base, texture: { sampleType: 'uint', viewDimension: '2d-array' } };
    case 'record_storage_texture':
      return { ...base, storageTexture: { access: 'write-only', format: 'rgba32uint', viewDimension: '2d-array' } };
    case 'word_texture':
      return { ...base, storageTexture: { access: 'read-write', format: 'r32uint', viewDimension: '2d-array' } };
    // Packed records (`Options::packed_records`): read-write rgba32uint needs
    // the device feature `texture-formats-tier2` (`missingFeature`).
    case 'packed_word_texture':
      return { ...base, storageTexture: { access: 'read-write', format: 'rgba32uint', viewDimension: '2d-array' } };
  }
}

/**
 * Why `device` cannot make a stage group with `bindings`, where one needs a
 * device feature the device lacks, or `null`: said before anything is made,
 * so that the reason names the feature rather than a format.
 */
export function missingFeature(device: GPUDevice, bindings: readonly PassBinding[]): string | null {
  const packed = bindings.some((b) => b.type.kind === 'packed_word_texture');
  if (!packed || device.features.has('texture-formats-tier2')) return null;
  return (
    'its records are packed into an rgba32uint read-write storage texture (compiled with --packed-records), which ' +
    'needs the device feature `texture-formats-tier2`: request it, or compile without --packed-records'
  );
}

const STORAGE_TEXTURES: readonly string[] = ['storage_texture', 'record_storage_texture', 'word_texture', 'packed_word_texture'];

/**
 * Why the device's per-stage limits refuse a kernel whose stage group has
 * \`bindings\` (with \`storageChannels\` channels read through storage
 * bindings in group 1, and the indirect arguments in group 3 where it
 * writes them), or \`null\`: said before anything is made, so that the
 * reason names the limit rather than an invalid pipeline layout.
 */
export function overLimits(device: GPUDevice, bindings: readonly PassBinding[], storageChannels: number, writesArguments: boolean): string | null {
  const own = bindings.filter((b) => STORAGE_TEXTURES.includes(b.type.kind)).length;
  const textures = own + storageChannels;
  const textureLimit = device.limits.maxStorageTexturesPerShaderStage;
  if (textures > textureLimit) {
    const channels = storageChannels > 0 ? ` (${storageChannels} of them the G-buffer channels read through storage bindings)` : '';
    const fewer = storageChannels > 0 ? 'compile without --storage-channels, or ' : '';
    return (
      `it binds ${textures} storage textures in its compute stage${channels}, more than the device's limit ` +
      `maxStorageTexturesPerShaderStage, ${textureLimit}: request a device with requiredLimits: { maxStorageTexturesPerShaderStage: ${textures} } ` +
      `where the adapter allows it (adapter.limits), ${fewer}compile only the modes the device runs (mrslc compile --mode ...)`
    );
  }
  const buffers = bindings.filter((b) => b.type.kind === 'buffer').length + (writesArguments ? 1 : 0);
  const bufferLimit = device.limits.maxStorageBuffersPerShaderStage;
  if (buffers > bufferLimit) {
    return (
      `it binds ${buffers} storage buffers in its compute stage, more than the device's limit maxStorageBuffersPerShaderStage, ${bufferLimit}: ` +
      `request a device with requiredLimits: { maxStorageBuffersPerShaderStage: ${buffers} } where the adapter allows it, or compile only the modes the device runs`
    );
  }
  return null;
}

/** The stage group of a kernel, from the bindings a pass of the plan lists. */
export function stageLayout(device: GPUDevice, label: string, bindings: readonly PassBinding[]): GPUBindGroupLayout {
  return device.createBindGroupLayout({ label, entries: bindings.map((b) => entry(b.binding, b.type)) });
}

/** Group 3: the indirect arguments an entry point writes, at `binding`. */
export function argumentsLayout(device: GPUDevice, binding: number): GPUBindGroupLayout {
  return device.createBindGroupLayout({
    label: 'mrsl indirect arguments',
    entries: [entry(binding, { kind: 'buffer', read_only: false })],
  });
}
