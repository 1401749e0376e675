// mrsl's WebGPU runtime for pages: loads what `mrslc compile -o DIR` writes
// (kernels, layout, pass plan), takes the page's GPUDevice, G-buffer and
// output textures, and records every mode's passes into the page's
// GPUCommandEncoder by interpreting the plan. See README.md.

/// <reference types="@webgpu/types" preserve="true" />

export type { Mode, Layout, Plan, ModePlan, PlanDevice } from './contract.js';
export { MODES } from './contract.js';
export { MrslError, type ErrorKind } from './errors.js';
export type { Bindings } from './bindings.js';
export { Shader, DEFAULT_SIMILARITY, DEFAULT_RATE_TILE, type DispatchOptions } from './shader.js';
export { loadProgram, parseLayout, kernelFileName, type CompiledProgram, type Kernel, type ProgramFiles } from './program.js';
export type { Stats, EffectStats, Timings } from './stats.js';
export { loadGBuffer, applyUniforms, GBUFFER_FORMAT, type GBufferManifest, type LoadedGBuffer } from './gbuffer.js';
export { rateImageSize, sampleGrid, type Size } from './geometry.js';
export { formatInfo } from './formats.js';
export { readTexture, uniformRateImage } from './readback.js';
export { decodeRefineMask, refineMaskBit, refineHeatmap, linearToSrgb8, type RefineMaskTexel } from './mask.js';
