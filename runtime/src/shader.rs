//! A compiled mrsl program instantiated on a wgpu device: pipelines, bind
//! group layouts, the control and uniform blocks, and the interface buffer.

use crate::error::Error;
use crate::{Mode, Stats};
use mrsl::layout::Layout;
use mrsl::{KernelKind, Program};
use std::collections::HashMap;

/// Resources an engine binds for one dispatch. Every name is a declaration of
/// the program; the layout says which are needed.
#[derive(Default)]
pub struct Bindings<'a> {
    /// Width and height of the shaded image in pixels.
    pub size: (u32, u32),
    /// G-buffer channel textures, by `in` name.
    pub channels: HashMap<String, &'a wgpu::Texture>,
    /// Sampled textures, by `uniform texture2d` name.
    pub textures: HashMap<String, &'a wgpu::TextureView>,
    /// Samplers, by `uniform sampler` name.
    pub samplers: HashMap<String, &'a wgpu::Sampler>,
    /// Output storage textures, by `fine out` name.
    pub outputs: HashMap<String, &'a wgpu::Texture>,
}

/// Per-dispatch settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DispatchOptions {
    pub mode: Mode,
    /// Treat every refine predicate as true (and refine every coarse effect):
    /// the output must then equal the reference.
    pub force_refine: bool,
    /// Hierarchical mode: a pixel is interpolated only while the variance of
    /// its four neighbours' values (each component, linear) is at most this.
    pub similarity: f32,
}

impl DispatchOptions {
    /// Default similarity threshold of the hierarchical mode (variance, linear units).
    pub const DEFAULT_SIMILARITY: f32 = 1e-3;

    pub fn new(mode: Mode) -> DispatchOptions {
        DispatchOptions { mode, force_refine: false, similarity: Self::DEFAULT_SIMILARITY }
    }
}

/// Buffers of the hierarchical mode.
struct HierBuffers {
    values: wgpu::Buffer,
    work: wgpu::Buffer,
    queue: wgpu::Buffer,
    args: wgpu::Buffer,
}

/// Timestamped passes: reference, coarse, fine, dynamic coarse 2x2.
const STAGES: usize = 4;

struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f32,
}

/// A program on a device.
pub struct Shader {
    layout: Layout,
    resources_layout: wgpu::BindGroupLayout,
    gbuffer_layout: wgpu::BindGroupLayout,
    stage_layouts: HashMap<KernelKind, wgpu::BindGroupLayout>,
    pipelines: HashMap<(KernelKind, u32), wgpu::ComputePipeline>,
    /// The hierarchical kernel's pipelines, by index in `HIERARCHICAL_ENTRY_POINTS`.
    hierarchical: HashMap<usize, wgpu::ComputePipeline>,
    /// Hierarchical mode buffers (values, work lists, queues) and the size they were made for.
    hier_buffers: Option<(HierBuffers, (u32, u32))>,
    /// The checkerboard kernel's pipelines: `cb_shade`, `cb_final`.
    checkerboard: Vec<wgpu::ComputePipeline>,
    /// Whether the dispatch being encoded forces refinement.
    forced: bool,
    args_group_layout: wgpu::BindGroupLayout,
    queue_readback: wgpu::Buffer,
    control: wgpu::Buffer,
    uniforms: Option<wgpu::Buffer>,
    uniform_values: HashMap<String, Vec<f64>>,
    /// Interface buffers by (block size, tagged), with the size they were made for.
    interfaces: HashMap<(u32, bool), (wgpu::Buffer, (u32, u32))>,
    /// Dispatch counter, written to the control block (validity tags of the dynamic mode).
    frame: u32,
    /// The fine kernel's per-pixel refine mask, with the size it was made for.
    rate: Option<(wgpu::Texture, (u32, u32))>,
    stats: wgpu::Buffer,
    stats_readback: wgpu::Buffer,
    timestamps: Option<Timestamps>,
    last: Option<(DispatchOptions, (u32, u32))>,
}

fn sample_grid(size: (u32, u32), block: u32) -> (u32, u32) {
    ((size.0 + block - 2) / block + 1, (size.1 + block - 2) / block + 1)
}

impl Shader {
    /// Creates the pipelines of every kernel in `program`.
    pub fn new(device: &wgpu::Device, program: &Program) -> Result<Shader, Error> {
        let layout = program.layout.clone();
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let resources_layout = resources_layout(device, &layout);
        let gbuffer_layout = gbuffer_layout(device, &layout);
        let mut stage_layouts = HashMap::new();
        for kind in [
            KernelKind::Coarse,
            KernelKind::Fine,
            KernelKind::Reference,
            KernelKind::DynamicCoarse,
            KernelKind::DynamicFine,
            KernelKind::Hierarchical,
            KernelKind::Checkerboard,
        ] {
            stage_layouts.insert(kind, stage_layout(device, &layout, kind));
        }
        let mut pipelines = HashMap::new();
        let mut hierarchical = HashMap::new();
        let mut checkerboard = vec![];
        let args_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mrsl hierarchical args"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        for kernel in &program.kernels {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(kernel.entry_point),
                source: wgpu::ShaderSource::Wgsl(kernel.wgsl.as_str().into()),
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(kernel.entry_point),
                bind_group_layouts: &[
                    Some(&resources_layout),
                    Some(&gbuffer_layout),
                    Some(&stage_layouts[&kernel.kind]),
                ],
                immediate_size: 0,
            });
            // The hierarchical `args` entry points also see the indirect arguments (group 3).
            let args_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("mrsl hierarchical args"),
                bind_group_layouts: &[
                    Some(&resources_layout),
                    Some(&gbuffer_layout),
                    Some(&stage_layouts[&kernel.kind]),
                    Some(&args_group_layout),
                ],
                immediate_size: 0,
            });
            for (k, entry) in kernel.entry_points.iter().enumerate() {
                let layout = if entry.starts_with("hier_args") { &args_layout } else { &pipeline_layout };
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                });
                if kernel.kind == KernelKind::Hierarchical {
                    hierarchical.insert(k, pipeline);
                } else if kernel.kind == KernelKind::Checkerboard {
                    checkerboard.push(pipeline);
                } else {
                    pipelines.insert((kernel.kind, kernel.block_size.unwrap_or(1)), pipeline);
                }
            }
        }
        let control = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mrsl control"),
            size: layout.control.size as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniforms = layout.uniforms.as_ref().map(|u| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl uniforms"),
                size: u.size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        // One counter per coarse effect, plus the dynamic mode's 2x2 sample count.
        let counters = (layout.stats.counters.len() + 1) as u64 * 4;
        let stats = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mrsl stats"),
            size: counters,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let stats_readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mrsl stats readback"),
            size: counters,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| Timestamps {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("mrsl timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * STAGES as u32,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl timestamps resolve"),
                size: 16 * STAGES as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl timestamps readback"),
                size: 16 * STAGES as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            period_ns: 1.0,
        });
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        Ok(Shader {
            layout,
            resources_layout,
            gbuffer_layout,
            stage_layouts,
            pipelines,
            hierarchical,
            hier_buffers: None,
            checkerboard,
            forced: false,
            args_group_layout,
            queue_readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl hierarchical queue readback"),
                size: 80,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            control,
            uniforms,
            uniform_values: HashMap::new(),
            interfaces: HashMap::new(),
            frame: 0,
            rate: None,
            stats,
            stats_readback,
            timestamps,
            last: None,
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
    /// column, bools as 0/1). Uniforms not set take their declared default.
    pub fn set_uniform(&mut self, name: &str, values: &[f64]) -> Result<(), Error> {
        let field = self
            .layout
            .uniforms
            .as_ref()
            .and_then(|u| u.fields.iter().find(|f| f.name == name))
            .ok_or_else(|| Error::UnknownUniform(name.to_string()))?;
        let expected = components(&field.ty);
        if values.len() != expected {
            return Err(Error::UniformComponents {
                name: name.into(),
                ty: field.ty.clone(),
                expected,
                found: values.len(),
            });
        }
        self.uniform_values.insert(name.to_string(), values.to_vec());
        Ok(())
    }

    /// The uniform block's bytes, from set values and defaults.
    fn uniform_bytes(&self) -> Result<Vec<u8>, Error> {
        let Some(block) = &self.layout.uniforms else { return Ok(vec![]) };
        let mut bytes = vec![0u8; block.size as usize];
        for field in &block.fields {
            let values = self
                .uniform_values
                .get(&field.name)
                .or(field.default.as_ref())
                .ok_or_else(|| Error::MissingUniform(field.name.clone()))?;
            write_field(&mut bytes[field.offset as usize..], &field.wgsl_type, &field.ty, values);
        }
        Ok(bytes)
    }

    /// Checks `bindings` against the layout.
    fn validate(&self, bindings: &Bindings, mode: Mode) -> Result<(), Error> {
        let (width, height) = bindings.size;
        let missing = |what: &str| {
            Err(Error::UnsupportedMode(mode.name().into(), format!("the program was compiled without {what}")))
        };
        match mode {
            Mode::Reference if !self.pipelines.contains_key(&(KernelKind::Reference, 1)) => {
                return missing("its reference kernel");
            }
            Mode::Coarse2x2 | Mode::Coarse4x4 | Mode::Dynamic => {
                let block = mode.block_size().unwrap_or(4);
                // The dynamic mode runs the 4x4 coarse kernel but its own fine kernel.
                let fine_needed = mode != Mode::Dynamic;
                if !self.pipelines.contains_key(&(KernelKind::Coarse, block))
                    || (fine_needed && !self.pipelines.contains_key(&(KernelKind::Fine, block)))
                {
                    return missing(&format!("{block}x{block} coarse and fine kernels"));
                }
                if mode == Mode::Dynamic
                    && (!self.pipelines.contains_key(&(KernelKind::DynamicCoarse, 2))
                        || !self.pipelines.contains_key(&(KernelKind::DynamicFine, 4)))
                {
                    return missing("the dynamic-mode kernels");
                }
            }
            Mode::Hierarchical if self.hierarchical.is_empty() => return missing("the hierarchical kernel"),
            Mode::Checkerboard if self.checkerboard.is_empty() => return missing("the checkerboard kernel"),
            _ => {}
        }
        if width == 0 || height == 0 {
            return Err(Error::BadSize { width, height, reason: "it is empty".into() });
        }
        if width > 16384 || height > 16384 {
            return Err(Error::BadSize { width, height, reason: "the largest supported side is 16384".into() });
        }
        if mode == Mode::Dynamic {
            let (nx, ny) = sample_grid(bindings.size, 2);
            let bytes = nx as u64 * ny as u64 * (self.layout.interface.stride_words as u64 + 1) * 4;
            if bytes > 128 << 20 {
                return Err(Error::BadSize {
                    width,
                    height,
                    reason: format!(
                        "the 2x2 level would need {} MiB, more than a 128 MiB storage binding",
                        bytes >> 20
                    ),
                });
            }
        }
        if mode == Mode::Hierarchical {
            // Work lists hold about 1.56 words per pixel; a level's shading
            // dispatch covers at most 65535 workgroups of 64 lanes.
            let pixels = width as u64 * height as u64;
            if pixels * 2 * 4 > 128 << 20 || pixels / 2 > 65535 * 64 {
                return Err(Error::BadSize { width, height, reason: "the hierarchical work lists would exceed the storage or dispatch limits (about 4 million pixels per level)".into() });
            }
        }
        if matches!(mode, Mode::Hierarchical | Mode::Checkerboard) {
            let bytes = width as u64 * height as u64 * self.layout.hierarchical.record_words as u64 * 4;
            if bytes > 128 << 20 {
                return Err(Error::BadSize {
                    width,
                    height,
                    reason: format!(
                        "the hierarchical records would need {} MiB, more than a 128 MiB storage binding",
                        bytes >> 20
                    ),
                });
            }
        }
        if let Some(block) = mode.block_size() {
            let (nx, ny) = sample_grid(bindings.size, block);
            let bytes = nx as u64 * ny as u64 * self.layout.interface.stride_words as u64 * 4;
            if bytes > 128 << 20 {
                return Err(Error::BadSize {
                    width,
                    height,
                    reason: format!(
                        "the interface would need {} MiB, more than a 128 MiB storage binding",
                        bytes >> 20
                    ),
                });
            }
        }
        let check_size = |what: &'static str, name: &str, t: &wgpu::Texture| {
            if (t.width(), t.height()) != (width, height) {
                return Err(Error::SizeMismatch {
                    what,
                    name: name.into(),
                    width,
                    height,
                    found_width: t.width(),
                    found_height: t.height(),
                });
            }
            Ok(())
        };
        for ch in &self.layout.channels {
            let t = bindings.channels.get(&ch.name).ok_or_else(|| Error::MissingChannel(ch.name.clone()))?;
            let need = components(&ch.ty) as u32;
            let fits = match (ch.sample_type, t.format().sample_type(None, None)) {
                ("uint", Some(wgpu::TextureSampleType::Uint)) => true,
                ("sint", Some(wgpu::TextureSampleType::Sint)) => true,
                ("unfilterable-float", Some(wgpu::TextureSampleType::Float { .. })) => true,
                _ => false,
            } && t.format().components() as u32 >= need.min(4)
                && (need != 3 || t.format().components() == 4);
            if !fits {
                return Err(Error::ChannelFormat {
                    channel: ch.name.clone(),
                    ty: ch.ty.clone(),
                    expected: ch.format.into(),
                    components: need,
                    found: t.format(),
                });
            }
            check_size("G-buffer channel", &ch.name, t)?;
        }
        for t in &self.layout.textures {
            if !bindings.textures.contains_key(&t.name) {
                return Err(Error::MissingTexture(t.name.clone()));
            }
        }
        for s in &self.layout.samplers {
            if !bindings.samplers.contains_key(&s.name) {
                return Err(Error::MissingSampler(s.name.clone()));
            }
        }
        for o in &self.layout.outputs {
            let t = bindings.outputs.get(&o.name).ok_or_else(|| Error::MissingOutput(o.name.clone()))?;
            let expected = storage_format(&o.format);
            if t.format() != expected {
                return Err(Error::OutputFormat { name: o.name.clone(), expected, found: t.format() });
            }
            if !t.usage().contains(wgpu::TextureUsages::STORAGE_BINDING) {
                return Err(Error::OutputUsage(o.name.clone()));
            }
            check_size("output", &o.name, t)?;
        }
        Ok(())
    }

    /// Records the program's passes for one image into `encoder`. The
    /// statistics of the last dispatch can be read with [`Shader::read_stats`]
    /// after the encoder's commands were submitted.
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &Bindings,
        options: DispatchOptions,
    ) -> Result<(), Error> {
        let mode = options.mode;
        self.validate(bindings, mode)?;
        let (width, height) = bindings.size;
        let mut control = [0u32; 8];
        control[0] = width;
        control[1] = height;
        control[2] = u32::from(options.force_refine);
        self.frame = self.frame.wrapping_add(1).max(1);
        self.forced = options.force_refine;
        control[3] = self.frame;
        control[4] = options.similarity.to_bits();
        queue.write_buffer(&self.control, 0, bytemuck::cast_slice(&control));
        if let Some(buffer) = &self.uniforms {
            queue.write_buffer(buffer, 0, &self.uniform_bytes()?);
        }
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let resources = self.resources_group(device, bindings);
        let gbuffer = self.gbuffer_group(device, bindings);
        let views: HashMap<&str, wgpu::TextureView> =
            bindings.outputs.iter().map(|(k, t)| (k.as_str(), t.create_view(&Default::default()))).collect();
        encoder.clear_buffer(&self.stats, 0, None);
        let tiles = (width.div_ceil(mrsl::layout::TILE), height.div_ceil(mrsl::layout::TILE));
        if mode == Mode::Hierarchical {
            self.encode_hierarchical(device, encoder, bindings, &resources, &gbuffer, &views);
        } else if mode == Mode::Checkerboard {
            self.encode_checkerboard(device, encoder, bindings, &resources, &gbuffer, &views);
        } else {
            match mode.block_size() {
                None => {
                    let stage = self.stage_group(device, KernelKind::Reference, None, None, &views);
                    self.pass(
                        encoder,
                        "mrsl reference",
                        0,
                        (KernelKind::Reference, 1),
                        &[&resources, &gbuffer, &stage],
                        tiles,
                    );
                }
                Some(block) => {
                    let interface = self.interface(device, block, false, bindings.size).clone();
                    self.ensure_rate_image(device, bindings.size);
                    let dynamic = mode == Mode::Dynamic;
                    let inner =
                        if dynamic { Some(self.interface(device, 2, true, bindings.size).clone()) } else { None };
                    let coarse_stage = self.stage_group(device, KernelKind::Coarse, Some(&interface), None, &views);
                    let fine_kind = if dynamic { KernelKind::DynamicFine } else { KernelKind::Fine };
                    let fine_stage = self.stage_group(device, fine_kind, Some(&interface), inner.as_ref(), &views);
                    let (nx, ny) = sample_grid(bindings.size, block);
                    let coarse_groups = (nx.div_ceil(8), ny.div_ceil(8));
                    self.pass(
                        encoder,
                        "mrsl coarse",
                        1,
                        (KernelKind::Coarse, block),
                        &[&resources, &gbuffer, &coarse_stage],
                        coarse_groups,
                    );
                    if dynamic {
                        let stage = self.stage_group(
                            device,
                            KernelKind::DynamicCoarse,
                            Some(&interface),
                            inner.as_ref(),
                            &views,
                        );
                        let (nx, ny) = sample_grid(bindings.size, 2);
                        self.pass(
                            encoder,
                            "mrsl dynamic coarse 2x2",
                            3,
                            (KernelKind::DynamicCoarse, 2),
                            &[&resources, &gbuffer, &stage],
                            (nx.div_ceil(8), ny.div_ceil(8)),
                        );
                    }
                    self.pass(encoder, "mrsl fine", 2, (fine_kind, block), &[&resources, &gbuffer, &fine_stage], tiles);
                }
            }
        }
        encoder.copy_buffer_to_buffer(&self.stats, 0, &self.stats_readback, 0, None);
        if let Some(t) = &self.timestamps {
            encoder.resolve_query_set(&t.set, 0..2 * STAGES as u32, &t.resolve, 0);
            encoder.copy_buffer_to_buffer(&t.resolve, 0, &t.readback, 0, None);
        }
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        self.last = Some((options, bindings.size));
        Ok(())
    }

    /// The hierarchical mode: level 0, then per level classify, args and an
    /// indirect shade over the compacted work list, then the final per-pixel pass.
    fn encode_hierarchical(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &Bindings,
        resources: &wgpu::BindGroup,
        gbuffer: &wgpu::BindGroup,
        views: &HashMap<&str, wgpu::TextureView>,
    ) {
        let (w, h) = bindings.size;
        let stage = self.record_stage(device, KernelKind::Hierarchical, bindings.size, views);
        let (buffers, _) = self.hier_buffers.as_ref().expect("created by record_stage");
        encoder.clear_buffer(&buffers.queue, 0, None);
        let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl hierarchical args"),
            layout: &self.args_group_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffers.args.as_entire_binding() }],
        });
        let count = |start: u32, step: u32, n: u32| if n > start { (n - start - 1) / step + 1 } else { 0 };
        let groups = |x: u32, y: u32| (x.div_ceil(8).max(1), y.div_ceil(8).max(1));
        let lattices = [
            groups(count(2, 4, w), count(2, 4, h)),
            groups(count(0, 2, w), count(0, 2, h)),
            groups(count(1, 2, w), count(1, 2, h)),
            groups(w, h),
        ];
        {
            let mut pass = self.begin_pass(encoder, "mrsl hierarchical levels", 1, &[resources, gbuffer, &stage]);
            let (gx, gy) = groups(count(0, 4, w), count(0, 4, h));
            pass.set_pipeline(&self.hierarchical[&0]);
            pass.dispatch_workgroups(gx, gy, 1);
            for (level, (gx, gy)) in lattices.iter().enumerate() {
                let base = 1 + 3 * level;
                pass.set_pipeline(&self.hierarchical[&base]);
                pass.dispatch_workgroups(*gx, *gy, 1);
                pass.set_pipeline(&self.hierarchical[&(base + 1)]);
                pass.set_bind_group(3, Some(&args), &[]);
                pass.dispatch_workgroups(1, 1, 1);
                pass.set_pipeline(&self.hierarchical[&(base + 2)]);
                pass.dispatch_workgroups_indirect(&buffers.args, 4 * (level as u64 + 1) * 4);
            }
        }
        {
            let mut pass = self.begin_pass(encoder, "mrsl hierarchical final", 2, &[resources, gbuffer, &stage]);
            pass.set_pipeline(&self.hierarchical[&13]);
            pass.dispatch_workgroups(w.div_ceil(mrsl::layout::TILE), h.div_ceil(mrsl::layout::TILE), 1);
        }
        encoder.copy_buffer_to_buffer(&buffers.queue, 0, &self.queue_readback, 0, None);
    }

    /// The checkerboard baseline: shade the coarse effects in half the quads,
    /// then reconstruct and finish every pixel.
    fn encode_checkerboard(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &Bindings,
        resources: &wgpu::BindGroup,
        gbuffer: &wgpu::BindGroup,
        views: &HashMap<&str, wgpu::TextureView>,
    ) {
        let (w, h) = bindings.size;
        let stage = self.record_stage(device, KernelKind::Checkerboard, bindings.size, views);
        let mut pass = self.begin_pass(encoder, "mrsl checkerboard", 1, &[resources, gbuffer, &stage]);
        // cb_shade: 16 shaded quads per workgroup along a row of quads.
        let (quads_x, quads_y) = (w.div_ceil(2), h.div_ceil(2));
        pass.set_pipeline(&self.checkerboard[0]);
        let shaded_per_row = if self.forced { quads_x } else { quads_x.div_ceil(2) };
        pass.dispatch_workgroups(shaded_per_row.div_ceil(16).max(1), quads_y, 1);
        pass.set_pipeline(&self.checkerboard[1]);
        pass.dispatch_workgroups(w.div_ceil(mrsl::layout::TILE), h.div_ceil(mrsl::layout::TILE), 1);
    }

    /// Group 2 of the modes that keep a record per pixel (hierarchical, checkerboard):
    /// the records (and for the hierarchical mode its work lists and queues), the
    /// outputs, the statistics and the rate image; (re)creates the record
    /// buffers and the rate image for `size` first.
    fn record_stage(
        &mut self,
        device: &wgpu::Device,
        kind: KernelKind,
        size: (u32, u32),
        views: &HashMap<&str, wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        self.ensure_rate_image(device, size);
        self.ensure_hier_buffers(device, size);
        let (buffers, _) = self.hier_buffers.as_ref().expect("created just above");
        let l = &self.layout;
        let hl = &l.hierarchical;
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: hl.values_binding, resource: buffers.values.as_entire_binding() }];
        if kind == KernelKind::Hierarchical {
            entries.push(wgpu::BindGroupEntry { binding: hl.work_binding, resource: buffers.work.as_entire_binding() });
            entries
                .push(wgpu::BindGroupEntry { binding: hl.queue_binding, resource: buffers.queue.as_entire_binding() });
        }
        self.finish_stage_group(device, kind, entries, Some(views))
    }

    fn ensure_hier_buffers(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        if self.hier_buffers.as_ref().is_some_and(|(_, s)| *s == size) {
            return;
        }
        let (w, h) = (size.0 as u64, size.1 as u64);
        let count = |start: u64, step: u64, n: u64| if n > start { (n - start - 1) / step + 1 } else { 0 };
        let work_words =
            count(2, 4, w) * count(2, 4, h) + count(0, 2, w) * count(0, 2, h) + count(1, 2, w) * count(1, 2, h) + w * h;
        let storage = |label, bytes: u64, extra| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(4),
                usage: wgpu::BufferUsages::STORAGE | extra,
                mapped_at_creation: false,
            })
        };
        let record = self.layout.hierarchical.record_words as u64;
        let buffers = HierBuffers {
            values: storage("mrsl hierarchical values", w * h * record * 4, wgpu::BufferUsages::empty()),
            work: storage("mrsl hierarchical work lists", work_words * 4, wgpu::BufferUsages::empty()),
            queue: storage("mrsl hierarchical queues", 80, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC),
            args: storage("mrsl hierarchical dispatch arguments", 80, wgpu::BufferUsages::INDIRECT),
        };
        self.hier_buffers = Some((buffers, size));
    }

    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        stage: u32,
        pipeline: (KernelKind, u32),
        groups: &[&wgpu::BindGroup],
        workgroups: (u32, u32),
    ) {
        let mut pass = self.begin_pass(encoder, label, stage, groups);
        pass.set_pipeline(&self.pipelines[&pipeline]);
        pass.dispatch_workgroups(workgroups.0, workgroups.1, 1);
    }

    /// Begins a compute pass that writes stage slot `stage`'s timestamps
    /// (see `read_stats`) and binds `groups` as groups 0, 1, 2, ...
    fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        stage: u32,
        groups: &[&wgpu::BindGroup],
    ) -> wgpu::ComputePass<'e> {
        let timestamp_writes = self.timestamps.as_ref().map(|t| wgpu::ComputePassTimestampWrites {
            query_set: &t.set,
            beginning_of_pass_write_index: Some(2 * stage),
            end_of_pass_write_index: Some(2 * stage + 1),
        });
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes });
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, Some(*g), &[]);
        }
        pass
    }

    /// The interface buffer for `block`, (re)created when the size changes.
    /// Tagged records (the dynamic mode's 2x2 level) have one more word.
    fn interface(&mut self, device: &wgpu::Device, block: u32, tagged: bool, size: (u32, u32)) -> &wgpu::Buffer {
        let stride = (self.layout.interface.stride_words + u32::from(tagged)).max(1) as u64;
        let fresh = self.interfaces.get(&(block, tagged)).is_none_or(|(_, s)| *s != size);
        if fresh {
            let (nx, ny) = sample_grid(size, block);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl interface"),
                size: nx as u64 * ny as u64 * stride * 4,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            self.interfaces.insert((block, tagged), (buffer, size));
        }
        &self.interfaces[&(block, tagged)].0
    }

    fn resources_group(&self, device: &wgpu::Device, bindings: &Bindings) -> wgpu::BindGroup {
        let l = &self.layout;
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: l.control.binding, resource: self.control.as_entire_binding() }];
        if let (Some(u), Some(buffer)) = (&l.uniforms, &self.uniforms) {
            entries.push(wgpu::BindGroupEntry { binding: u.binding, resource: buffer.as_entire_binding() });
        }
        for t in &l.textures {
            entries.push(wgpu::BindGroupEntry {
                binding: t.binding,
                resource: wgpu::BindingResource::TextureView(bindings.textures[&t.name]),
            });
        }
        for s in &l.samplers {
            entries.push(wgpu::BindGroupEntry {
                binding: s.binding,
                resource: wgpu::BindingResource::Sampler(bindings.samplers[&s.name]),
            });
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl resources"),
            layout: &self.resources_layout,
            entries: &entries,
        })
    }

    fn gbuffer_group(&self, device: &wgpu::Device, bindings: &Bindings) -> wgpu::BindGroup {
        let views: Vec<(u32, wgpu::TextureView)> = self
            .layout
            .channels
            .iter()
            .map(|c| (c.binding, bindings.channels[&c.name].create_view(&Default::default())))
            .collect();
        let entries: Vec<wgpu::BindGroupEntry> = views
            .iter()
            .map(|(b, v)| wgpu::BindGroupEntry { binding: *b, resource: wgpu::BindingResource::TextureView(v) })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl g-buffer"),
            layout: &self.gbuffer_layout,
            entries: &entries,
        })
    }

    fn stage_group(
        &self,
        device: &wgpu::Device,
        kind: KernelKind,
        interface: Option<&wgpu::Buffer>,
        inner: Option<&wgpu::Buffer>,
        outputs: &HashMap<&str, wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        let l = &self.layout;
        let mut entries = vec![];
        if let (Some(buffer), true) = (interface, kind != KernelKind::Reference) {
            entries.push(wgpu::BindGroupEntry { binding: l.interface.binding, resource: buffer.as_entire_binding() });
        }
        if let (Some(buffer), true) = (inner, matches!(kind, KernelKind::DynamicCoarse | KernelKind::DynamicFine)) {
            entries.push(wgpu::BindGroupEntry { binding: l.interface2.binding, resource: buffer.as_entire_binding() });
        }
        if kind == KernelKind::DynamicCoarse {
            entries.push(wgpu::BindGroupEntry { binding: l.stats.binding, resource: self.stats.as_entire_binding() });
        }
        let outputs = (!kind.is_coarse()).then_some(outputs);
        self.finish_stage_group(device, kind, entries, outputs)
    }

    /// Adds the outputs (when given), the statistics and the rate image (for the
    /// kernels that count) to a stage group's entries, and creates the group.
    fn finish_stage_group(
        &self,
        device: &wgpu::Device,
        kind: KernelKind,
        entries: Vec<wgpu::BindGroupEntry<'_>>,
        outputs: Option<&HashMap<&str, wgpu::TextureView>>,
    ) -> wgpu::BindGroup {
        let l = &self.layout;
        let rate_view = self.rate.as_ref().map(|(t, _)| t.create_view(&Default::default()));
        // Rebound so the entries may also borrow the views made here.
        let mut entries: Vec<wgpu::BindGroupEntry<'_>> = entries;
        for o in outputs.map(|_| &l.outputs[..]).unwrap_or_default() {
            let view = &outputs.expect("checked above")[o.name.as_str()];
            entries
                .push(wgpu::BindGroupEntry { binding: o.binding, resource: wgpu::BindingResource::TextureView(view) });
        }
        let counts = kind.is_fine() || matches!(kind, KernelKind::Hierarchical | KernelKind::Checkerboard);
        if counts && !l.stats.counters.is_empty() {
            entries.push(wgpu::BindGroupEntry { binding: l.stats.binding, resource: self.stats.as_entire_binding() });
            if let Some(view) = &rate_view {
                entries.push(wgpu::BindGroupEntry {
                    binding: l.rate_image.binding,
                    resource: wgpu::BindingResource::TextureView(view),
                });
            }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(kind.name()),
            layout: &self.stage_layouts[&kind],
            entries: &entries,
        })
    }

    fn ensure_rate_image(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        if self.rate.as_ref().is_some_and(|(_, s)| *s == size) {
            return;
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("mrsl rate image"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rg32Uint,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        self.rate = Some((texture, size));
    }

    /// The per-pixel refine mask of the last coarse-mode dispatch: bit k set
    /// when coarse effect k (`layout().stats.counters[k]`) was evaluated per
    /// pixel. `None` before any coarse-mode dispatch.
    pub fn rate_image(&self) -> Option<&wgpu::Texture> {
        self.rate.as_ref().map(|(t, _)| t)
    }

    /// Reads the statistics of the last submitted dispatch (waits for the GPU).
    pub fn read_stats(&self, device: &wgpu::Device) -> Result<Stats, Error> {
        let (options, size) = self.last.ok_or_else(|| Error::Readback("nothing was dispatched yet".into()))?;
        let counters: Vec<u32> = read_buffer(device, &self.stats_readback)?;
        let timings = match &self.timestamps {
            Some(t) => {
                let ticks: Vec<u64> = read_buffer(device, &t.readback)?;
                let ms = |stage: usize| {
                    let (a, b) = (ticks[2 * stage], ticks[2 * stage + 1]);
                    (b.saturating_sub(a)) as f64 * t.period_ns as f64 / 1e6
                };
                // Stages written by each mode (see `encode`): 0 reference; 1 coarse
                // or hierarchical levels or checkerboard; 2 fine or final; 3 the
                // dynamic mode's 2x2 coarse pass, which runs between 1 and 2.
                let span = |first: usize, last: usize| {
                    (ticks[2 * last + 1].saturating_sub(ticks[2 * first])) as f64 * t.period_ns as f64 / 1e6
                };
                let (coarse_ms, coarse2_ms, fine_ms, total_ms) = match options.mode {
                    Mode::Reference => (0.0, 0.0, ms(0), ms(0)),
                    Mode::Checkerboard => (0.0, 0.0, ms(1), ms(1)),
                    Mode::Dynamic => (ms(1), ms(3), ms(2), span(1, 2)),
                    _ => (ms(1), 0.0, ms(2), span(1, 2)),
                };
                Some(crate::Timings { coarse_ms, coarse2_ms, fine_ms, total_ms })
            }
            None => None,
        };
        let mut stats = Stats::new(&self.layout, options, size, &counters, timings);
        if options.mode == Mode::Hierarchical {
            let queue: Vec<u32> = read_buffer(device, &self.queue_readback)?;
            stats.work_lists = (1..=4).map(|l| queue[4 * l] as u64).collect();
            let queued: u64 = stats.work_lists.iter().sum();
            let lanes: u64 = stats.work_lists.iter().map(|c| c.div_ceil(64) * 64).sum();
            stats.lane_utilisation = Some(if lanes == 0 { 1.0 } else { queued as f64 / lanes as f64 });
        }
        Ok(stats)
    }

    /// Number of coarse samples for a size and block size (as the kernels compute it).
    pub fn coarse_samples(size: (u32, u32), block: u32) -> u64 {
        let (nx, ny) = sample_grid(size, block);
        nx as u64 * ny as u64
    }
}

fn read_buffer<T: bytemuck::Pod>(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<T>, Error> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Readback(e.to_string()))?;
    rx.recv().map_err(|e| Error::Readback(e.to_string()))?.map_err(|e| Error::Readback(e.to_string()))?;
    let data = {
        let view = slice.get_mapped_range().map_err(|e| Error::Readback(e.to_string()))?;
        bytemuck::cast_slice(&view).to_vec()
    };
    buffer.unmap();
    Ok(data)
}

/// A wgpu error's full description (its Display is only "Validation Error").
pub(crate) fn describe(error: &wgpu::Error) -> String {
    match error {
        wgpu::Error::Validation { description, .. } => description.clone(),
        other => other.to_string(),
    }
}

/// Number of scalar components of an mrsl type name (`float3` = 3, `float4[8]` = 32).
pub fn components(ty: &str) -> usize {
    match ty {
        "float2x2" => 4,
        "float3x3" => 9,
        "float4x4" => 16,
        t if t.ends_with(']') => {
            let (elem, n) = t.trim_end_matches(']').split_once('[').unwrap_or((t, "1"));
            components(elem) * n.parse::<usize>().unwrap_or(1)
        }
        t => match t.chars().last() {
            Some(c @ '2'..='4') => c.to_digit(10).unwrap_or(1) as usize,
            _ => 1,
        },
    }
}

/// Writes a uniform's components at the start of `out`, laid out as WGSL's
/// uniform address space wants (matrix columns and array elements 16-byte aligned).
fn write_field(out: &mut [u8], wgsl_type: &str, ty: &str, values: &[f64]) {
    let float = wgsl_type.contains("f32");
    let signed = wgsl_type.contains("i32");
    let mut put = |index: usize, v: f64| {
        let bytes = if float {
            (v as f32).to_le_bytes()
        } else if signed {
            (v as i32).to_le_bytes()
        } else {
            (v as u32).to_le_bytes()
        };
        out[index * 4..index * 4 + 4].copy_from_slice(&bytes);
    };
    let matrix = match ty {
        "float2x2" => Some(2),
        "float3x3" => Some(3),
        "float4x4" => Some(4),
        _ => None,
    };
    if let Some(n) = matrix {
        // Columns of a mat2x2 are 8 bytes apart, of mat3x3/mat4x4 16 bytes.
        let column_words = if n == 2 { 2 } else { 4 };
        for col in 0..n {
            for row in 0..n {
                put(col * column_words + row, values[col * n + row]);
            }
        }
    } else if ty.ends_with(']') {
        // Arrays of 16-byte elements (float4, int4, uint4, float4x4): tightly packed words.
        for (i, v) in values.iter().enumerate() {
            put(i, *v);
        }
    } else {
        for (i, v) in values.iter().enumerate() {
            put(i, *v);
        }
    }
}

fn storage_format(name: &str) -> wgpu::TextureFormat {
    use wgpu::TextureFormat as F;
    match name {
        "r32float" => F::R32Float,
        "rg32float" => F::Rg32Float,
        "rgba16float" => F::Rgba16Float,
        "rgba8unorm" => F::Rgba8Unorm,
        "r32uint" => F::R32Uint,
        "rgba32uint" => F::Rgba32Uint,
        "r32sint" => F::R32Sint,
        "rgba32sint" => F::Rgba32Sint,
        _ => F::Rgba32Float,
    }
}

fn resources_layout(device: &wgpu::Device, l: &Layout) -> wgpu::BindGroupLayout {
    let uniform = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let mut entries = vec![uniform(l.control.binding)];
    if let Some(u) = &l.uniforms {
        entries.push(uniform(u.binding));
    }
    for t in &l.textures {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: t.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
    }
    for s in &l.samplers {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: s.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("mrsl resources"), entries: &entries })
}

fn gbuffer_layout(device: &wgpu::Device, l: &Layout) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = l
        .channels
        .iter()
        .map(|c| wgpu::BindGroupLayoutEntry {
            binding: c.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Texture {
                sample_type: match c.sample_type {
                    "uint" => wgpu::TextureSampleType::Uint,
                    "sint" => wgpu::TextureSampleType::Sint,
                    _ => wgpu::TextureSampleType::Float { filterable: false },
                },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        })
        .collect();
    device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("mrsl g-buffer"), entries: &entries })
}

fn stage_layout(device: &wgpu::Device, l: &Layout, kind: KernelKind) -> wgpu::BindGroupLayout {
    let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let mut entries = vec![];
    match kind {
        KernelKind::Coarse => entries.push(storage(l.interface.binding, false)),
        KernelKind::Fine => entries.push(storage(l.interface.binding, true)),
        KernelKind::DynamicCoarse => {
            entries.push(storage(l.interface.binding, true));
            entries.push(storage(l.interface2.binding, false));
            entries.push(storage(l.stats.binding, false));
        }
        KernelKind::DynamicFine => {
            entries.push(storage(l.interface.binding, true));
            entries.push(storage(l.interface2.binding, true));
        }
        KernelKind::Checkerboard => entries.push(storage(l.hierarchical.values_binding, false)),
        KernelKind::Hierarchical => {
            entries.push(storage(l.hierarchical.values_binding, false));
            entries.push(storage(l.hierarchical.work_binding, false));
            entries.push(storage(l.hierarchical.queue_binding, false));
        }
        KernelKind::Reference => {}
    }
    if !kind.is_coarse() {
        for o in &l.outputs {
            entries.push(wgpu::BindGroupLayoutEntry {
                binding: o.binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: storage_format(&o.format),
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            });
        }
    }
    if (kind.is_fine() || matches!(kind, KernelKind::Hierarchical | KernelKind::Checkerboard))
        && !l.stats.counters.is_empty()
    {
        entries.push(storage(l.stats.binding, false));
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: l.rate_image.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rg32Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        });
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(kind.name()), entries: &entries })
}
