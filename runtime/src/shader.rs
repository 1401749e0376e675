//! A compiled mrsl program instantiated on a wgpu device: pipelines, bind
//! group layouts, the control and uniform blocks, and the interface buffer.

use crate::error::Error;
use crate::{Mode, Stats};
use mrsl_abi::geometry::{
    self, HIERARCHICAL_LEVEL0, HIERARCHICAL_LEVELS, MAX_SIDE, MAX_STORAGE_BINDING_BYTES, MAX_TEXTURE_LAYERS,
    MAX_TEXTURE_SIDE,
};
use mrsl_abi::{
    BINDING_ARGS, CompiledProgram, Control, GROUP_ARGS, KernelKind, Layout, SampleType, Scalar, StageResource,
    StageSlot, TextureFormat, ValueType, entry,
};
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
    /// The rate-image mode's shading-rate image: one texel per
    /// [`DispatchOptions::rate_tile`]-pixel tile
    /// ([`mrsl_abi::shading_rate::rate_image_size`]), an unsigned-integer
    /// texture (R8Uint, R16Uint or R32Uint) holding the codes of
    /// [`mrsl_abi::ShadingRate`]. Other modes ignore it.
    pub shading_rate: Option<&'a wgpu::Texture>,
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
    /// Rate-image mode: pixels per side of a shading-rate tile (8 or 16).
    pub rate_tile: u32,
    /// Count per-pixel re-evaluations ([`Shader::read_stats`]) and write the
    /// per-pixel refine mask ([`Shader::rate_image`]). On by default; turn it
    /// off for frames that are only displayed or timed: the counters are
    /// workgroup atomics and a barrier per tile, under 2% of a coarse 4x4
    /// frame on lavapipe in the ablations of docs/evaluation.md.
    pub statistics: bool,
}

impl DispatchOptions {
    /// Default similarity threshold of the hierarchical mode (variance, linear units).
    pub const DEFAULT_SIMILARITY: f32 = 1e-3;

    pub fn new(mode: Mode) -> DispatchOptions {
        DispatchOptions {
            mode,
            force_refine: false,
            similarity: Self::DEFAULT_SIMILARITY,
            rate_tile: mrsl_abi::shading_rate::DEFAULT_RATE_TILE,
            statistics: true,
        }
    }

    /// The same dispatch with `statistics` off: no per-pixel counters and no
    /// rate image, as a timed run measures it.
    pub fn uninstrumented(self) -> DispatchOptions {
        DispatchOptions { statistics: false, ..self }
    }
}

/// Resources of the hierarchical and checkerboard modes.
struct HierBuffers {
    /// The per-pixel records (`r32uint`, a layer per record word).
    values: wgpu::TextureView,
    work: wgpu::Buffer,
    queue: wgpu::Buffer,
    args: wgpu::Buffer,
}

/// Buffers of the rate-image mode: the sample list, its counter and the
/// indirect arguments of `rate_coarse`.
struct RateBuffers {
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

/// A pipeline: kernel kind, block size (as in [`mrsl_abi::Kernel::block_size`]) and entry point.
type PipelineKey = (KernelKind, Option<u32>, &'static str);

/// A program on a device.
pub struct Shader {
    layout: Layout,
    resources_layout: wgpu::BindGroupLayout,
    gbuffer_layout: wgpu::BindGroupLayout,
    stage_layouts: HashMap<KernelKind, wgpu::BindGroupLayout>,
    /// Every entry point of every kernel, by name (see [`mrsl_abi::KernelKind::entry_points`]).
    pipelines: HashMap<PipelineKey, wgpu::ComputePipeline>,
    /// Kernel kinds whose stage layout or pipelines the device refused, with
    /// its reason: the modes that need them are refused at `encode`.
    unavailable: HashMap<KernelKind, String>,
    /// Hierarchical mode buffers (values, work lists, queues) and the size they were made for.
    hier_buffers: Option<(HierBuffers, (u32, u32))>,
    /// Rate-image mode buffers and the size they were made for.
    rate_buffers: Option<(RateBuffers, (u32, u32))>,
    /// Whether the dispatch being encoded forces refinement.
    forced: bool,
    args_group_layout: wgpu::BindGroupLayout,
    queue_readback: wgpu::Buffer,
    control: wgpu::Buffer,
    uniforms: Option<wgpu::Buffer>,
    uniform_values: HashMap<String, Vec<f64>>,
    /// Interface buffers by (block size, tagged), with the size they were made
    /// for: the dynamic mode's 2x2 level and the rate-image mode's records.
    interfaces: HashMap<(u32, bool), (wgpu::Buffer, (u32, u32))>,
    /// The block modes' textures over a sample grid (records, neighbour
    /// values) by block size, with the image size they were made for.
    sample_textures: HashMap<(SampleTexture, u32), (wgpu::TextureView, (u32, u32))>,
    /// Dispatch counter, written to the control block (validity tags of the dynamic mode).
    frame: u32,
    /// The fine kernel's per-pixel refine mask, with the size it was made for.
    rate: Option<(wgpu::Texture, (u32, u32))>,
    stats: wgpu::Buffer,
    stats_readback: wgpu::Buffer,
    timestamps: Option<Timestamps>,
    last: Option<(DispatchOptions, (u32, u32))>,
}

impl Shader {
    /// Creates the pipelines of every kernel in `program`: compiled just now
    /// (`&mrsl::compile(..)?` dereferences to one) or read from the files
    /// `mrslc compile` wrote ([`CompiledProgram::read_dir`]). A kernel the
    /// device refuses (a limit exceeded) does not fail this: the modes that
    /// need it return [`Error::UnsupportedMode`] from [`Shader::encode`].
    pub fn new(device: &wgpu::Device, program: &CompiledProgram) -> Result<Shader, Error> {
        let layout = program.layout.clone();
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let resources_layout = resources_layout(device, &layout);
        let gbuffer_layout = gbuffer_layout(device, &layout);
        // A kernel kind this device cannot run (its stage group beyond the
        // device's limits, say the hierarchical kernel's outputs and records
        // beyond `max_storage_textures_per_shader_stage`) refuses the modes
        // that need it when they are dispatched, not every mode here: each
        // kind's layout and pipelines are made under their own error scope.
        let mut unavailable: HashMap<KernelKind, String> = HashMap::new();
        let mut stage_layouts: HashMap<KernelKind, wgpu::BindGroupLayout> = HashMap::new();
        for kind in KernelKind::ALL {
            let kind_scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            stage_layouts.insert(kind, stage_layout(device, &layout, kind));
            if let Some(error) = pollster::block_on(kind_scope.pop()) {
                unavailable.insert(kind, describe(&error));
            }
        }
        let mut pipelines = HashMap::new();
        let args_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mrsl hierarchical args"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: BINDING_ARGS,
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
            if unavailable.contains_key(&kernel.kind) {
                continue;
            }
            let kind_scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(kernel.kind.name()),
                source: wgpu::ShaderSource::Wgsl(kernel.wgsl.as_str().into()),
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(kernel.kind.name()),
                bind_group_layouts: &[
                    Some(&resources_layout),
                    Some(&gbuffer_layout),
                    Some(&stage_layouts[&kernel.kind]),
                ],
                immediate_size: 0,
            });
            // The hierarchical `args` entry points also see the indirect arguments (`GROUP_ARGS`).
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
            for &entry in kernel.entry_points() {
                let layout = if entry::binds_args_group(entry) { &args_layout } else { &pipeline_layout };
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                });
                pipelines.insert((kernel.kind, kernel.block_size, entry), pipeline);
            }
            if let Some(error) = pollster::block_on(kind_scope.pop()) {
                unavailable.insert(kernel.kind, describe(&error));
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
        let counters = layout.stats_counters() as u64 * 4;
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
            unavailable,
            hier_buffers: None,
            rate_buffers: None,
            forced: false,
            args_group_layout,
            queue_readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl hierarchical queue readback"),
                size: geometry::HIERARCHICAL_QUEUE_BYTES,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            control,
            uniforms,
            uniform_values: HashMap::new(),
            interfaces: HashMap::new(),
            sample_textures: HashMap::new(),
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
        let expected = field.ty.components() as usize;
        if values.len() != expected {
            return Err(Error::UniformComponents {
                name: name.into(),
                ty: field.ty.to_string(),
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
            write_field(&mut bytes[field.offset as usize..], &field.ty, values);
        }
        Ok(bytes)
    }

    /// Checks `bindings` against the layout.
    fn validate(&self, bindings: &Bindings, options: DispatchOptions) -> Result<(), Error> {
        let mode = options.mode;
        let (width, height) = bindings.size;
        let missing = |what: &str| {
            Err(Error::UnsupportedMode(mode.name().into(), format!("the program was compiled without {what}")))
        };
        if let Some((kind, reason)) = mode.kernels().iter().find_map(|(k, _)| self.unavailable.get_key_value(k)) {
            let reason = format!("the device cannot run its {kind} kernel: {reason}");
            return Err(Error::UnsupportedMode(mode.name().into(), reason));
        }
        if let Some(what) = mode.kernels().iter().find(|(kind, block)| !self.has_kernel(*kind, *block)) {
            return missing(&match what {
                (kind, Some(b)) if kind.per_block_size() => format!("its {b}x{b} {kind} kernel"),
                (kind, _) => format!("its {kind} kernel"),
            });
        }
        if width == 0 || height == 0 {
            return Err(Error::BadSize { width, height, reason: "it is empty".into() });
        }
        if width > MAX_SIDE || height > MAX_SIDE {
            return Err(Error::BadSize { width, height, reason: format!("the largest supported side is {MAX_SIDE}") });
        }
        // Every buffer a mode allocates must fit one storage binding.
        let fits = |what: &str, words: u64| {
            let bytes = words * 4;
            if bytes > MAX_STORAGE_BINDING_BYTES {
                let limit = MAX_STORAGE_BINDING_BYTES >> 20;
                let reason = format!("{what} would need {} MiB, more than a {limit} MiB storage binding", bytes >> 20);
                return Err(Error::BadSize { width, height, reason });
            }
            Ok(())
        };
        // Every texture array of records must fit WebGPU's default texture limits.
        let fits_texture = |what: &str, (w, h): (u32, u32), layers: u32| {
            if w.max(h) > MAX_TEXTURE_SIDE || layers > MAX_TEXTURE_LAYERS {
                let reason = format!(
                    "{what} would need {w}x{h} texels and {layers} layers, more than \
                     {MAX_TEXTURE_SIDE}x{MAX_TEXTURE_SIDE} texels and {MAX_TEXTURE_LAYERS} layers"
                );
                return Err(Error::BadSize { width, height, reason });
            }
            Ok(())
        };
        let samples = |block| {
            let (nx, ny) = geometry::sample_grid(bindings.size, block);
            u64::from(nx) * u64::from(ny)
        };
        let pixels = u64::from(width) * u64::from(height);
        if let Some(block) = mode.block_size() {
            let grid = geometry::sample_grid(bindings.size, block);
            fits_texture("the record texture", grid, self.layout.interface.layers())?;
            fits_texture("the neighbour values", grid, self.layout.neighbours.words)?;
        }
        if mode == Mode::Dynamic {
            let words = u64::from(self.layout.interface.stride_words + geometry::DYNAMIC_TAG_WORDS);
            fits("the 2x2 level", samples(geometry::DYNAMIC_INNER_BLOCK) * words)?;
        }
        if matches!(mode, Mode::Hierarchical | Mode::Checkerboard) {
            fits_texture("the per-pixel record texture", bindings.size, self.layout.hierarchical.record_words)?;
        }
        if mode == Mode::RateImage {
            fits("the rate-image interface", pixels * u64::from(self.layout.interface.stride_words))?;
            fits("the rate-image sample list", geometry::rate_work_words(bindings.size))?;
            self.validate_shading_rate(bindings, options.rate_tile)?;
        }
        if mode == Mode::Hierarchical {
            fits("the hierarchical work lists", geometry::work_list_words(bindings.size))?;
            // The last level queues at most half the pixels; its indirect
            // dispatch covers at most 65535 workgroups.
            if pixels / 2 > 65535 * u64::from(geometry::WORK_LIST_WORKGROUP) {
                let reason = "a hierarchical level would need more than 65535 workgroups".into();
                return Err(Error::BadSize { width, height, reason });
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
            let need = ch.ty.components();
            let fits = matches!(
                (ch.sample_type, t.format().sample_type(None, None)),
                (SampleType::Uint, Some(wgpu::TextureSampleType::Uint))
                    | (SampleType::Sint, Some(wgpu::TextureSampleType::Sint))
                    | (SampleType::UnfilterableFloat, Some(wgpu::TextureSampleType::Float { .. }))
            ) && t.format().components() as u32 >= need.min(4)
                && (need != 3 || t.format().components() == 4);
            if !fits {
                return Err(Error::ChannelFormat {
                    channel: ch.name.clone(),
                    ty: ch.ty.to_string(),
                    expected: ch.format.to_string(),
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
            let expected = wgpu_format(o.format);
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
        self.validate(bindings, options)?;
        let (width, height) = bindings.size;
        self.frame = self.frame.wrapping_add(1).max(1);
        self.forced = options.force_refine;
        let control = Control {
            size: [width, height],
            force_refine: u32::from(options.force_refine),
            frame: self.frame,
            similarity: options.similarity,
            rate_tile: options.rate_tile,
            statistics: u32::from(options.statistics),
            reserved: 0,
        };
        queue.write_buffer(&self.control, 0, bytemuck::bytes_of(&control));
        if let Some(buffer) = &self.uniforms {
            queue.write_buffer(buffer, 0, &self.uniform_bytes()?);
        }
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let resources = self.resources_group(device, bindings);
        let gbuffer = self.gbuffer_group(device, bindings);
        let views: HashMap<&str, wgpu::TextureView> =
            bindings.outputs.iter().map(|(k, t)| (k.as_str(), t.create_view(&Default::default()))).collect();
        encoder.clear_buffer(&self.stats, 0, None);
        let tiles = geometry::pixel_workgroups(bindings.size);
        if mode == Mode::RateImage {
            self.rate_image_passes(device, encoder, bindings, &views, [&resources, &gbuffer], options.rate_tile);
        } else if matches!(mode, Mode::Hierarchical | Mode::Checkerboard) {
            let kind = mode.kernels()[0].0;
            let stage = self.record_stage(device, kind, bindings.size, &views);
            let groups = [&resources, &gbuffer, &stage];
            if kind == KernelKind::Hierarchical {
                self.hierarchical_passes(device, encoder, bindings.size, &groups);
            } else {
                self.checkerboard_passes(encoder, bindings.size, &groups);
            }
        } else {
            match mode.block_size() {
                None => {
                    let stage = self.stage_group(device, KernelKind::Reference, Interface::None, None, &views, None);
                    self.pass(
                        encoder,
                        "mrsl reference",
                        0,
                        (KernelKind::Reference, None, entry::REFERENCE),
                        &[&resources, &gbuffer, &stage],
                        tiles,
                    );
                }
                Some(block) => {
                    let records = self.sample_texture(device, SampleTexture::Records, block, bindings.size).clone();
                    let stores_neighbours = self.layout.neighbours.words > 0;
                    let neighbours = stores_neighbours
                        .then(|| self.sample_texture(device, SampleTexture::Neighbours, block, bindings.size).clone());
                    self.ensure_rate_image(device, bindings.size);
                    let dynamic = mode == Mode::Dynamic;
                    let inner = if dynamic {
                        Some(self.interface(device, geometry::DYNAMIC_INNER_BLOCK, true, bindings.size).clone())
                    } else {
                        None
                    };
                    let interface = Interface::Records(&records, neighbours.as_ref());
                    let coarse_stage = self.stage_group(device, KernelKind::Coarse, interface, None, &views, None);
                    let fine_kind = if dynamic { KernelKind::DynamicFine } else { KernelKind::Fine };
                    let fine_stage = self.stage_group(device, fine_kind, interface, inner.as_ref(), &views, None);
                    {
                        // The neighbour values first, then the samples, which read them.
                        let groups = [&resources, &gbuffer, &coarse_stage];
                        let mut pass = self.begin_pass(encoder, "mrsl coarse", 1, &groups);
                        let (gx, gy) = geometry::coarse_workgroups(bindings.size, block);
                        let entries: &[&str] = if stores_neighbours {
                            &[entry::COARSE_NEIGHBOURS, entry::COARSE]
                        } else {
                            &[entry::COARSE]
                        };
                        for &name in entries {
                            pass.set_pipeline(&self.pipelines[&(KernelKind::Coarse, Some(block), name)]);
                            pass.dispatch_workgroups(gx, gy, 1);
                        }
                    }
                    if dynamic {
                        let stage = self.stage_group(
                            device,
                            KernelKind::DynamicCoarse,
                            interface,
                            inner.as_ref(),
                            &views,
                            None,
                        );
                        self.pass(
                            encoder,
                            "mrsl dynamic coarse 2x2",
                            3,
                            (KernelKind::DynamicCoarse, Some(geometry::DYNAMIC_INNER_BLOCK), entry::DYNAMIC_COARSE),
                            &[&resources, &gbuffer, &stage],
                            geometry::coarse_workgroups(bindings.size, geometry::DYNAMIC_INNER_BLOCK),
                        );
                    }
                    let fine_entry = if dynamic { entry::DYNAMIC_FINE } else { entry::FINE };
                    self.pass(
                        encoder,
                        "mrsl fine",
                        2,
                        (fine_kind, Some(block), fine_entry),
                        &[&resources, &gbuffer, &fine_stage],
                        tiles,
                    );
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
    fn hierarchical_passes(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        size: (u32, u32),
        groups: &[&wgpu::BindGroup; 3],
    ) {
        let (buffers, _) = self.hier_buffers.as_ref().expect("created by record_stage");
        encoder.clear_buffer(&buffers.queue, 0, None);
        let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl hierarchical args"),
            layout: &self.args_group_layout,
            entries: &[wgpu::BindGroupEntry { binding: BINDING_ARGS, resource: buffers.args.as_entire_binding() }],
        });
        let pipeline = |name: &'static str| &self.pipelines[&(KernelKind::Hierarchical, None, name)];
        {
            let mut pass = self.begin_pass(encoder, "mrsl hierarchical levels", 1, groups);
            let (gx, gy) = HIERARCHICAL_LEVEL0.workgroups(size);
            pass.set_pipeline(pipeline(entry::HIER_LEVEL0));
            pass.dispatch_workgroups(gx, gy, 1);
            for (index, lattice) in HIERARCHICAL_LEVELS.iter().enumerate() {
                let (gx, gy) = lattice.workgroups(size);
                pass.set_pipeline(pipeline(entry::HIER_CLASSIFY[index]));
                pass.dispatch_workgroups(gx, gy, 1);
                pass.set_pipeline(pipeline(entry::HIER_ARGS[index]));
                pass.set_bind_group(GROUP_ARGS, Some(&args), &[]);
                pass.dispatch_workgroups(1, 1, 1);
                pass.set_pipeline(pipeline(entry::HIER_SHADE[index]));
                pass.dispatch_workgroups_indirect(&buffers.args, geometry::indirect_args_offset(index as u32 + 1));
            }
        }
        {
            let mut pass = self.begin_pass(encoder, "mrsl hierarchical final", 2, groups);
            pass.set_pipeline(pipeline(entry::HIER_FINAL));
            let (gx, gy) = geometry::pixel_workgroups(size);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        encoder.copy_buffer_to_buffer(&buffers.queue, 0, &self.queue_readback, 0, None);
    }

    /// The rate-image mode: list the samples each tile's rate needs, shade
    /// them from the list (indirect), then resolve every pixel.
    fn rate_image_passes(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &Bindings,
        views: &HashMap<&str, wgpu::TextureView>,
        groups: [&wgpu::BindGroup; 2],
        tile: u32,
    ) {
        let size = bindings.size;
        let interface = self.interface(device, 1, false, size).clone();
        self.ensure_rate_image(device, size);
        self.ensure_rate_buffers(device, size);
        let shading_rate = bindings.shading_rate.expect("validated").create_view(&Default::default());
        let interface = Interface::Buffer(&interface);
        let coarse = self.stage_group(device, KernelKind::RateCoarse, interface, None, views, Some(&shading_rate));
        let fine = self.stage_group(device, KernelKind::RateFine, interface, None, views, Some(&shading_rate));
        let (buffers, _) = self.rate_buffers.as_ref().expect("created above");
        encoder.clear_buffer(&buffers.queue, 0, None);
        let args = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl rate-image args"),
            layout: &self.args_group_layout,
            entries: &[wgpu::BindGroupEntry { binding: BINDING_ARGS, resource: buffers.args.as_entire_binding() }],
        });
        let pipeline = |kind, name: &'static str| &self.pipelines[&(kind, None, name)];
        {
            let mut pass = self.begin_pass(encoder, "mrsl rate-image coarse", 1, &[groups[0], groups[1], &coarse]);
            let (gx, gy) = geometry::rate_list_workgroups(size, tile);
            pass.set_pipeline(pipeline(KernelKind::RateCoarse, entry::RATE_LIST));
            pass.dispatch_workgroups(gx, gy, 1);
            pass.set_pipeline(pipeline(KernelKind::RateCoarse, entry::RATE_ARGS));
            pass.set_bind_group(GROUP_ARGS, Some(&args), &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(pipeline(KernelKind::RateCoarse, entry::RATE_COARSE));
            pass.dispatch_workgroups_indirect(&buffers.args, 0);
        }
        {
            let mut pass = self.begin_pass(encoder, "mrsl rate-image fine", 2, &[groups[0], groups[1], &fine]);
            pass.set_pipeline(pipeline(KernelKind::RateFine, entry::RATE_FINE));
            let (gx, gy) = geometry::pixel_workgroups(size);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        encoder.copy_buffer_to_buffer(&buffers.queue, 0, &self.queue_readback, 0, Some(4));
    }

    fn ensure_rate_buffers(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        if self.rate_buffers.as_ref().is_some_and(|(_, s)| *s == size) {
            return;
        }
        let storage = |label, bytes, extra| storage_buffer(device, label, bytes, extra);
        let buffers = RateBuffers {
            work: storage(
                "mrsl rate-image sample list",
                geometry::rate_work_words(size) * 4,
                wgpu::BufferUsages::empty(),
            ),
            queue: storage(
                "mrsl rate-image sample count",
                geometry::RATE_QUEUE_BYTES,
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            ),
            args: storage(
                "mrsl rate-image dispatch arguments",
                geometry::RATE_QUEUE_BYTES,
                wgpu::BufferUsages::INDIRECT,
            ),
        };
        self.rate_buffers = Some((buffers, size));
    }

    /// The shading-rate image of the rate-image mode: bound, an unsigned-integer
    /// texture, one texel per tile.
    fn validate_shading_rate(&self, bindings: &Bindings, tile: u32) -> Result<(), Error> {
        const WHAT: &str = "the shading-rate image";
        if !mrsl_abi::shading_rate::RATE_TILE_SIZES.contains(&tile) {
            return Err(Error::BadTileSize(tile));
        }
        let t = bindings.shading_rate.ok_or(Error::MissingShadingRate)?;
        if !matches!(
            t.format(),
            wgpu::TextureFormat::R8Uint | wgpu::TextureFormat::R16Uint | wgpu::TextureFormat::R32Uint
        ) {
            let expected = "R8Uint (as in D3D12 and Vulkan), R16Uint or R32Uint";
            return Err(Error::RateFormat { what: WHAT, expected, found: t.format() });
        }
        if !t.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return Err(Error::RateUsage { what: WHAT, missing: "TEXTURE_BINDING" });
        }
        let expected = mrsl_abi::shading_rate::rate_image_size(bindings.size, tile);
        if (t.width(), t.height()) != expected {
            let (image, found) = (bindings.size, (t.width(), t.height()));
            return Err(Error::RateImageSize { what: WHAT, image, tile, expected, found });
        }
        Ok(())
    }

    /// The checkerboard baseline: shade the coarse effects in half the quads,
    /// then reconstruct and finish every pixel.
    fn checkerboard_passes(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        size: (u32, u32),
        groups: &[&wgpu::BindGroup; 3],
    ) {
        let pipeline = |name: &'static str| &self.pipelines[&(KernelKind::Checkerboard, None, name)];
        let mut pass = self.begin_pass(encoder, "mrsl checkerboard", 1, groups);
        let (gx, gy) = geometry::checkerboard_workgroups(size, self.forced);
        pass.set_pipeline(pipeline(entry::CB_SHADE));
        pass.dispatch_workgroups(gx, gy, 1);
        pass.set_pipeline(pipeline(entry::CB_FINAL));
        let (gx, gy) = geometry::pixel_workgroups(size);
        pass.dispatch_workgroups(gx, gy, 1);
    }

    /// Group 2 of the modes that keep a record per pixel (hierarchical,
    /// checkerboard); (re)creates the record buffers and the rate image for
    /// `size` first.
    fn record_stage(
        &mut self,
        device: &wgpu::Device,
        kind: KernelKind,
        size: (u32, u32),
        views: &HashMap<&str, wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        self.ensure_rate_image(device, size);
        self.ensure_hier_buffers(device, size);
        self.stage_group(device, kind, Interface::None, None, views, None)
    }

    fn ensure_hier_buffers(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        if self.hier_buffers.as_ref().is_some_and(|(_, s)| *s == size) {
            return;
        }
        let work_words = geometry::work_list_words(size);
        let storage = |label, bytes, extra| storage_buffer(device, label, bytes, extra);
        let record = self.layout.hierarchical.record_words;
        let buffers = HierBuffers {
            values: word_texture_array(device, "mrsl per-pixel records", size, record, RECORD_WORDS),
            work: storage("mrsl hierarchical work lists", work_words * 4, wgpu::BufferUsages::empty()),
            queue: storage(
                "mrsl hierarchical queues",
                geometry::HIERARCHICAL_QUEUE_BYTES,
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            ),
            args: storage(
                "mrsl hierarchical dispatch arguments",
                geometry::HIERARCHICAL_QUEUE_BYTES,
                wgpu::BufferUsages::INDIRECT,
            ),
        };
        self.hier_buffers = Some((buffers, size));
    }

    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        stage: u32,
        pipeline: PipelineKey,
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
        let tag = if tagged { geometry::DYNAMIC_TAG_WORDS } else { 0 };
        let stride = (self.layout.interface.stride_words + tag).max(1) as u64;
        let fresh = self.interfaces.get(&(block, tagged)).is_none_or(|(_, s)| *s != size);
        if fresh {
            let (nx, ny) = geometry::sample_grid(size, block);
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

    /// The block modes' texture `what` for `block`, (re)created when the
    /// size changes: the sample grid in texels, with the layers of its
    /// layout ([`mrsl_abi::InterfaceLayout`], [`mrsl_abi::NeighbourLayout`]).
    fn sample_texture(
        &mut self,
        device: &wgpu::Device,
        what: SampleTexture,
        block: u32,
        size: (u32, u32),
    ) -> &wgpu::TextureView {
        if self.sample_textures.get(&(what, block)).is_none_or(|(_, s)| *s != size) {
            let grid = geometry::sample_grid(size, block);
            let view = match what {
                SampleTexture::Records => {
                    word_texture_array(device, "mrsl records", grid, self.layout.interface.layers(), RECORD_TEXELS)
                }
                SampleTexture::Neighbours => {
                    let words = self.layout.neighbours.words;
                    word_texture_array(device, "mrsl neighbour values", grid, words, RECORD_WORDS)
                }
            };
            self.sample_textures.insert((what, block), (view, size));
        }
        &self.sample_textures[&(what, block)].0
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

    /// Group 2 of the kernel of `kind`: every binding the layout says it
    /// declares ([`Layout::stage_bindings`]), each bound to what its slot names.
    /// `interface` is the mode's coarse samples and `inner` the dynamic
    /// mode's 2x2 level; the rate image and the record buffers must exist
    /// when the kernel uses them.
    fn stage_group(
        &self,
        device: &wgpu::Device,
        kind: KernelKind,
        interface: Interface<'_>,
        inner: Option<&wgpu::Buffer>,
        outputs: &HashMap<&str, wgpu::TextureView>,
        shading_rate: Option<&wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        let l = &self.layout;
        // The rate-image mode binds its own list and counter where the hierarchical mode binds its.
        let rate_buffers = self.rate_buffers.as_ref().map(|(b, _)| b);
        let rate_kind = matches!(kind, KernelKind::RateCoarse | KernelKind::RateFine);
        let rate_view = self.rate.as_ref().map(|(t, _)| t.create_view(&Default::default()));
        let records = self.hier_buffers.as_ref().map(|(b, _)| b);
        let needed = "created by encode before the stage group";
        let entries: Vec<wgpu::BindGroupEntry> = l
            .stage_bindings(kind)
            .into_iter()
            .map(|b| wgpu::BindGroupEntry {
                binding: b.binding,
                resource: match b.slot {
                    StageSlot::Interface => match interface {
                        Interface::Records(view, _) => wgpu::BindingResource::TextureView(view),
                        Interface::Buffer(buffer) => buffer.as_entire_binding(),
                        Interface::None => panic!("the interface is {needed}"),
                    },
                    StageSlot::Interface2 => inner.expect(needed).as_entire_binding(),
                    StageSlot::Stats => self.stats.as_entire_binding(),
                    StageSlot::RateImage => wgpu::BindingResource::TextureView(rate_view.as_ref().expect(needed)),
                    StageSlot::Output(index) => {
                        wgpu::BindingResource::TextureView(&outputs[l.outputs[index].name.as_str()])
                    }
                    StageSlot::Records => wgpu::BindingResource::TextureView(&records.expect(needed).values),
                    StageSlot::WorkLists if rate_kind => rate_buffers.expect(needed).work.as_entire_binding(),
                    StageSlot::Queues if rate_kind => rate_buffers.expect(needed).queue.as_entire_binding(),
                    StageSlot::WorkLists => records.expect(needed).work.as_entire_binding(),
                    StageSlot::Queues => records.expect(needed).queue.as_entire_binding(),
                    StageSlot::ShadingRate => wgpu::BindingResource::TextureView(shading_rate.expect(needed)),
                    StageSlot::Neighbours => match interface {
                        Interface::Records(_, Some(view)) => wgpu::BindingResource::TextureView(view),
                        _ => panic!("the neighbour values are {needed}"),
                    },
                },
            })
            .collect();
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
    /// pixel. `None` before any coarse-mode dispatch; a dispatch with
    /// `DispatchOptions::statistics` off leaves it as it was.
    pub fn rate_image(&self) -> Option<&wgpu::Texture> {
        self.rate.as_ref().map(|(t, _)| t)
    }

    /// Reads the statistics of the last submitted dispatch (waits for the GPU).
    /// [`Error::StatisticsOff`] when it ran with `DispatchOptions::statistics` off.
    pub fn read_stats(&self, device: &wgpu::Device) -> Result<Stats, Error> {
        let (options, size) = self.last.ok_or_else(|| Error::Readback("nothing was dispatched yet".into()))?;
        if !options.statistics {
            return Err(Error::StatisticsOff);
        }
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
        let listed = if options.mode == Mode::RateImage {
            read_buffer::<u32>(device, &self.queue_readback)?[0] as u64
        } else {
            0
        };
        let mut stats = Stats::new(&self.layout, options, size, &counters, timings, listed);
        if options.mode == Mode::Hierarchical {
            let queue: Vec<u32> = read_buffer(device, &self.queue_readback)?;
            let words = geometry::QUEUE_WORDS_PER_LEVEL as usize;
            stats.work_lists = (1..=HIERARCHICAL_LEVELS.len()).map(|l| queue[words * l] as u64).collect();
            let queued: u64 = stats.work_lists.iter().sum();
            let lane = u64::from(geometry::WORK_LIST_WORKGROUP);
            let lanes: u64 = stats.work_lists.iter().map(|c| c.div_ceil(lane) * lane).sum();
            stats.lane_utilisation = Some(if lanes == 0 { 1.0 } else { queued as f64 / lanes as f64 });
        }
        Ok(stats)
    }

    /// Whether the program has the kernel `kind` for `block` (as a mode needs it).
    fn has_kernel(&self, kind: KernelKind, block: Option<u32>) -> bool {
        kind.entry_points().iter().all(|e| self.pipelines.contains_key(&(kind, block, *e)))
    }
}

/// The block modes' records: four words a texel, read by the fine kernels as a sampled texture.
const RECORD_TEXELS: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// The per-pixel records and the neighbour values: a word a texel, read and written in place.
const RECORD_WORDS: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// A 2D texture array of `size` texels and `layers` layers (at least one) of
/// `format`, as the array view the kernels bind: a storage texture, which the
/// block records (`RECORD_TEXELS`) also are as a sampled one.
fn word_texture_array(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    layers: u32,
    format: wgpu::TextureFormat,
) -> wgpu::TextureView {
    let sampled =
        if format == RECORD_TEXELS { wgpu::TextureUsages::TEXTURE_BINDING } else { wgpu::TextureUsages::empty() };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: layers.max(1) },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::STORAGE_BINDING | sampled,
        view_formats: &[],
    });
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

/// A storage buffer of `bytes` (at least 4) with `extra` usages besides `STORAGE`.
fn storage_buffer(device: &wgpu::Device, label: &str, bytes: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(4),
        usage: wgpu::BufferUsages::STORAGE | extra,
        mapped_at_creation: false,
    })
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

/// Writes a uniform's components at the start of `out`, laid out as WGSL's
/// uniform address space wants (matrix columns 16-byte aligned but for
/// `mat2x2`; arrays hold 16-byte elements only, so their words are packed).
fn write_field(out: &mut [u8], ty: &ValueType, values: &[f64]) {
    let scalar = ty.scalar();
    let mut put = |index: usize, v: f64| {
        let bytes = match scalar {
            Scalar::Float => (v as f32).to_le_bytes(),
            Scalar::Int => (v as i32).to_le_bytes(),
            Scalar::Uint | Scalar::Bool => (v as u32).to_le_bytes(),
        };
        out[index * 4..index * 4 + 4].copy_from_slice(&bytes);
    };
    if let ValueType::Matrix(n) = ty {
        let n = usize::from(*n);
        // Columns of a mat2x2 are 8 bytes apart, of mat3x3/mat4x4 16 bytes.
        let column_words = if n == 2 { 2 } else { 4 };
        for col in 0..n {
            for row in 0..n {
                put(col * column_words + row, values[col * n + row]);
            }
        }
    } else {
        for (i, v) in values.iter().enumerate() {
            put(i, *v);
        }
    }
}

/// The wgpu format of a layout format.
pub fn wgpu_format(format: TextureFormat) -> wgpu::TextureFormat {
    use wgpu::TextureFormat as F;
    match format {
        TextureFormat::R32Float => F::R32Float,
        TextureFormat::Rg32Float => F::Rg32Float,
        TextureFormat::Rgba32Float => F::Rgba32Float,
        TextureFormat::Rgba16Float => F::Rgba16Float,
        TextureFormat::Rgba8Unorm => F::Rgba8Unorm,
        TextureFormat::R32Uint => F::R32Uint,
        TextureFormat::Rg32Uint => F::Rg32Uint,
        TextureFormat::Rgba32Uint => F::Rgba32Uint,
        TextureFormat::R32Sint => F::R32Sint,
        TextureFormat::Rg32Sint => F::Rg32Sint,
        TextureFormat::Rgba32Sint => F::Rgba32Sint,
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
                    SampleType::Uint => wgpu::TextureSampleType::Uint,
                    SampleType::Sint => wgpu::TextureSampleType::Sint,
                    SampleType::UnfilterableFloat => wgpu::TextureSampleType::Float { filterable: false },
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

/// The block modes' textures over a sample grid.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum SampleTexture {
    /// The coarse-to-fine records.
    Records,
    /// The coarse kernel's neighbour values.
    Neighbours,
}

/// What a stage group binds as the interface ([`StageSlot::Interface`]).
#[derive(Clone, Copy)]
enum Interface<'a> {
    /// The block modes' record texture, and the coarse kernel's neighbour values if it has them.
    Records(&'a wgpu::TextureView, Option<&'a wgpu::TextureView>),
    /// The rate-image mode's record buffer.
    Buffer(&'a wgpu::Buffer),
    /// None: the kernel binds no interface.
    None,
}

fn stage_layout(device: &wgpu::Device, l: &Layout, kind: KernelKind) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = l
        .stage_bindings(kind)
        .into_iter()
        .map(|b| wgpu::BindGroupLayoutEntry {
            binding: b.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: match b.resource {
                StageResource::Buffer { read_only } => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                StageResource::StorageTexture(format) => wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu_format(format),
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                StageResource::UintTexture => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                StageResource::RecordTexture => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
                StageResource::RecordStorageTexture => wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::Rgba32Uint,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                },
                StageResource::WordTexture => wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::ReadWrite,
                    format: wgpu::TextureFormat::R32Uint,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                },
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(kind.name()), entries: &entries })
}
