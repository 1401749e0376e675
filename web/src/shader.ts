// A compiled mrsl program on a page's GPUDevice: pipelines, bind group
// layouts, the control and uniform blocks, and the resources of its plan.
// `Shader.encode` interprets the mode's plan: one loop over its steps, with
// no dispatch rule of its own.

import type { KernelRef, Mode, ModePlan, Pass, PlanDevice, ResourceId } from './contract.js';
import { MODES, resourceKey } from './contract.js';
import { MrslError } from './errors.js';
import { directWorkgroups, type DispatchContext, type Size } from './geometry.js';
import * as groups from './groups.js';
import { modePlan, mostPasses, passes, planResources } from './plan.js';
import { ResourcePool, type ResourceSet } from './pool.js';
import { ReadbackRing, readWords, type ReadbackSlot } from './ring.js';
import type { CompiledProgram, Kernel } from './program.js';
import { makeStats, type Stats, type Timings } from './stats.js';
import { controlBytes, UniformValues } from './uniforms.js';
import { checkBindings, checkSize, checkSizeShape, described } from './validate.js';
import type { Bindings } from './bindings.js';

export interface DispatchOptions {
  mode: Mode;
  /** Treat every refine predicate as true: the output must then equal the reference. */
  forceRefine?: boolean;
  /** Hierarchical mode: the relative variance still interpolated (default 1e-3). */
  similarity?: number;
  /** Rate-image mode: pixels per side of a shading-rate tile, 8 (default) or 16. */
  rateTile?: number;
  /** Count per-pixel re-evaluations and write the refine mask (default on). */
  statistics?: boolean;
  /**
   * Which of the mode's plans to run: `'gpu'` (default; the block modes' tile
   * kernel) or `'cpu'` (their coarse and fine kernels, faster on a CPU device
   * such as SwiftShader). Both give the same image and statistics.
   */
  device?: PlanDevice;
}

/** The hierarchical mode's default similarity: a standard deviation of about 3% of the values. */
export const DEFAULT_SIMILARITY = 1e-3;
/** The rate-image mode's default tile size. */
export const DEFAULT_RATE_TILE = 8;

interface Timestamps {
  set: GPUQuerySet;
  resolve: GPUBuffer;
}

/** What one `encode` recorded: its options and size, its resources, where it copied its counters. */
interface Encoded {
  options: Required<DispatchOptions>;
  size: Size;
  passes: number;
  set: ResourceSet;
  slot: ReadbackSlot;
  /** Its statistics, once a `readStats` asked for them. */
  stats: Promise<Stats> | null;
}

/** The read-back slot's key of the timestamps. */
const TICKS = 'timestamps';

const kernelKey = (k: KernelRef) => `${k.kind}/${k.block}`;

/** A program on a device. Make one with `Shader.create`. */
export class Shader {
  readonly #uniforms: UniformValues;
  readonly #pool: ResourcePool;
  readonly #readbacks: ReadbackRing;
  readonly #control: GPUBuffer;
  readonly #uniformBuffer: GPUBuffer | null;
  #frame = 0;
  #last: Encoded | null = null;
  #destroyed = false;

  private constructor(
    readonly device: GPUDevice,
    readonly program: CompiledProgram,
    private readonly layouts: { resources: GPUBindGroupLayout; gbuffer: GPUBindGroupLayout; arguments: GPUBindGroupLayout; stages: Map<string, GPUBindGroupLayout> },
    private readonly pipelines: Map<string, GPUComputePipeline>,
    /** Kernel kinds the device refused, with its reason. */
    private readonly unavailable: Map<string, string>,
    private readonly timestamps: Timestamps | null,
  ) {
    const layout = program.layout;
    this.#uniforms = new UniformValues(layout.uniforms);
    this.#pool = new ResourcePool(device, layout.plan);
    this.#readbacks = new ReadbackRing(device);
    const uniform = (label: string, size: number) =>
      device.createBuffer({ label, size, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST });
    this.#control = uniform('mrsl control', layout.control.size);
    this.#uniformBuffer = layout.uniforms ? uniform('mrsl uniforms', layout.uniforms.size) : null;
  }

  /**
   * Creates the pipelines of every kernel the plan uses. A kernel the device
   * refuses does not fail this: the modes that need it are refused by
   * `supports` and `encode` with the device's reason.
   */
  static async create(device: GPUDevice, program: CompiledProgram): Promise<Shader> {
    const layout = program.layout;
    const plan = layout.plan;
    const c = plan.constants;
    const resources = groups.resourcesLayout(device, layout);
    const gbuffer = groups.gbufferLayout(device, layout);
    const argumentsLayout = groups.argumentsLayout(device, c.arguments_binding);
    const stages = new Map<string, GPUBindGroupLayout>();
    const pipelines = new Map<string, GPUComputePipeline>();
    const unavailable = new Map<string, string>();
    const allPasses = plan.modes.flatMap(passes);
    // One kernel at a time, each under its own error scope, so that a
    // kernel the device refuses is told apart from the others.
    for (const kernel of program.kernels) {
      const key = kernelKey(kernel);
      const kernelPasses = allPasses.filter((p) => kernelKey(p.kernel) === key);
      if (kernelPasses.length === 0) continue;
      const made = await makeKernel(device, kernel, kernelPasses, {
        resources,
        gbuffer,
        arguments: argumentsLayout,
        argumentsGroup: c.arguments_group,
        storageChannels: layout.channels.filter((ch) => ch.access === 'storage').length,
      });
      if ('refused' in made) unavailable.set(kernel.kind, made.refused);
      else {
        stages.set(key, made.stage);
        for (const [entry, pipeline] of made.pipelines) pipelines.set(`${key}:${entry}`, pipeline);
      }
    }
    const timestamps = device.features.has('timestamp-query') ? makeTimestamps(device, 2 * Math.max(mostPasses(plan), 1)) : null;
    return new Shader(device, program, { resources, gbuffer, arguments: argumentsLayout, stages }, pipelines, unavailable, timestamps);
  }

  get layout() {
    return this.program.layout;
  }

  /** Sets a uniform's components in order (matrices column by column, arrays element by element, bools as 0/1). */
  setUniform(name: string, values: number | readonly number[] | boolean): void {
    const list = typeof values === 'number' ? [values] : typeof values === 'boolean' ? [values ? 1 : 0] : values;
    this.#uniforms.set(name, list);
  }

  /** A uniform's value: the one set, else its default, else `null`. */
  uniform(name: string): number[] | null {
    return this.#uniforms.get(name);
  }

  /** Whether `encode` can run `mode` (its plan for `device`); throws `unsupported-mode` saying why not. */
  supports(mode: Mode, device: PlanDevice = 'gpu'): void {
    if (!MODES.includes(mode)) {
      throw new MrslError('unknown-mode', `unknown mode \`${mode}\` (expected ${MODES.join(', ')})`, mode);
    }
    const plan = modePlan(this.program.layout.plan, mode, device);
    const unsupported = (reason: string) =>
      new MrslError('unsupported-mode', `mode \`${mode}\` is not supported by this program: ${reason}`, mode);
    if (!plan) throw unsupported("the program's plan does not list it");
    for (const k of plan.kernels) {
      const refused = this.unavailable.get(k.kind);
      if (refused) throw unsupported(`the device cannot run its ${k.kind} kernel: ${refused}`);
      if (!this.layouts.stages.has(kernelKey(k))) throw unsupported(`the program was compiled without its ${k.kind} kernel`);
    }
  }

  /** The modes this program and device can run. */
  modes(): Mode[] {
    return MODES.filter((m) => {
      try {
        this.supports(m);
        return true;
      } catch {
        return false;
      }
    });
  }

  /**
   * Records the program's passes for one image into `encoder`. Everything
   * WebGPU lets a page check is checked before anything is recorded (a typed
   * `MrslError`, thrown). The returned promise settles once the device has
   * checked what was made: it rejects with an `MrslError` where the device
   * refused it (`foreign-device`: a texture of another GPUDevice, which
   * WebGPU does not let a page see); that encoder must not be submitted then.
   * Several `encode`s into one encoder (views of their own size, uniforms
   * and options) each render their own image. The statistics of the last
   * one can be read with `readStats` after the encoder's commands were submitted.
   */
  encode(encoder: GPUCommandEncoder, bindings: Bindings, options: DispatchOptions): Promise<void> {
    checkArguments(bindings, options, () => this.modes());
    const o: Required<DispatchOptions> = {
      mode: options.mode,
      forceRefine: options.forceRefine ?? false,
      similarity: options.similarity ?? DEFAULT_SIMILARITY,
      rateTile: options.rateTile ?? DEFAULT_RATE_TILE,
      statistics: options.statistics ?? true,
      device: options.device ?? 'gpu',
    };
    if (!Number.isFinite(o.similarity) || o.similarity < 0) {
      throw new MrslError('bad-option', `similarity is ${o.similarity}, but it must be a finite number >= 0`);
    }
    this.supports(o.mode, o.device);
    const layout = this.program.layout;
    const plan = modePlan(layout.plan, o.mode, o.device) as ModePlan;
    checkSizeShape(bindings.size);
    checkSize(layout.plan, plan, bindings.size, this.device.limits);
    checkBindings(layout, plan, bindings, o.rateTile);
    const uniformBytes = this.#uniformBuffer ? this.#uniforms.bytes() : null;
    this.#frame = (this.#frame + 1) % 2 ** 32 || 1;
    const control = controlBytes(layout.control.fields, layout.control.size, {
      size: [bindings.size[0], bindings.size[1]],
      force_refine: [o.forceRefine ? 1 : 0],
      frame: [this.#frame],
      similarity: [o.similarity],
      rate_tile: [o.rateTile],
      statistics: [o.statistics ? 1 : 0],
    });
    this.device.pushErrorScope('validation');
    try {
      this.#record(encoder, bindings, o, plan, control, uniformBytes);
    } catch (error) {
      void this.device.popErrorScope();
      throw error;
    }
    return this.device.popErrorScope().then((error) => {
      if (error) throw deviceError(error.message);
    });
  }

  #record(encoder: GPUCommandEncoder, bindings: Bindings, o: Required<DispatchOptions>, plan: ModePlan, control: ArrayBuffer, uniformBytes: ArrayBuffer | null): void {
    const set = this.#pool.at(bindings.size);
    for (const desc of planResources(this.program.layout.plan, plan)) set.ensure(desc);
    this.#stage(encoder, control, uniformBytes);
    const shared = [this.#resourcesGroup(bindings), this.#gbufferGroup(bindings)] as const;
    const context: DispatchContext = { size: bindings.size, forced: o.forceRefine, rateTile: o.rateTile };
    const stageGroups = new Map<string, GPUBindGroup>();
    const slot = this.#readbacks.take();
    let index = 0;
    for (const step of plan.steps) {
      if (step.step === 'clear') encoder.clearBuffer(set.buffer(step.resource));
      else if (step.step === 'readback') {
        const size = set.bytes(step.resource);
        slot.copy(encoder, resourceKey(step.resource), set.buffer(step.resource), step.bytes ?? size, size);
      } else {
        const key = kernelKey(step.kernel);
        let stage = stageGroups.get(key);
        if (!stage) stageGroups.set(key, (stage = this.#stageGroup(step, bindings, set)));
        this.#recordPass(encoder, step, index++, [shared[0], shared[1], stage], context, set);
      }
    }
    if (this.timestamps && index > 0) {
      const t = this.timestamps;
      encoder.resolveQuerySet(t.set, 0, 2 * index, t.resolve, 0);
      slot.copy(encoder, TICKS, t.resolve, 16 * index, t.resolve.size);
    }
    this.#last = { options: o, size: [bindings.size[0], bindings.size[1]], passes: index, set, slot, stats: null };
  }

  /**
   * Records copies of the control and uniform blocks into their buffers,
   * from a buffer made for this `encode`: in order with the passes, so that
   * several `encode`s before one submit each dispatch with their own values
   * (`queue.writeBuffer` lands before the whole submission runs). The
   * staging buffer is not destroyed (the page submits the encoder later):
   * it is freed once nothing uses it.
   */
  #stage(encoder: GPUCommandEncoder, control: ArrayBuffer, uniforms: ArrayBuffer | null): void {
    const size = control.byteLength + (uniforms?.byteLength ?? 0);
    const staging = this.device.createBuffer({ label: 'mrsl staged blocks', size, usage: GPUBufferUsage.COPY_SRC, mappedAtCreation: true });
    const mapped = new Uint8Array(staging.getMappedRange());
    mapped.set(new Uint8Array(control), 0);
    if (uniforms) mapped.set(new Uint8Array(uniforms), control.byteLength);
    staging.unmap();
    encoder.copyBufferToBuffer(staging, 0, this.#control, 0, control.byteLength);
    if (uniforms && this.#uniformBuffer) encoder.copyBufferToBuffer(staging, control.byteLength, this.#uniformBuffer, 0, uniforms.byteLength);
  }

  #recordPass(encoder: GPUCommandEncoder, pass: Pass, index: number, bound: GPUBindGroup[], context: DispatchContext, set: ResourceSet): void {
    const timestampWrites = this.timestamps
      ? { querySet: this.timestamps.set, beginningOfPassWriteIndex: 2 * index, endOfPassWriteIndex: 2 * index + 1 }
      : undefined;
    const compute = encoder.beginComputePass(timestampWrites ? { label: pass.label, timestampWrites } : { label: pass.label });
    bound.forEach((group, i) => compute.setBindGroup(i, group));
    const c = this.program.layout.plan.constants;
    for (const dispatch of pass.dispatches) {
      compute.setPipeline(this.pipelines.get(`${kernelKey(pass.kernel)}:${dispatch.entry}`) as GPUComputePipeline);
      if (dispatch.arguments) {
        const group = this.device.createBindGroup({
          label: 'mrsl indirect arguments',
          layout: this.layouts.arguments,
          entries: [{ binding: c.arguments_binding, resource: { buffer: set.buffer(dispatch.arguments) } }],
        });
        compute.setBindGroup(c.arguments_group, group);
      }
      const w = dispatch.workgroups;
      if (w.kind === 'indirect') compute.dispatchWorkgroupsIndirect(set.buffer(w.buffer), w.offset);
      else {
        const [x, y] = directWorkgroups(c, w, context) as [number, number];
        compute.dispatchWorkgroups(x, y, 1);
      }
    }
    compute.end();
  }

  #resourcesGroup(bindings: Bindings): GPUBindGroup {
    const l = this.program.layout;
    const entries: GPUBindGroupEntry[] = [{ binding: l.control.binding, resource: { buffer: this.#control } }];
    if (l.uniforms && this.#uniformBuffer) entries.push({ binding: l.uniforms.binding, resource: { buffer: this.#uniformBuffer } });
    for (const t of l.textures) {
      const bound = bindings.textures?.[t.name] as GPUTexture | GPUTextureView;
      entries.push({ binding: t.binding, resource: 'createView' in bound ? bound.createView() : bound });
    }
    for (const s of l.samplers) entries.push({ binding: s.binding, resource: bindings.samplers?.[s.name] as GPUSampler });
    return this.device.createBindGroup({ label: 'mrsl resources', layout: this.layouts.resources, entries });
  }

  #gbufferGroup(bindings: Bindings): GPUBindGroup {
    // A depth-and-stencil texture is bound through its depth aspect.
    const entries = this.program.layout.channels.map((c) => ({
      binding: c.binding,
      // A depth texture through its depth aspect; a storage binding takes one mip level.
      resource: (bindings.channels[c.name] as GPUTexture).createView(
        c.sample_type === 'depth' ? { aspect: 'depth-only' } : c.access === 'storage' ? { mipLevelCount: 1 } : {},
      ),
    }));
    return this.device.createBindGroup({ label: 'mrsl g-buffer', layout: this.layouts.gbuffer, entries });
  }

  /** Group 2 of `pass`: each binding the resource the plan names. */
  #stageGroup(pass: Pass, bindings: Bindings, set: ResourceSet): GPUBindGroup {
    const outputs = this.program.layout.outputs;
    const resource = (id: ResourceId): GPUBindingResource => {
      if (id.id === 'output') return (bindings.outputs[outputs[id.index]!.name] as GPUTexture).createView();
      if (id.id === 'shading_rate') return (bindings.shadingRate as GPUTexture).createView();
      return set.binding(id);
    };
    return this.device.createBindGroup({
      label: pass.kernel.kind,
      layout: this.layouts.stages.get(kernelKey(pass.kernel)) as GPUBindGroupLayout,
      entries: pass.bindings.map((b) => ({ binding: b.binding, resource: resource(b.resource) })),
    });
  }

  /**
   * The per-pixel refine mask (rg32uint) of the last dispatch of a mode with
   * coarse effects: x bit k set when coarse effect k (`layout.stats.counters[k]`)
   * was evaluated per pixel, y bit k when it came from the dynamic mode's 2x2 level.
   */
  refineMask(): GPUTexture | null {
    return this.#last?.set.texture({ id: 'refine_mask' }) ?? null;
  }

  /**
   * The statistics of the last `encode`, once the GPU has run it: call it
   * after submitting that `encode`'s encoder. It does not stall the frame
   * loop: a page may call it every frame without waiting for it, since the
   * next `encode`s copy their counters into other buffers. Its failures are
   * `MrslError`s (`readback`, `statistics-off`).
   */
  readStats(): Promise<Stats> {
    const last = this.#last;
    if (!last) {
      return Promise.reject(
        new MrslError('readback', 'reading the statistics back failed: nothing was encoded yet (call `readStats` after an `encode` and the submit of its encoder)'),
      );
    }
    if (!last.options.statistics) {
      return Promise.reject(new MrslError('statistics-off', 'the last dispatch ran with statistics off, so it counted nothing'));
    }
    if (!last.stats) {
      last.stats = this.#read(last);
      const done = () => {
        last.slot.reading = null;
      };
      last.slot.reading = last.stats.then(done, done);
    }
    return last.stats;
  }

  async #read(last: Encoded): Promise<Stats> {
    const layout = this.program.layout;
    const plan = modePlan(layout.plan, last.options.mode, last.options.device) as ModePlan;
    try {
      // Not before the work submitted by then is done: a page that calls this
      // between `encode` and its submit has then submitted (a map pending on
      // a buffer fails the submit that uses it).
      await this.device.queue.onSubmittedWorkDone();
      const mapped = new Map<string, Promise<ArrayBuffer>>();
      const words = (key: string, bytes?: number) => {
        let read = mapped.get(key);
        if (!read) {
          const buffer = last.slot.buffer(key);
          if (!buffer) return Promise.reject(new MrslError('readback', `reading the statistics back failed: ${key} was not read back`));
          mapped.set(key, (read = readWords(buffer, bytes)));
        }
        return read;
      };
      const u32 = async (id: ResourceId) => new Uint32Array(await words(resourceKey(id)));
      const samples = plan.counts.samples;
      const lists = plan.counts.work_lists;
      const [counters, listed, listWords, ticks] = await Promise.all([
        u32({ id: 'statistics' }),
        samples.kind === 'listed' ? u32(samples.resource).then((w) => w[samples.word] ?? 0) : 0,
        lists ? u32(lists.resource) : null,
        this.timestamps && last.passes > 0 ? words(TICKS, 16 * last.passes).then((b) => new BigUint64Array(b)) : null,
      ]);
      const workLists = lists && listWords ? lists.levels.map((level) => listWords[lists.words_per_level * level] ?? 0) : [];
      const timings = this.timestamps ? timingsOf(plan, ticks ?? new BigUint64Array(0)) : null;
      const counted = { counters, listedSamples: listed, workLists };
      return makeStats(layout, plan.counts, last.options.mode, last.options.forceRefine, last.size, counted, timings);
    } catch (error) {
      if (error instanceof MrslError && !this.#destroyed) throw error;
      const why = this.#destroyed ? 'the Shader was destroyed before they were read' : error instanceof Error ? `${error.name}: ${error.message}` : String(error);
      throw new MrslError('readback', `reading the statistics back failed: ${why}`);
    }
  }

  /** Frees the shader's buffers and textures; a `readStats` in progress fails with a `readback` error. */
  destroy(): void {
    this.#destroyed = true;
    this.#pool.destroy();
    this.#readbacks.destroy();
    this.#control.destroy();
    this.#uniformBuffer?.destroy();
    this.timestamps?.resolve.destroy();
    this.timestamps?.set.destroy();
  }
}

/** `encode`'s arguments are there: the bindings an object, the options one with a mode. */
function checkArguments(bindings: Bindings, options: DispatchOptions, modes: () => Mode[]): void {
  const example = () => `shader.encode(encoder, bindings, { mode: '${modes()[0] ?? 'reference'}' }) (this shader runs ${modes().join(', ')})`;
  if (!options || typeof options !== 'object') {
    throw new MrslError('bad-option', `encode's options are ${described(options)}, but they name the mode at least: ${example()}`);
  }
  if (options.mode === undefined) throw new MrslError('bad-option', `encode's options have no \`mode\`: ${example()}`);
  if (!bindings || typeof bindings !== 'object') {
    throw new MrslError('bad-option', `encode's bindings are ${described(bindings)}, but they are { size: [width, height], channels: { ... }, outputs: { ... } }`);
  }
}

/** What the device refused in what `encode` made, as an `MrslError`. */
function deviceError(message: string): MrslError {
  if (/is associated with .* and cannot be used with|another device|different device/is.test(message)) {
    return new MrslError(
      'foreign-device',
      `a texture, view or sampler bound was made on another GPUDevice than the one passed to Shader.create: make the G-buffer, the outputs and the textures on that device (in an engine, the device its renderer runs on); do not submit this encoder. The device said: ${message.trim()}`,
    );
  }
  return new MrslError('pipeline', `the device refused what encode made: do not submit this encoder. The device said: ${message.trim()}`);
}

interface SharedLayouts {
  resources: GPUBindGroupLayout;
  gbuffer: GPUBindGroupLayout;
  arguments: GPUBindGroupLayout;
  argumentsGroup: number;
  /** The G-buffer channels read through storage bindings, storage textures in every kernel's stage. */
  storageChannels: number;
}

/**
 * A kernel's stage group and the pipeline of each entry point its passes
 * dispatch (those that write indirect arguments also see the arguments
 * group), or the device's reason for refusing them.
 */
async function makeKernel(
  device: GPUDevice,
  kernel: Kernel,
  kernelPasses: Pass[],
  shared: SharedLayouts,
): Promise<{ stage: GPUBindGroupLayout; pipelines: Map<string, GPUComputePipeline> } | { refused: string }> {
  const missing = groups.missingFeature(device, kernelPasses[0]!.bindings);
  if (missing !== null) return { refused: missing };
  const writes = kernelPasses.some((p) => p.dispatches.some((d) => d.arguments !== null));
  const over = groups.overLimits(device, kernelPasses[0]!.bindings, shared.storageChannels, writes);
  if (over !== null) return { refused: over };
  const memory = kernelPasses[0]!.workgroup_bytes ?? 0;
  const limit = device.limits.maxComputeWorkgroupStorageSize;
  if (memory > limit) {
    return { refused: `it needs ${memory} bytes of workgroup memory, more than the device's ${limit} (maxComputeWorkgroupStorageSize)` };
  }
  device.pushErrorScope('validation');
  const stage = groups.stageLayout(device, kernel.kind, kernelPasses[0]!.bindings);
  const module = device.createShaderModule({ label: kernel.kind, code: kernel.wgsl });
  const groupLayouts: (GPUBindGroupLayout | null)[] = [shared.resources, shared.gbuffer, stage];
  const plain = device.createPipelineLayout({ label: kernel.kind, bindGroupLayouts: groupLayouts });
  const withArgumentsGroups = [...groupLayouts];
  withArgumentsGroups[shared.argumentsGroup] = shared.arguments;
  const withArguments = device.createPipelineLayout({ label: kernel.kind, bindGroupLayouts: withArgumentsGroups });
  const writesArguments = new Map<string, boolean>();
  for (const d of kernelPasses.flatMap((p) => p.dispatches)) {
    writesArguments.set(d.entry, (writesArguments.get(d.entry) ?? false) || d.arguments !== null);
  }
  const pipelines = new Map<string, GPUComputePipeline>();
  let refused: string | null = null;
  for (const [entry, writes] of writesArguments) {
    try {
      const layout = writes ? withArguments : plain;
      pipelines.set(entry, await device.createComputePipelineAsync({ label: entry, layout, compute: { module, entryPoint: entry } }));
    } catch (error) {
      refused ??= error instanceof Error ? error.message : String(error);
    }
  }
  const scoped = await device.popErrorScope();
  refused ??= scoped?.message ?? null;
  return refused === null ? { stage, pipelines } : { refused };
}

function makeTimestamps(device: GPUDevice, count: number): Timestamps {
  return {
    set: device.createQuerySet({ label: 'mrsl timestamps', type: 'timestamp', count }),
    resolve: device.createBuffer({ label: 'mrsl timestamps resolve', size: 8 * count, usage: GPUBufferUsage.QUERY_RESOLVE | GPUBufferUsage.COPY_SRC }),
  };
}

/** The passes' GPU times (WebGPU timestamps are nanoseconds), summed by stage. */
function timingsOf(plan: ModePlan, ticks: BigUint64Array): Timings {
  const ms = (a: bigint, b: bigint) => (b > a ? Number(b - a) / 1e6 : 0);
  const t: Timings = { coarseMs: 0, coarse2Ms: 0, fineMs: 0, totalMs: 0 };
  const list = passes(plan);
  list.forEach((pass, i) => {
    const time = ms(ticks[2 * i]!, ticks[2 * i + 1]!);
    if (pass.stage === 'coarse') t.coarseMs += time;
    else if (pass.stage === 'coarse2x2') t.coarse2Ms += time;
    else t.fineMs += time;
  });
  if (list.length > 0) t.totalMs = ms(ticks[0]!, ticks[2 * list.length - 1]!);
  return t;
}
