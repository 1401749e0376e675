// What a page binds, checked against the program's layout and the mode's
// plan before anything is recorded: every mismatch is a typed `MrslError`
// naming the binding at fault (the Rust runtime's checks, in WebGPU terms).

import type { Channel, Layout, ModePlan, Output, Plan } from './contract.js';
import { MrslError } from './errors.js';
import { formatInfo } from './formats.js';
import { extentCount, extentGrid, rateImageSize, type Size } from './geometry.js';
import { planResources } from './plan.js';
import type { Bindings } from './bindings.js';

/** Shading-rate tile sizes the rate-image mode supports. */
export const RATE_TILE_SIZES: readonly number[] = [8, 16];

/** How a value the page passed reads in a message: `a GPUTextureView`, `an object {width, height}`, `undefined`. */
export function described(value: unknown): string {
  if (value === null || value === undefined) return String(value);
  if (typeof value !== 'object') return `the ${typeof value} ${JSON.stringify(value)}`;
  const name = (value as object).constructor?.name;
  if (name && name !== 'Object') return /^[AEIOU]/.test(name) ? `an ${name}` : `a ${name}`;
  return `an object {${Object.keys(value).join(', ')}}`;
}

/** `bindings.size` is `[width, height]` (what `{width, height}`, a GPUExtent3DDict, is not). */
export function checkSizeShape(size: unknown): void {
  const pair = (Array.isArray(size) || ArrayBuffer.isView(size)) && (size as ArrayLike<unknown>).length === 2;
  if (pair) return;
  throw new MrslError(
    'bad-size',
    `the target size \`bindings.size\` must be [width, height], but it is ${described(size)}: pass [width, height] (of a texture, [texture.width, texture.height])`,
  );
}

/**
 * `value`, bound as `what` \`name\`, is a GPUTexture (the runtime makes the
 * views it binds: a depth aspect, one mip level), not a view or anything else.
 */
function checkIsTexture(what: string, name: string, value: unknown): asserts value is GPUTexture {
  const t = value as Partial<GPUTexture> | null;
  if (t && typeof t === 'object' && typeof t.createView === 'function' && typeof t.format === 'string') return;
  const view = described(value) === 'a GPUTextureView';
  const fix = view ? 'pass the GPUTexture itself, not a view of it (the runtime makes the views it binds)' : 'pass a GPUTexture';
  throw new MrslError('not-a-texture', `${what} \`${name}\` is ${described(value)}, but it takes a GPUTexture: ${fix}`, name);
}

function badSize([w, h]: Size, reason: string): MrslError {
  return new MrslError('bad-size', `target size ${w}x${h} is not supported: ${reason}`);
}

/**
 * The image size: not empty, within the largest side (the plan's and the
 * device's), and within the limits of what the mode makes and dispatches.
 */
export function checkSize(plan: Plan, mode: ModePlan, size: Size, limits: GPUSupportedLimits): void {
  const g = plan.constants;
  const [w, h] = size;
  if (!(Number.isInteger(w) && Number.isInteger(h)) || w <= 0 || h <= 0) throw badSize(size, 'it is empty');
  if (w > g.max_side || h > g.max_side) throw badSize(size, `the largest supported side is ${g.max_side}`);
  if (w > limits.maxTextureDimension2D || h > limits.maxTextureDimension2D) {
    throw badSize(size, `the device's largest texture side (maxTextureDimension2D) is ${limits.maxTextureDimension2D}`);
  }
  for (const desc of planResources(plan, mode)) {
    const shape = desc.shape;
    if (shape.type === 'buffer') {
      const bytes = extentCount(g, shape.elements, size) * shape.words * 4;
      if (bytes > g.max_storage_binding_bytes) {
        const mib = (n: number) => Math.floor(n / 2 ** 20);
        throw badSize(size, `${desc.what} would need ${mib(bytes)} MiB, more than a ${mib(g.max_storage_binding_bytes)} MiB storage binding`);
      }
    } else if (shape.type === 'texture_array') {
      const [tw, th] = extentGrid(shape.texels, size) ?? [1, 1];
      if (Math.max(tw, th) > g.max_texture_side || shape.layers > g.max_texture_layers) {
        const side = g.max_texture_side;
        throw badSize(size, `${desc.what} would need ${tw}x${th} texels and ${shape.layers} layers, more than ${side}x${side} texels and ${g.max_texture_layers} layers`);
      }
    }
  }
  for (const pass of mode.steps) {
    if (pass.step !== 'pass') continue;
    for (const d of pass.dispatches) {
      if (d.workgroups.kind === 'indirect' && d.workgroups.at_most) {
        const groups = Math.ceil(extentCount(g, d.workgroups.at_most, size) / d.workgroups.per_workgroup);
        if (groups > g.max_workgroups_per_dimension) {
          throw badSize(size, `\`${d.entry}\` would need more than ${g.max_workgroups_per_dimension} workgroups`);
        }
      }
    }
  }
}

/** Why `t` is not the single-sample 2D texture of one layer (and one mip level for storage) a binding takes. */
function shapeProblem(t: GPUTexture, storage: boolean): string | null {
  if (t.dimension !== '2d') return `a ${t.dimension} texture`;
  if (t.depthOrArrayLayers !== 1) return `a 2D texture of ${t.depthOrArrayLayers} layers`;
  if (t.sampleCount !== 1) return `a multisampled texture (${t.sampleCount} samples): resolve it into a single-sample one`;
  if (storage && t.mipLevelCount !== 1) {
    return `a texture of ${t.mipLevelCount} mip levels, and a storage texture binding takes one`;
  }
  return null;
}

function checkTextureSize(what: string, name: string, t: GPUTexture, [w, h]: Size): void {
  if (t.width !== w || t.height !== h) {
    throw new MrslError('size-mismatch', `${what} \`${name}\` is ${t.width}x${t.height}, but the target is ${w}x${h}`, name);
  }
}

const COMPONENTS: Record<string, number> = { '2': 2, '3': 3, '4': 4 };

/** The components the engine's texture holds for a channel (two octahedral ones for a `float3`, say). */
function storedComponents(ch: Channel): number {
  const components = COMPONENTS[ch.type.at(-1) ?? ''] ?? 1;
  switch (ch.decode?.kind) {
    case 'depth':
      return 1;
    case 'octahedral':
    case 'octahedral_unorm':
      return 2;
    case 'bevy_deferred':
      return 4;
    default:
      return components;
  }
}

/**
 * A channel's texture: a depth format exactly when the channel is rebuilt
 * from depth, else a colour format read as the channel's sample type with
 * enough components (of what its encoding stores).
 */
function checkChannel(ch: Channel, t: GPUTexture): void {
  const info = formatInfo(t.format);
  const wants = ch.sample_type === 'unfilterable-float' ? 'float' : ch.sample_type;
  if (ch.decode?.kind === 'depth') {
    if (info?.readAs !== 'depth' || t.format === 'stencil8') {
      throw new MrslError(
        'channel-format',
        `G-buffer channel \`${ch.name}\` is rebuilt from depth (\`@depth\`), so it binds the engine's depth texture (depth32float, depth24plus, depth16unorm or a depth-stencil format), but a ${t.format} texture was bound`,
        ch.name,
      );
    }
    return checkUsageAndShape(ch, t);
  }
  if (info?.readAs === 'depth') {
    throw new MrslError(
      'channel-format',
      `G-buffer channel \`${ch.name}\` has the depth/stencil format ${t.format}, which is not accepted as a channel (the kernels read channels as colour textures): write what the program reads as \`${ch.type}\` into a ${ch.format} texture, or declare the channel \`@depth(inverse_view_projection) in float3\` to have the kernels rebuild a position from this depth texture`,
      ch.name,
    );
  }
  if (ch.access === 'storage') {
    if (t.format !== ch.format) {
      throw new MrslError(
        'channel-format',
        `G-buffer channel \`${ch.name}\` has format ${t.format}, but the kernels read it through a storage binding of format ${ch.format}, which takes no other: bind a ${ch.format} texture, or compile without storage channels to read it sampled`,
        ch.name,
      );
    }
    return checkUsageAndShape(ch, t);
  }
  const need = Math.min(storedComponents(ch), 4);
  const fits = info !== null && info.readAs === wants && info.components >= need && (need !== 3 || info.components === 4);
  if (!fits) {
    const rule = need === 1 ? 'any' : need === 2 ? 'at least 2' : 'exactly 4';
    throw new MrslError(
      'channel-format',
      `G-buffer channel \`${ch.name}\` has format ${t.format}, but the program reads it as \`${ch.type}\`: bind ${ch.format} (the layout's format) or another format read as ${wants} with ${rule} components`,
      ch.name,
    );
  }
  checkUsageAndShape(ch, t);
}

/**
 * A channel's texture has the usage its binding needs (TEXTURE_BINDING, or
 * STORAGE_BINDING for a storage channel) and is a single-sample 2D texture
 * of one layer.
 */
function checkUsageAndShape(ch: Channel, t: GPUTexture): void {
  const [usage, name] =
    ch.access === 'storage' ? [GPUTextureUsage.STORAGE_BINDING, 'STORAGE_BINDING'] : [GPUTextureUsage.TEXTURE_BINDING, 'TEXTURE_BINDING'];
  if (!(t.usage & usage)) {
    throw new MrslError(
      'channel-usage',
      `G-buffer channel \`${ch.name}\` was not created with GPUTextureUsage.${name}, which the kernels need to read it: add it to the texture's usage`,
      ch.name,
    );
  }
  const shape = shapeProblem(t, false);
  if (shape) {
    throw new MrslError('texture-shape', `G-buffer channel \`${ch.name}\` is ${shape}, but the kernels bind a single-sample 2D texture of one layer`, ch.name);
  }
}

function checkOutput(o: Output, t: GPUTexture): void {
  if (t.format !== o.format) {
    throw new MrslError('output-format', `output \`${o.name}\` must be a ${o.format} storage texture, found ${t.format}: ${outputFormatHint(o, t.format)}`, o.name);
  }
  if (!(t.usage & GPUTextureUsage.STORAGE_BINDING)) {
    throw new MrslError(
      'output-usage',
      `output \`${o.name}\` was not created with GPUTextureUsage.STORAGE_BINDING, which the kernels need to write it: add it to the texture's usage`,
      o.name,
    );
  }
  const shape = shapeProblem(t, true);
  if (shape) {
    throw new MrslError('texture-shape', `output \`${o.name}\` is ${shape}, but the kernels bind a single-sample 2D texture of one layer and one mip level`, o.name);
  }
}

/** The formats \`@format(..)\` can declare an output of \`type\` as (the language's \`TextureFormat::for_output\`). */
function declarableFormats(type: string): string[] {
  const m = /^(float|uint|int)([234])?$/.exec(type);
  if (!m) return [];
  const n = m[2] ? Number(m[2]) : 1;
  const any: Record<string, string[]> = {
    float: n === 1 ? ['r32float', 'rgba16float', 'rgba32float', 'rgba8unorm'] : ['rgba32float', 'rgba16float', 'rgba8unorm', 'rg32float'],
    uint: ['r32uint', 'rgba32uint'],
    int: ['r32sint', 'rgba32sint'],
  };
  return (any[m[1]!] ?? []).filter((f) => {
    const components = formatInfo(f)?.components ?? 0;
    return components >= Math.min(n, 4) || components === 4;
  });
}

/**
 * How to fix an output bound with a texture of format \`found\`: declare the
 * output with \`@format\` where the language can store its type in it, else
 * create the texture in the layout's format (the Rust runtime's hint).
 */
export function outputFormatHint(o: Output, found: string): string {
  const declarable = declarableFormats(o.type);
  if (declarable.includes(found)) {
    return `to write a ${found} texture, declare the output \`@format(${found}) fine out ${o.type} ${o.name}\` and compile the program again`;
  }
  return `create it as ${o.format} (the layout's format); \`@format(..)\` can declare a \`${o.type}\` output as ${declarable.join(', ')}`;
}

function checkShadingRate(bindings: Bindings, tile: number): void {
  const what = 'the shading-rate image';
  if (!RATE_TILE_SIZES.includes(tile)) {
    throw new MrslError('bad-tile-size', `rate tile size ${tile} is not supported (expected 8 or 16)`);
  }
  const t = bindings.shadingRate;
  if (!t) {
    throw new MrslError('missing-shading-rate', 'the rate-image mode needs a shading-rate image (`Bindings.shadingRate`), and none is bound');
  }
  checkIsTexture('the shading-rate image', 'shadingRate', t);
  if (!['r8uint', 'r16uint', 'r32uint'].includes(t.format)) {
    throw new MrslError('rate-format', `${what} has format ${t.format}, expected r8uint (as in D3D12 and Vulkan), r16uint or r32uint`);
  }
  if (!(t.usage & GPUTextureUsage.TEXTURE_BINDING)) {
    throw new MrslError('rate-usage', `${what} was not created with GPUTextureUsage.TEXTURE_BINDING`);
  }
  const [ew, eh] = rateImageSize(bindings.size, tile);
  if (t.width !== ew || t.height !== eh) {
    const [w, h] = bindings.size;
    throw new MrslError('rate-image-size', `${what} is ${t.width}x${t.height}, but a ${w}x${h} image with ${tile}x${tile} tiles needs ${ew}x${eh} texels`);
  }
}

/** Every channel, texture, sampler and output the layout declares, and the shading-rate image where the mode binds one. */
export function checkBindings(layout: Layout, mode: ModePlan, bindings: Bindings, rateTile: number): void {
  const bindsRate = mode.steps.some((s) => s.step === 'pass' && s.bindings.some((b) => b.resource.id === 'shading_rate'));
  if (bindsRate) checkShadingRate(bindings, rateTile);
  for (const ch of layout.channels) {
    const t = bindings.channels?.[ch.name];
    if (!t) throw new MrslError('missing-channel', `G-buffer channel \`${ch.name}\` is not bound`, ch.name);
    checkIsTexture('G-buffer channel', ch.name, t);
    checkChannel(ch, t);
    checkTextureSize('G-buffer channel', ch.name, t, bindings.size);
  }
  for (const t of layout.textures) {
    const bound = bindings.textures?.[t.name];
    if (!bound) throw new MrslError('missing-texture', `texture \`${t.name}\` is not bound`, t.name);
    if ('usage' in bound && !(bound.usage & GPUTextureUsage.TEXTURE_BINDING)) {
      throw new MrslError(
        'texture-usage',
        `texture \`${t.name}\` was not created with GPUTextureUsage.TEXTURE_BINDING, which the kernels need to sample it: add it to the texture's usage`,
        t.name,
      );
    }
  }
  for (const s of layout.samplers) {
    if (!bindings.samplers?.[s.name]) throw new MrslError('missing-sampler', `sampler \`${s.name}\` is not bound`, s.name);
  }
  for (const o of layout.outputs) {
    const t = bindings.outputs?.[o.name];
    if (!t) throw new MrslError('missing-output', `output \`${o.name}\` is not bound`, o.name);
    checkIsTexture('output', o.name, t);
    checkOutput(o, t);
    checkTextureSize('output', o.name, t, bindings.size);
  }
}
