//! A compiled mrsl program instantiated on a wgpu device: pipelines, bind
//! group layouts, the control and uniform blocks, and the resources of its
//! plan. [`Shader::encode`] interprets the mode's plan
//! ([`mrsl_abi::plan::ModePlan`]): one loop over its steps.

use crate::bindings::Bindings;
use crate::error::Error;
use crate::gpu::{describe, read_buffer};
use crate::groups;
use crate::pool::ResourcePool;
use crate::uniforms::UniformValues;
use crate::{Mode, Stats};
use mrsl_abi::plan::{DispatchContext, ModePlan, Pass, SampleCount, Stage, Step, Workgroups};
use mrsl_abi::{CompiledProgram, Control, Device, GROUP_ARGS, KernelKind, KernelRef, Layout, Plan, ResourceId, Scalar};
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

/// Per-dispatch settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DispatchOptions {
    pub mode: Mode,
    /// Treat every refine predicate as true (and refine every coarse effect):
    /// the output must then equal the reference.
    pub force_refine: bool,
    /// Hierarchical mode: a pixel is interpolated only while the variance of
    /// its neighbours' values (the largest component's) is at most this
    /// times the largest square of those values (a relative spread).
    pub similarity: f32,
    /// Rate-image mode: pixels per side of a shading-rate tile (8 or 16).
    pub rate_tile: u32,
    /// Count per-pixel re-evaluations ([`Shader::read_stats`]) and write the
    /// per-pixel refine mask ([`Shader::refine_mask`]). On by default; turn it
    /// off for frames that are only displayed or timed: the counters are
    /// workgroup atomics and a barrier per tile, whose cost depends on the
    /// program and scene (on lavapipe 8% to 35% of a coarse 4x4 frame in the
    /// ablation of docs/eval/evaluation.md, 18% for the demo at 640x360;
    /// docs/runtime.md, section 5).
    pub statistics: bool,
    /// Which of the mode's plans to run ([`mrsl_abi::Device`]): `None`, the
    /// one for the kind of device the shader was made on (a CPU device, such
    /// as lavapipe, or a GPU); `Some` to run the other (the block modes'
    /// tile kernel on a CPU device, say, to compare them). Every plan of a
    /// mode gives the same image and statistics, bit for bit.
    pub device: Option<Device>,
}

impl DispatchOptions {
    /// Default similarity threshold of the hierarchical mode (a relative
    /// variance: a standard deviation of about 3% of the values).
    pub const DEFAULT_SIMILARITY: f32 = 1e-3;

    pub fn new(mode: Mode) -> DispatchOptions {
        DispatchOptions {
            mode,
            force_refine: false,
            similarity: Self::DEFAULT_SIMILARITY,
            rate_tile: mrsl_abi::shading_rate::DEFAULT_RATE_TILE,
            statistics: true,
            device: None,
        }
    }

    /// The same dispatch with `statistics` off: no per-pixel counters and no
    /// refine mask, as a timed run measures it.
    pub fn uninstrumented(self) -> DispatchOptions {
        DispatchOptions { statistics: false, ..self }
    }
}

/// Timestamp queries: two per pass (its beginning and end), in plan order.
struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f32,
}

impl Timestamps {
    /// A query set of `queries` timestamps, with its resolve and readback buffers.
    fn new(device: &wgpu::Device, queries: u32) -> Timestamps {
        let bytes = 8 * u64::from(queries);
        Timestamps {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("mrsl timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: queries,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl timestamps resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl timestamps readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            period_ns: 1.0,
        }
    }
}

/// A pipeline: the kernel and the entry point.
type PipelineKey = (KernelRef, String);

/// A program on a device.
pub struct Shader {
    layout: Layout,
    /// The layout's plan, shared so that a dispatch can read it while it fills the pool.
    plan: Arc<Plan>,
    resources_layout: wgpu::BindGroupLayout,
    gbuffer_layout: wgpu::BindGroupLayout,
    /// Each kernel's stage group, from the bindings its passes list.
    stage_layouts: HashMap<KernelRef, wgpu::BindGroupLayout>,
    arguments_layout: wgpu::BindGroupLayout,
    pipelines: HashMap<PipelineKey, wgpu::ComputePipeline>,
    /// Kernel kinds whose stage layout or pipelines the device refused, with
    /// its reason: the modes that need them are refused at `encode`.
    unavailable: HashMap<KernelKind, String>,
    control: wgpu::Buffer,
    uniforms: Option<wgpu::Buffer>,
    uniform_values: UniformValues,
    pool: ResourcePool,
    /// Dispatch counter, written to the control block (validity tags of the dynamic mode).
    frame: u32,
    timestamps: Option<Timestamps>,
    last: Option<(DispatchOptions, (u32, u32))>,
    /// The kind of device the shader runs on, whose plans it runs by default.
    device: Device,
}

impl Shader {
    /// Creates the pipelines of every kernel in `program`: compiled just now
    /// (`&mrsl::compile(..)?` dereferences to one) or read from the files
    /// `mrslc compile` wrote ([`CompiledProgram::read_dir`]). A kernel the
    /// device refuses (a limit exceeded) does not fail this: the modes that
    /// need it return [`Error::UnsupportedMode`] from [`Shader::encode`].
    pub fn new(device: &wgpu::Device, program: &CompiledProgram) -> Result<Shader, Error> {
        let layout = program.layout.clone();
        let plan = &layout.plan;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let resources_layout = groups::resources_layout(device, &layout);
        let gbuffer_layout = groups::gbuffer_layout(device, &layout);
        let arguments_layout = groups::arguments_layout(device);
        let KernelPipelines { stage_layouts, pipelines, unavailable } =
            kernel_pipelines(device, program, [&resources_layout, &gbuffer_layout, &arguments_layout]);
        let uniform_buffer = |label, size: u32| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: u64::from(size),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let control = uniform_buffer("mrsl control", layout.control.size);
        let uniforms = layout.uniforms.as_ref().map(|u| uniform_buffer("mrsl uniforms", u.size));
        let timestamps = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| Timestamps::new(device, 2 * plan.most_passes().max(1) as u32));
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        Ok(Shader {
            pool: ResourcePool::new(plan),
            plan: Arc::new(layout.plan.clone()),
            layout,
            resources_layout,
            gbuffer_layout,
            stage_layouts,
            arguments_layout,
            pipelines,
            unavailable,
            control,
            uniforms,
            uniform_values: UniformValues::default(),
            frame: 0,
            timestamps,
            last: None,
            device: crate::gpu::device_kind(device),
        })
    }

    /// Sets the timestamp period (nanoseconds per tick) from the queue.
    pub fn set_timestamp_period(&mut self, queue: &wgpu::Queue) {
        if let Some(t) = &mut self.timestamps {
            t.period_ns = queue.get_timestamp_period();
        }
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Sets a uniform's value: its components in order (matrices column by
    /// column, arrays element by element, bools as 0/1). Uniforms not set
    /// take their declared default. Each value must be one the uniform's
    /// scalar type holds: a finite float within f32's range; for `int` and
    /// `uint` an integer within i32's or u32's range; for `bool` 0 or 1
    /// ([`Error::UniformValue`] otherwise, and the uniform keeps its value).
    pub fn set_uniform(&mut self, name: &str, values: &[f64]) -> Result<(), Error> {
        self.uniform_values.set(self.layout.uniforms.as_ref(), name, values)
    }

    /// The value set for uniform `name` by one of the setters, components in
    /// the order [`Shader::set_uniform`] takes them; `None` for a uniform not
    /// set (it takes its declared default) or not declared. Lets a tool
    /// record what it bound, say to hand it to another runtime.
    pub fn uniform(&self, name: &str) -> Option<&[f64]> {
        self.uniform_values.get(name)
    }

    /// Sets a `float` uniform (vector, matrix or array of floats) from f32
    /// values, as [`Shader::set_uniform`] does; a uniform of another scalar
    /// type is [`Error::UniformType`].
    pub fn set_uniform_f32(&mut self, name: &str, values: &[f32]) -> Result<(), Error> {
        let values: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
        self.uniform_values.set_typed(self.layout.uniforms.as_ref(), name, (Scalar::Float, "f32"), &values)
    }

    /// Sets an `int` uniform (or vector or array of ints); see [`Shader::set_uniform_f32`].
    pub fn set_uniform_i32(&mut self, name: &str, values: &[i32]) -> Result<(), Error> {
        let values: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
        self.uniform_values.set_typed(self.layout.uniforms.as_ref(), name, (Scalar::Int, "i32"), &values)
    }

    /// Sets a `uint` uniform (or vector or array of uints); see [`Shader::set_uniform_f32`].
    pub fn set_uniform_u32(&mut self, name: &str, values: &[u32]) -> Result<(), Error> {
        let values: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
        self.uniform_values.set_typed(self.layout.uniforms.as_ref(), name, (Scalar::Uint, "u32"), &values)
    }

    /// Sets a `bool` uniform (or vector or array of bools); see [`Shader::set_uniform_f32`].
    pub fn set_uniform_bool(&mut self, name: &str, values: &[bool]) -> Result<(), Error> {
        let values: Vec<f64> = values.iter().map(|&v| f64::from(u8::from(v))).collect();
        self.uniform_values.set_typed(self.layout.uniforms.as_ref(), name, (Scalar::Bool, "bool"), &values)
    }

    /// Whether [`Shader::encode`] can run `mode`: the device runs its kernels
    /// and the program was compiled with them (else
    /// [`Error::UnsupportedMode`], saying which kernel and why). Lets a tool
    /// that renders several modes skip one before binding anything.
    pub fn supports(&self, mode: Mode) -> Result<(), Error> {
        self.supports_on(mode, self.device)
    }

    /// [`Shader::supports`] for the mode's plan on `device` ([`DispatchOptions::device`]).
    pub fn supports_on(&self, mode: Mode, device: Device) -> Result<(), Error> {
        let unsupported = |reason: String| Error::UnsupportedMode(mode.name().into(), reason);
        let Some(plan) = self.plan.mode_on(mode, device) else {
            return Err(unsupported("the program's plan does not list it".into()));
        };
        if let Some((kind, reason)) = plan.kernels.iter().find_map(|k| self.unavailable.get_key_value(&k.kind)) {
            return Err(unsupported(format!("the device cannot run its {kind} kernel: {reason}")));
        }
        let has =
            |k: &KernelRef| k.kind.entry_points().iter().all(|e| self.pipelines.contains_key(&(*k, e.to_string())));
        if let Some(missing) = plan.kernels.iter().find(|k| !has(k)) {
            return Err(unsupported(format!("the program was compiled without its {missing} kernel")));
        }
        Ok(())
    }

    /// The kind of device whose plans [`Shader::encode`] runs by default.
    pub fn device(&self) -> Device {
        self.device
    }

    /// The plan `options` run, once [`Shader::supports_on`] accepted it.
    fn plan_of(&self, options: &DispatchOptions) -> &ModePlan {
        self.plan.mode_on(options.mode, options.device.unwrap_or(self.device)).expect("checked by supports")
    }

    /// Whether [`Shader::encode`] can run `mode` for a `size` image:
    /// [`Shader::supports`], then the size against the limits of every
    /// resource and indirect dispatch of the mode's plan (else
    /// [`Error::BadSize`], saying which resource needs what; e.g. an
    /// interface buffer past a 128 MiB storage binding). Lets a tool skip one
    /// mode at a size another mode can still render.
    pub fn supports_size(&self, mode: Mode, size: (u32, u32)) -> Result<(), Error> {
        self.supports_size_on(mode, self.device, size)
    }

    /// [`Shader::supports_size`] for the mode's plan on `device`.
    pub fn supports_size_on(&self, mode: Mode, device: Device, size: (u32, u32)) -> Result<(), Error> {
        self.supports_on(mode, device)?;
        let plan = self.plan.mode_on(mode, device).expect("checked by supports");
        crate::validate::size(&self.plan, plan, size)
    }

    /// Records the program's passes for one image into `encoder`. The
    /// statistics of the last dispatch can be read with [`Shader::read_stats`]
    /// after the encoder's commands were submitted. Several `encode`s before
    /// one submit (views of several sizes, uniforms and options) each render
    /// their own image: the control and uniform blocks are copied in the
    /// encoder. `_queue` is not used (it was, for those blocks).
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        _queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &Bindings,
        options: DispatchOptions,
    ) -> Result<(), Error> {
        let device_kind = options.device.unwrap_or(self.device);
        self.supports_size_on(options.mode, device_kind, bindings.size)?;
        let whole = Arc::clone(&self.plan);
        let plan = whole.mode_on(options.mode, device_kind).expect("checked by supports");
        crate::validate::bindings(&self.layout, plan, bindings, options.rate_tile)?;
        let uniform_bytes = match &self.layout.uniforms {
            Some(block) => Some(self.uniform_values.bytes(block)?),
            None => None,
        };
        let (width, height) = bindings.size;
        self.frame = self.frame.wrapping_add(1).max(1);
        let control = Control {
            size: [width, height],
            force_refine: u32::from(options.force_refine),
            frame: self.frame,
            similarity: options.similarity,
            rate_tile: options.rate_tile,
            statistics: u32::from(options.statistics),
            reserved: 0,
        };
        // Copied in the encoder, not written with `queue.write_buffer` (which
        // lands before the whole submission runs): several `encode`s of this
        // shader before one submit each dispatch with their own values.
        stage(device, encoder, &self.control, bytemuck::bytes_of(&control));
        if let (Some(buffer), Some(bytes)) = (&self.uniforms, &uniform_bytes) {
            stage(device, encoder, buffer, bytes);
        }
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        for id in plan.resources() {
            if let Some(desc) = whole.resource(id) {
                self.pool.ensure(device, desc, bindings.size);
            }
        }
        let control_buffers = (&self.control, self.uniforms.as_ref());
        let resources =
            groups::resources_group(device, &self.layout, &self.resources_layout, control_buffers, bindings);
        let gbuffer = groups::gbuffer_group(device, &self.layout, &self.gbuffer_layout, bindings);
        let context =
            DispatchContext { size: bindings.size, forced: options.force_refine, rate_tile: options.rate_tile };
        let mut frame = Frame::new(bindings);
        let mut passes = 0;
        for step in &plan.steps {
            match step {
                Step::Clear { resource } => encoder.clear_buffer(self.pool.buffer(*resource), 0, None),
                Step::Pass(pass) => {
                    let stage = frame.stage_group(device, self, pass);
                    self.record_pass(device, encoder, pass, passes, [&resources, &gbuffer, &stage], context);
                    passes += 1;
                }
                Step::Readback { resource, bytes } => self.pool.copy_out(device, encoder, *resource, *bytes),
            }
        }
        if let Some(t) = &self.timestamps {
            let queries = 2 * passes as u32;
            encoder.resolve_query_set(&t.set, 0..queries, &t.resolve, 0);
            encoder.copy_buffer_to_buffer(&t.resolve, 0, &t.readback, 0, Some(8 * u64::from(queries)));
        }
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        self.last = Some((options, bindings.size));
        Ok(())
    }

    /// Records one compute pass of the plan: the `index`-th of its mode,
    /// whose timestamps take query slots `2 index` and `2 index + 1`.
    fn record_pass(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        pass: &Pass,
        index: usize,
        groups: [&wgpu::BindGroup; 3],
        context: DispatchContext,
    ) {
        let timestamp_writes = self.timestamps.as_ref().map(|t| wgpu::ComputePassTimestampWrites {
            query_set: &t.set,
            beginning_of_pass_write_index: Some(2 * index as u32),
            end_of_pass_write_index: Some(2 * index as u32 + 1),
        });
        let mut compute =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&pass.label), timestamp_writes });
        for (group, bind_group) in groups.iter().enumerate() {
            compute.set_bind_group(group as u32, Some(*bind_group), &[]);
        }
        for dispatch in &pass.dispatches {
            compute.set_pipeline(&self.pipelines[&(pass.kernel, dispatch.entry.clone())]);
            if let Some(arguments) = dispatch.arguments {
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("mrsl indirect arguments"),
                    layout: &self.arguments_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: mrsl_abi::BINDING_ARGS,
                        resource: self.pool.buffer(arguments).as_entire_binding(),
                    }],
                });
                compute.set_bind_group(GROUP_ARGS, Some(&group), &[]);
            }
            match dispatch.workgroups {
                Workgroups::Indirect { buffer, offset, .. } => {
                    compute.dispatch_workgroups_indirect(self.pool.buffer(buffer), offset)
                }
                direct => {
                    let (x, y) = direct.direct(context).expect("a direct dispatch");
                    compute.dispatch_workgroups(x, y, 1);
                }
            }
        }
    }

    /// The per-pixel refine mask of the last dispatch of a mode with coarse
    /// effects: x bit k set when coarse effect k (`layout().stats.counters[k]`,
    /// in dependency order, not the declaration order of `Stats::effects`)
    /// was evaluated per pixel, y bit k when it was taken from the dynamic
    /// mode's 2x2 level; [`Layout::refine_mask_bit`] gives an effect's bit and
    /// [`Layout::decode_refine_mask`] a texel's effects by name. `None` before
    /// any such dispatch; a dispatch with `DispatchOptions::statistics` off
    /// leaves it as it was.
    pub fn refine_mask(&self) -> Option<&wgpu::Texture> {
        self.pool.texture(ResourceId::RefineMask)
    }

    /// Reads the statistics of the last submitted dispatch (waits for the GPU).
    /// [`Error::StatisticsOff`] when it ran with `DispatchOptions::statistics` off.
    pub fn read_stats(&self, device: &wgpu::Device) -> Result<Stats, Error> {
        let (options, size) = self.last.ok_or_else(|| Error::Readback("nothing was dispatched yet".into()))?;
        if !options.statistics {
            return Err(Error::StatisticsOff);
        }
        let plan = self.plan_of(&options);
        let read = |id: ResourceId| -> Result<Vec<u32>, Error> {
            let buffer = self.pool.readback(id).ok_or_else(|| Error::Readback(format!("{id:?} was not read back")))?;
            read_buffer(device, buffer)
        };
        let counters = read(ResourceId::Statistics)?;
        let timings = self.read_timings(device)?;
        let listed = match plan.counts.samples {
            SampleCount::Listed { resource, word } => read(resource)?[word] as u64,
            _ => 0,
        };
        let mut stats = Stats::new(&self.layout, &plan.counts, options, size, &counters, timings, listed);
        if let Some(lists) = &plan.counts.work_lists {
            let words = read(lists.resource)?;
            stats.work_lists =
                lists.levels.iter().map(|&level| words[(lists.words_per_level * level) as usize] as u64).collect();
            let queued: u64 = stats.work_lists.iter().sum();
            let lane = u64::from(lists.lanes);
            let lanes: u64 = stats.work_lists.iter().map(|c| c.div_ceil(lane) * lane).sum();
            stats.lane_utilisation = Some(if lanes == 0 { 1.0 } else { queued as f64 / lanes as f64 });
        }
        Ok(stats)
    }

    /// The GPU times of the last submitted dispatch's passes (waits for the
    /// GPU), with statistics on or off; `None` where the device has no
    /// timestamp queries. Meaningful on a GPU only: a CPU device such as
    /// lavapipe writes a timestamp when its queue thread reaches it, not
    /// when the shader work ends (docs/runtime.md, section 9). Call
    /// [`Shader::set_timestamp_period`] first for times in milliseconds.
    pub fn read_timings(&self, device: &wgpu::Device) -> Result<Option<crate::Timings>, Error> {
        let (options, _) = self.last.ok_or_else(|| Error::Readback("nothing was dispatched yet".into()))?;
        let plan = self.plan_of(&options);
        match &self.timestamps {
            Some(t) => Ok(Some(timings(plan, &read_buffer(device, &t.readback)?, t.period_ns))),
            None => Ok(None),
        }
    }
}

/// The passes' GPU times from their timestamps (two per pass, in plan
/// order): summed by stage, and from the first pass's beginning to the last
/// pass's end.
/// Records a copy of `bytes` into `target` (a uniform block) in `encoder`,
/// through a buffer made for it.
fn stage(device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder, target: &wgpu::Buffer, bytes: &[u8]) {
    use wgpu::util::DeviceExt;
    let staging = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("mrsl staged block"),
        contents: bytes,
        usage: wgpu::BufferUsages::COPY_SRC,
    });
    encoder.copy_buffer_to_buffer(&staging, 0, target, 0, Some(bytes.len() as u64));
}

fn timings(plan: &ModePlan, ticks: &[u64], period_ns: f32) -> crate::Timings {
    let ms = |ticks: u64| ticks as f64 * f64::from(period_ns) / 1e6;
    let mut t = crate::Timings { coarse_ms: 0.0, coarse2_ms: 0.0, fine_ms: 0.0, total_ms: 0.0 };
    let passes: Vec<&Pass> = plan.passes().collect();
    for (index, pass) in passes.iter().enumerate() {
        let time = ms(ticks[2 * index + 1].saturating_sub(ticks[2 * index]));
        match pass.stage {
            Stage::Coarse => t.coarse_ms += time,
            Stage::Coarse2x2 => t.coarse2_ms += time,
            Stage::Fine => t.fine_ms += time,
        }
    }
    if !passes.is_empty() {
        t.total_ms = ms(ticks[2 * passes.len() - 1].saturating_sub(ticks[0]));
    }
    t
}

/// What one dispatch binds besides the pool: the engine's output views and
/// shading-rate view, and each kernel's stage group once made.
struct Frame<'a> {
    outputs: HashMap<&'a str, wgpu::TextureView>,
    shading_rate: Option<wgpu::TextureView>,
    stage_groups: HashMap<KernelRef, wgpu::BindGroup>,
}

impl<'a> Frame<'a> {
    fn new(bindings: &'a Bindings<'a>) -> Frame<'a> {
        Frame {
            outputs: bindings.outputs.iter().map(|(k, t)| (k.as_str(), t.create_view(&Default::default()))).collect(),
            shading_rate: bindings.shading_rate.map(|t| t.create_view(&Default::default())),
            stage_groups: HashMap::new(),
        }
    }

    /// Group 2 of `pass`: each binding the resource the plan names.
    fn stage_group(&mut self, device: &wgpu::Device, shader: &Shader, pass: &Pass) -> wgpu::BindGroup {
        if let Some(group) = self.stage_groups.get(&pass.kernel) {
            return group.clone();
        }
        let outputs = &shader.layout.outputs;
        let entries: Vec<wgpu::BindGroupEntry> = pass
            .bindings
            .iter()
            .map(|b| wgpu::BindGroupEntry {
                binding: b.binding,
                resource: match b.resource {
                    ResourceId::Output { index } => {
                        wgpu::BindingResource::TextureView(&self.outputs[outputs[index].name.as_str()])
                    }
                    ResourceId::ShadingRate => {
                        wgpu::BindingResource::TextureView(self.shading_rate.as_ref().expect("validated"))
                    }
                    id => shader.pool.binding(id),
                },
            })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(pass.kernel.kind.name()),
            layout: &shader.stage_layouts[&pass.kernel],
            entries: &entries,
        });
        self.stage_groups.insert(pass.kernel, group.clone());
        group
    }
}

/// Each kernel's stage layout and pipelines, and the kernel kinds the device
/// refused with its reasons.
struct KernelPipelines {
    stage_layouts: HashMap<KernelRef, wgpu::BindGroupLayout>,
    pipelines: HashMap<PipelineKey, wgpu::ComputePipeline>,
    unavailable: HashMap<KernelKind, String>,
}

/// Makes every kernel's stage layout and pipelines over the shared groups
/// (`resources`, `gbuffer`, `arguments`: groups 0, 1 and 3).
fn kernel_pipelines(
    device: &wgpu::Device,
    program: &CompiledProgram,
    [resources_layout, gbuffer_layout, arguments_layout]: [&wgpu::BindGroupLayout; 3],
) -> KernelPipelines {
    let plan = &program.layout.plan;
    // The entry points that write indirect arguments also see group 3.
    let writes_arguments: HashSet<(KernelRef, &str)> = plan
        .modes
        .iter()
        .flat_map(|m| m.passes())
        .flat_map(|p| p.dispatches.iter().filter(|d| d.arguments.is_some()).map(|d| (p.kernel, d.entry.as_str())))
        .collect();
    // A kernel kind this device cannot run (its stage group beyond the
    // device's limits, say the hierarchical kernel's outputs and records
    // beyond `max_storage_textures_per_shader_stage`) refuses the modes
    // that need it when they are dispatched, not every mode here: each
    // kernel's layout and pipelines are made under their own error scope.
    let mut unavailable: HashMap<KernelKind, String> = HashMap::new();
    let mut stage_layouts = HashMap::new();
    let mut pipelines = HashMap::new();
    for kernel in &program.kernels {
        let kernel_ref = KernelRef::new(kernel.kind, kernel.block_size);
        let Some(pass) = plan.modes.iter().flat_map(|m| m.passes()).find(|p| p.kernel == kernel_ref) else {
            continue;
        };
        if let Some(reason) = groups::missing_feature(device, &pass.bindings) {
            unavailable.insert(kernel.kind, reason);
            continue;
        }
        let workgroup_limit = device.limits().max_compute_workgroup_storage_size;
        if pass.workgroup_bytes > workgroup_limit {
            let reason = format!(
                "it needs {} bytes of workgroup memory, more than the device's {workgroup_limit} \
                 (`max_compute_workgroup_storage_size`)",
                pass.workgroup_bytes
            );
            unavailable.insert(kernel.kind, reason);
            continue;
        }
        let kind_scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let stage_layout = groups::stage_layout(device, kernel.kind.name(), &pass.bindings);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(kernel.kind.name()),
            source: wgpu::ShaderSource::Wgsl(kernel.wgsl.as_str().into()),
        });
        let groups = [Some(resources_layout), Some(gbuffer_layout), Some(&stage_layout), Some(arguments_layout)];
        let pipeline_layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(kernel.kind.name()),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let (plain, with_arguments) = (pipeline_layout(&groups[..3]), pipeline_layout(&groups));
        for &entry in kernel.entry_points() {
            let layout = if writes_arguments.contains(&(kernel_ref, entry)) { &with_arguments } else { &plain };
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            });
            pipelines.insert((kernel_ref, entry.to_string()), pipeline);
        }
        stage_layouts.insert(kernel_ref, stage_layout);
        if let Some(error) = pollster::block_on(kind_scope.pop()) {
            unavailable.insert(kernel.kind, describe(&error));
        }
    }
    KernelPipelines { stage_layouts, pipelines, unavailable }
}
