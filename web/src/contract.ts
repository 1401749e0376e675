// The shapes of the JSON that `mrslc compile -o DIR` writes as
// `STEM.layout.json` (the Rust crate `mrsl-abi`'s `Layout` and `Plan`,
// serialised with serde). Only the parts this runtime reads are typed; the
// names and tags are serde's, so a layout parses as it is. The meaning of
// every field is documented on the Rust type of the same name.

/** A mode, as the layout and the command line name it. */
export type Mode =
  | 'reference'
  | 'coarse2x2'
  | 'coarse4x4'
  | 'dynamic'
  | 'hierarchical'
  | 'checkerboard'
  | 'rate-image'
  | 'multi-rate';

/** Every mode, in the order the Rust runtime lists them. */
export const MODES: readonly Mode[] = [
  'reference',
  'coarse2x2',
  'coarse4x4',
  'dynamic',
  'hierarchical',
  'checkerboard',
  'rate-image',
  'multi-rate',
];

/** A texture format, by its WebGPU name (the layout uses the same names). */
export type TextureFormatName = GPUTextureFormat;

export interface Layout {
  format: string;
  control: ControlBlock;
  uniforms: UniformBlock | null;
  textures: ResourceBinding[];
  samplers: ResourceBinding[];
  channels: Channel[];
  outputs: Output[];
  stats: StatsLayout;
  effects: EffectLayout[];
  /** The multi-rate mode's levels: `block[k]` is effect k's (4 or 2 for a coarse effect, 1 otherwise). */
  levels?: { block: number[] } | null;
  plan: Plan;
}

export interface ControlBlock {
  group: number;
  binding: number;
  size: number;
  fields: Field[];
}

export interface UniformBlock {
  group: number;
  binding: number;
  size: number;
  fields: Field[];
}

/** A uniform (or control-block) field: `type` is an mrsl type name ("float3", "float4[64]", "float4x4"). */
export interface Field {
  name: string;
  type: string;
  wgsl_type: string;
  offset: number;
  size: number;
  default: number[] | null;
}

export interface ResourceBinding {
  name: string;
  group: number;
  binding: number;
  kind: string;
}

export type SampleType = 'uint' | 'sint' | 'unfilterable-float' | 'depth';

/** How a channel is decoded from what the engine stores (`@depth`, `@encoded`). */
export type Decode =
  | { kind: 'depth'; inverse_view_projection: string }
  | { kind: 'unorm' }
  | { kind: 'octahedral' }
  | { kind: 'octahedral_unorm' }
  | { kind: 'bevy_deferred'; field: string };

export interface Channel {
  name: string;
  type: string;
  group: number;
  binding: number;
  format: TextureFormatName;
  sample_type: SampleType;
  decode?: Decode | null;
  /** How the kernels bind the channel's texture; absent means sampled. */
  access?: ChannelAccess;
}

/**
 * `sampled`: a sampled texture of any format of the channel's sample type
 * with enough components. `storage`: a read-only storage texture of exactly
 * the channel's format (`STORAGE_BINDING`), one more storage texture per
 * shader stage in every kernel's pipeline.
 */
export type ChannelAccess = 'sampled' | 'storage';

export interface Output {
  name: string;
  type: string;
  format: TextureFormatName;
  group: number;
  binding: number;
}

export interface StatsLayout {
  group: number;
  binding: number;
  /** The coarse effects with a counter, in counter order. */
  counters: string[];
}

export type Rate = 'coarse' | 'fine' | 'out';

export interface EffectLayout {
  name: string;
  rate: Rate;
  type: string;
  live: boolean;
}

// ---- The pass plan (`mrsl_abi::plan`) ----

export interface Plan {
  modes: ModePlan[];
  resources: ResourceDesc[];
  constants: PlanConstants;
}

export interface LatticeDesc {
  start: number;
  step: number;
  odd_only: boolean;
}

export interface PlanConstants {
  tile: number;
  coarse_workgroup: number;
  rate_list_tiles: number;
  checkerboard_quads_per_workgroup: number;
  hierarchical_levels: LatticeDesc[];
  max_side: number;
  max_storage_binding_bytes: number;
  max_texture_side: number;
  max_texture_layers: number;
  max_workgroups_per_dimension: number;
  arguments_group: number;
  arguments_binding: number;
  /** The refine-mask texel of a background pixel (where the background rule skipped the coarse effects). */
  background_mark: [number, number];
}

export interface KernelRef {
  kind: string;
  block: number | null;
}

/** The kind of device a mode's plan is for (`mrsl_abi::Device`). */
export type PlanDevice = 'gpu' | 'cpu';

export interface ModePlan {
  mode: Mode;
  /** Absent: the plan for every device. */
  device?: PlanDevice;
  kernels: KernelRef[];
  steps: Step[];
  counts: Counts;
}

export type Step =
  | { step: 'clear'; resource: ResourceId }
  | ({ step: 'pass' } & Pass)
  | { step: 'readback'; resource: ResourceId; bytes: number | null };

export type Stage = 'coarse' | 'coarse2x2' | 'fine';

export interface Pass {
  label: string;
  stage: Stage;
  kernel: KernelRef;
  bindings: PassBinding[];
  dispatches: Dispatch[];
  /** Bytes of workgroup memory the kernel declares (against `maxComputeWorkgroupStorageSize`). */
  workgroup_bytes?: number;
}

export interface PassBinding {
  binding: number;
  resource: ResourceId;
  type: BindingType;
}

export interface Dispatch {
  entry: string;
  arguments: ResourceId | null;
  workgroups: Workgroups;
}

export type ResourceId =
  | { id: 'records'; block: number }
  | { id: 'neighbour_values'; block: number }
  | { id: 'tagged_records'; block: number }
  | { id: 'pixel_records' }
  | { id: 'packed_pixel_records' }
  | { id: 'work_lists' }
  | { id: 'level_counts' }
  | { id: 'level_arguments' }
  | { id: 'rate_records' }
  | { id: 'sample_list' }
  | { id: 'sample_count' }
  | { id: 'sample_arguments' }
  | { id: 'tile_lists' }
  | { id: 'tile_counts' }
  | { id: 'tile_arguments' }
  | { id: 'statistics' }
  | { id: 'refine_mask' }
  | { id: 'level_records'; block: number }
  | { id: 'level_values' }
  | { id: 'shading_rate' }
  | { id: 'output'; index: number };

export type BindingType =
  | { kind: 'buffer'; read_only: boolean }
  | { kind: 'storage_texture'; format: TextureFormatName }
  | { kind: 'uint_texture' }
  | { kind: 'record_texture' }
  | { kind: 'record_storage_texture' }
  | { kind: 'word_texture' }
  | { kind: 'packed_word_texture' };

export interface ResourceDesc {
  id: ResourceId;
  what: string;
  shape: Shape;
  readable?: boolean;
}

export type Shape =
  | { type: 'buffer'; elements: Extent; words: number }
  | { type: 'texture_array'; texels: Extent; layers: number; format: TextureFormatName }
  | { type: 'texture'; format: TextureFormatName };

export type Extent =
  | { kind: 'pixels' }
  | { kind: 'sample_grid'; block: number }
  | { kind: 'hierarchical_levels' }
  | { kind: 'lattice'; start: number; step: number; odd_only: boolean }
  | { kind: 'fixed'; count: number };

export type Workgroups =
  | { kind: 'tiles' }
  | { kind: 'pixel_tiles'; side: number }
  | { kind: 'sample_grid'; block: number }
  | { kind: 'lattice'; start: number; step: number; odd_only?: boolean }
  | { kind: 'one' }
  | { kind: 'rate_tiles' }
  | { kind: 'checkerboard_quads' }
  | { kind: 'indirect'; buffer: ResourceId; offset: number; at_most: Extent | null; per_workgroup: number };

export interface Counts {
  samples:
    | { kind: 'none' }
    | { kind: 'grid'; block: number; counter: number | null }
    | { kind: 'listed'; resource: ResourceId; word: number }
    | { kind: 'levels' };
  evaluations: 'every_pixel' | 'counted' | 'samples_and_counted';
  work_lists: { resource: ResourceId; words_per_level: number; levels: number[]; lanes: number } | null;
  background?: { pixels: number; samples: number | null } | null;
}

/** A resource id as a map key ("records/4", "output/0"). */
export function resourceKey(id: ResourceId): string {
  if ('block' in id) return `${id.id}/${id.block}`;
  if ('index' in id) return `${id.id}/${id.index}`;
  return id.id;
}

/** Whether the engine binds the resource (else the runtime owns it). */
export function engineBound(id: ResourceId): boolean {
  return id.id === 'shading_rate' || id.id === 'output';
}
