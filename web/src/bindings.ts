// What a page binds for one dispatch: the image size and its textures,
// samplers and outputs by the program's names (the Rust runtime's
// `Bindings`). A leaf module that the shader and the checks both read.

import type { Size } from './geometry.js';

/** What the page binds for one dispatch; every name is a declaration of the program. */
export interface Bindings {
  /** Width and height of the shaded image in pixels. */
  size: Size;
  /** G-buffer channel textures, by `in` name. */
  channels: Record<string, GPUTexture>;
  /** Sampled textures, by `uniform texture2d` name (a texture, or a view of one). */
  textures?: Record<string, GPUTexture | GPUTextureView>;
  /** Samplers, by `uniform sampler` name. */
  samplers?: Record<string, GPUSampler>;
  /** Output storage textures, by `fine out` name. */
  outputs: Record<string, GPUTexture>;
  /** The rate-image mode's shading-rate image: one r8uint/r16uint/r32uint texel per tile. */
  shadingRate?: GPUTexture;
}
