//! The rate source of the `rate-image` mode: computes the shading-rate image
//! (one rate per 8x8 or 16x16 tile) that the next frame is shaded with, from
//! the previous frame's output and motion vectors as VALAR (Intel's
//! implementation of Yang et al.'s NVIDIA Adaptive Shading) does, damped over
//! time, reprojected along the motion, and combined with an engine's own rate
//! image and a built-in foveation source. docs/rate-image.md gives the
//! equations as implemented and what differs from VALAR.
//!
//! The computed image is an `R32Uint` storage texture holding the D3D12/Vulkan
//! codes of [`mrsl_abi::shading_rate`] (`(log2(width) << 2) | log2(height)`):
//! `R8Uint`, the format engines upload, is not a storage format in WebGPU, and
//! the `rate-image` kernels read any uint format with `textureLoad`.
//!
//! ```no_run
//! # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, previous_output: &wgpu::Texture,
//! #         velocity: &wgpu::Texture) -> Result<(), mrsl_runtime::Error> {
//! use mrsl_runtime::rate_source::{create_rate_image, read_rate_image, Preset, RateInputs, RateOptions, RateSource};
//! let mut source = RateSource::new(device)?;
//! let options = RateOptions { motion: true, ..RateOptions::preset(Preset::Balanced) };
//! let size = (previous_output.width(), previous_output.height());
//! let rates = create_rate_image(device, size, options.tile)?;
//! let mut encoder = device.create_command_encoder(&Default::default());
//! let inputs = RateInputs { velocity: Some(velocity), ..RateInputs::new(previous_output) };
//! source.encode(device, &mut encoder, &inputs, &options, &rates)?;
//! queue.submit([encoder.finish()]);
//! let per_tile = read_rate_image(device, queue, &rates)?; // Vec<ShadingRate>, row by row
//! # Ok(()) }
//! ```

use crate::Error;
use crate::controller::{Target, ThresholdController};
use crate::gpu::describe;
use mrsl_abi::shading_rate::{DEFAULT_RATE_TILE, RATE_TILE_SIZES, ShadingRate, rate_image_size};
use wgpu::util::DeviceExt;

/// The format of the rate image the rate source writes.
pub const RATE_IMAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// VALAR's quarter-rate sensitivity K (NAS's fitted ratio of quarter- to half-rate error).
pub const DEFAULT_K: f32 = 2.13;
/// VALAR's environment luminance l_env (Eq. 15).
pub const DEFAULT_ENV_LUMA: f32 = 0.05;
/// VALAR's Weber–Fechner constant (the brightness sensitivity's scale).
pub const DEFAULT_WEBER_FECHNER_CONSTANT: f32 = 1.0;
/// The smallest Weber–Fechner divisor (`WEBER_FLOOR` in rate_source.wgsl):
/// keeps a zero constant over black pixels finite.
pub const WEBER_FLOOR: f32 = 1.0e-4;

/// The range a [`ThresholdController`] keeps the sensitivity t in: from
/// far finer than Quality to well past Performance (at t = 4 only tiles whose
/// error exceeds four times the JND threshold keep full rate).
pub const SENSITIVITY_RANGE: (f64, f64) = (0.01, 4.0);

/// VALAR's sensitivity presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// t = 0.25.
    Quality,
    /// t = 0.5.
    Balanced,
    /// t = 0.75.
    Performance,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Quality, Preset::Balanced, Preset::Performance];

    /// The sensitivity threshold t.
    pub fn sensitivity(self) -> f32 {
        match self {
            Preset::Quality => 0.25,
            Preset::Balanced => 0.5,
            Preset::Performance => 0.75,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Preset::Quality => "quality",
            Preset::Balanced => "balanced",
            Preset::Performance => "performance",
        }
    }
}

/// How a second rate (an engine's rate image, the foveation source) combines
/// with the rate computed so far, per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Combiner {
    /// The finer of the two on each axis.
    Min,
    /// The coarser of the two on each axis.
    Max,
    /// The second rate wins.
    Override,
}

impl Combiner {
    fn code(self) -> u32 {
        match self {
            Combiner::Min => 0,
            Combiner::Max => 1,
            Combiner::Override => 2,
        }
    }

    /// The combined rate, as the GPU computes it (4x1 and 1x4 clamped, as
    /// [`ShadingRate::clamp_size`]).
    pub fn apply(self, current: ShadingRate, other: ShadingRate) -> ShadingRate {
        match self {
            Combiner::Min => current.finer(other),
            Combiner::Max => current.coarser(other),
            Combiner::Override => other,
        }
    }
}

/// The built-in foveation source: full rate around the gaze, coarser with
/// distance. A tile's distance is that of its point nearest to the gaze.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foveation {
    /// The gaze point in pixels (x right, y down).
    pub gaze: [f32; 2],
    /// Tiles within this distance (pixels) are 1x1.
    pub inner_radius: f32,
    /// Tiles within this distance (and beyond the inner radius) are 2x2; farther ones 4x4.
    pub outer_radius: f32,
    /// How the foveation rate combines with the content-adaptive one.
    pub combiner: Combiner,
}

impl Foveation {
    /// The foveation rate of the tile of `tile` pixels per side at tile
    /// coordinates `(tx, ty)` of an image of `size` pixels (what the GPU computes).
    pub fn rate(&self, size: (u32, u32), tile: u32, (tx, ty): (u32, u32)) -> ShadingRate {
        let lo = [(tx * tile) as f32, (ty * tile) as f32];
        let hi = [((tx + 1) * tile).min(size.0) as f32, ((ty + 1) * tile).min(size.1) as f32];
        let nearest = [self.gaze[0].clamp(lo[0], hi[0]), self.gaze[1].clamp(lo[1], hi[1])];
        let d = ((nearest[0] - self.gaze[0]).powi(2) + (nearest[1] - self.gaze[1]).powi(2)).sqrt();
        if d <= self.inner_radius {
            ShadingRate::R1x1
        } else if d <= self.outer_radius {
            ShadingRate::R2x2
        } else {
            ShadingRate::R4x4
        }
    }
}

/// The rate source's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateOptions {
    /// Pixels per tile side: one of [`RATE_TILE_SIZES`] (8 or 16).
    pub tile: u32,
    /// The sensitivity threshold t of the JND threshold τ = t · (L̄ + l_env)
    /// (Eq. 15); larger is coarser. See [`Preset`].
    pub sensitivity: f32,
    /// K, the quarter-rate error's factor over the half-rate one (Eq. 14, 21);
    /// lower keeps more tiles from 4x.
    pub k: f32,
    /// l_env, the environment luminance added to the tile's mean (Eq. 15).
    pub env_luma: f32,
    /// Weber–Fechner differences instead of Eq. 2's |ΔL| / 2.
    pub weber_fechner: bool,
    /// The Weber–Fechner brightness sensitivity's scale.
    pub weber_fechner_constant: f32,
    /// Lower rates where the tile moves (Eq. 20, 21, from the tile's minimum
    /// speed): needs [`RateInputs::velocity`].
    pub motion: bool,
    /// Reproject the decisions along the motion vectors when they are given.
    pub reproject: bool,
    /// Temporal damping: a tile coarsens only when its last three decisions agree.
    pub hysteresis: bool,
    /// The built-in foveation source, if any.
    pub foveation: Option<Foveation>,
}

impl RateOptions {
    /// VALAR's defaults at a preset's sensitivity: 8x8 tiles, K = 2.13,
    /// l_env = 0.05, approximate differences, no motion terms, reprojection
    /// and hysteresis on.
    pub fn preset(preset: Preset) -> RateOptions {
        RateOptions {
            tile: DEFAULT_RATE_TILE,
            sensitivity: preset.sensitivity(),
            k: DEFAULT_K,
            env_luma: DEFAULT_ENV_LUMA,
            weber_fechner: false,
            weber_fechner_constant: DEFAULT_WEBER_FECHNER_CONSTANT,
            motion: false,
            reproject: true,
            hysteresis: true,
            foveation: None,
        }
    }

    fn validate(&self) -> Result<(), Error> {
        if !RATE_TILE_SIZES.contains(&self.tile) {
            return Err(Error::BadTileSize(self.tile));
        }
        let mut values = vec![
            ("sensitivity", self.sensitivity),
            ("k", self.k),
            ("env_luma", self.env_luma),
            ("weber_fechner_constant", self.weber_fechner_constant),
        ];
        if let Some(f) = &self.foveation {
            values.extend([
                ("foveation.gaze[0]", f.gaze[0]),
                ("foveation.gaze[1]", f.gaze[1]),
                ("foveation.inner_radius", f.inner_radius),
                ("foveation.outer_radius", f.outer_radius),
            ]);
        }
        for (name, value) in values {
            // A gaze may lie off screen (negative), but must be a number.
            let negative_ok = name.starts_with("foveation.gaze");
            if !value.is_finite() || (value < 0.0 && !negative_ok) {
                return Err(Error::BadRateOption { name, value });
            }
        }
        Ok(())
    }
}

impl Default for RateOptions {
    /// [`Preset::Balanced`].
    fn default() -> RateOptions {
        RateOptions::preset(Preset::Balanced)
    }
}

/// An engine's own rate image and how it combines with the computed rates.
#[derive(Debug, Clone, Copy)]
pub struct ExternalRates<'a> {
    /// One texel per tile, D3D12/Vulkan codes, `R8Uint` (or `R16Uint`,
    /// `R32Uint`), created with `TEXTURE_BINDING`. Codes outside the seven
    /// are clamped per axis (3 reads as 4x) and 4x1/1x4 become 2x1/1x2.
    pub texture: &'a wgpu::Texture,
    pub combiner: Combiner,
}

/// What one rate computation reads.
#[derive(Debug, Clone, Copy)]
pub struct RateInputs<'a> {
    /// The previous frame's output: linear RGB, `Rgba32Float` or
    /// `Rgba16Float`, with `TEXTURE_BINDING`. Its size is the image size.
    pub color: &'a wgpu::Texture,
    /// Motion vectors of that frame: current minus previous position in
    /// pixels, `Rg16Float` or `Rg32Float` (or the RGBA float formats: x and
    /// y are read), the colour's size.
    pub velocity: Option<&'a wgpu::Texture>,
    /// An engine's rate image, combined last.
    pub external: Option<ExternalRates<'a>>,
}

impl<'a> RateInputs<'a> {
    pub fn new(color: &'a wgpu::Texture) -> RateInputs<'a> {
        RateInputs { color, velocity: None, external: None }
    }
}

/// The uniform block of rate_source.wgsl (`Params`).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    size: [u32; 2],
    rate_size: [u32; 2],
    tile: u32,
    flags: u32,
    sensitivity: f32,
    env_luma: f32,
    k: f32,
    weber_fechner: f32,
    fovea_inner: f32,
    fovea_outer: f32,
    gaze: [f32; 2],
    combiners: u32,
    pad: u32,
}

/// `flags` of `Params` (the `FLAG_` constants of rate_source.wgsl).
mod flags {
    pub const WEBER_FECHNER: u32 = 1;
    pub const MOTION: u32 = 2;
    pub const FIRST_FRAME: u32 = 4;
    pub const REPROJECT: u32 = 8;
    pub const EXTERNAL: u32 = 16;
    pub const FOVEATION: u32 = 32;
    pub const HYSTERESIS: u32 = 64;
}

/// The per-size state: the raw decisions of the current frame and the two
/// history images (ping-pong: one read, one written per frame), each texel
/// packing the decisions of the last two frames (`code | previous << 8`).
struct History {
    size: (u32, u32),
    tile: u32,
    raw: wgpu::Texture,
    history: [wgpu::Texture; 2],
    /// The history image the next frame reads.
    current: usize,
    /// No frame recorded yet (creation, resize, tile change, [`RateSource::reset`]).
    first: bool,
}

/// Computes rate images; create one per device and keep it across frames
/// (it holds the history the temporal damping and reprojection need).
pub struct RateSource {
    decide_layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
    /// `decide` for 8x8 and 16x16 tiles (one invocation per tile).
    decide: Vec<(u32, wgpu::ComputePipeline)>,
    resolve: wgpu::ComputePipeline,
    /// Bound where no velocity or external image is given.
    no_velocity: wgpu::Texture,
    no_external: wgpu::Texture,
    state: Option<History>,
}

fn texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: RATE_IMAGE_FORMAT,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

fn uniform_entry() -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture(device: &wgpu::Device, label: &str, size: (u32, u32), format: wgpu::TextureFormat) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

impl RateSource {
    /// Creates the pipelines (both tile sizes) on `device`.
    pub fn new(device: &wgpu::Device) -> Result<RateSource, Error> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let uint = wgpu::TextureSampleType::Uint;
        let decide_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mrsl rate decide"),
            entries: &[uniform_entry(), texture_entry(1, float), texture_entry(2, float), storage_entry(3)],
        });
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mrsl rate resolve"),
            entries: &[
                uniform_entry(),
                texture_entry(2, float),
                texture_entry(4, uint),
                texture_entry(5, uint),
                texture_entry(6, uint),
                storage_entry(7),
                storage_entry(8),
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mrsl rate source"),
            source: wgpu::ShaderSource::Wgsl(include_str!("rate_source.wgsl").into()),
        });
        let pipeline = |layout: &wgpu::BindGroupLayout, entry: &str, constants: &[(&str, f64)]| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
                cache: None,
            })
        };
        let decide = RATE_TILE_SIZES
            .iter()
            .map(|&tile| (tile, pipeline(&decide_layout, "decide", &[("TILE", f64::from(tile))])))
            .collect();
        let resolve = pipeline(&resolve_layout, "resolve", &[]);
        let no_velocity = texture(device, "mrsl rate no velocity", (1, 1), wgpu::TextureFormat::Rg32Float);
        let no_external = texture(device, "mrsl rate no external", (1, 1), RATE_IMAGE_FORMAT);
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        Ok(RateSource { decide_layout, resolve_layout, decide, resolve, no_velocity, no_external, state: None })
    }

    /// Forgets the history: the next frame is treated as the first (full
    /// rate), as after a camera cut.
    pub fn reset(&mut self) {
        if let Some(state) = &mut self.state {
            state.first = true;
        }
    }

    /// Records the rate computation into `encoder`: reads `inputs` (the
    /// previous frame), writes one code per tile into `target` (an
    /// [`RATE_IMAGE_FORMAT`] storage texture of [`rate_image_size`], e.g. from
    /// [`create_rate_image`]) and advances the history. The first frame after
    /// creation, [`RateSource::reset`], or a change of image or tile size
    /// is 1x1 before the combiners. Call it once per submitted frame: the
    /// history advances at every call.
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &RateInputs,
        options: &RateOptions,
        target: &wgpu::Texture,
    ) -> Result<(), Error> {
        options.validate()?;
        let tile = options.tile;
        let size = validate_inputs(inputs, options)?;
        let rate_size = rate_image_size(size, tile);
        check_rate_texture(target, "the rate image (target)", size, tile, &[RATE_IMAGE_FORMAT], "R32Uint")?;
        if !target.usage().contains(wgpu::TextureUsages::STORAGE_BINDING) {
            return Err(Error::RateUsage { what: "the rate image (target)", missing: "STORAGE_BINDING" });
        }
        if self.state.as_ref().is_none_or(|s| s.size != size || s.tile != tile) {
            self.state = Some(History {
                size,
                tile,
                raw: texture(device, "mrsl rate decisions", rate_size, RATE_IMAGE_FORMAT),
                history: [
                    texture(device, "mrsl rate history a", rate_size, RATE_IMAGE_FORMAT),
                    texture(device, "mrsl rate history b", rate_size, RATE_IMAGE_FORMAT),
                ],
                current: 0,
                first: true,
            });
        }
        let state = self.state.as_mut().expect("the history was just ensured");
        let mut bits = 0;
        for (on, flag) in [
            (options.weber_fechner, flags::WEBER_FECHNER),
            (options.motion, flags::MOTION),
            (state.first, flags::FIRST_FRAME),
            (options.reproject && inputs.velocity.is_some(), flags::REPROJECT),
            (inputs.external.is_some(), flags::EXTERNAL),
            (options.foveation.is_some(), flags::FOVEATION),
            (options.hysteresis, flags::HYSTERESIS),
        ] {
            if on {
                bits |= flag;
            }
        }
        let fovea = options.foveation;
        let params = Params {
            size: [size.0, size.1],
            rate_size: [rate_size.0, rate_size.1],
            tile,
            flags: bits,
            sensitivity: options.sensitivity,
            env_luma: options.env_luma,
            k: options.k,
            weber_fechner: options.weber_fechner_constant,
            fovea_inner: fovea.map_or(0.0, |f| f.inner_radius),
            fovea_outer: fovea.map_or(0.0, |f| f.outer_radius),
            gaze: fovea.map_or([0.0; 2], |f| f.gaze),
            combiners: inputs.external.map_or(0, |e| e.combiner.code()) | fovea.map_or(0, |f| f.combiner.code()) << 4,
            pad: 0,
        };
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        // A buffer per call rather than `queue.write_buffer`: two frames
        // encoded before one submit each keep their own parameters.
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl rate params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let color = view(inputs.color);
        let velocity = view(inputs.velocity.unwrap_or(&self.no_velocity));
        let external = view(inputs.external.map_or(&self.no_external, |e| e.texture));
        let raw = view(&state.raw);
        let history_in = view(&state.history[state.current]);
        let history_out = view(&state.history[1 - state.current]);
        let target_view = view(target);
        fn entry(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) }
        }
        let uniform_entry = wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() };
        let decide_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl rate decide"),
            layout: &self.decide_layout,
            entries: &[uniform_entry.clone(), entry(1, &color), entry(2, &velocity), entry(3, &raw)],
        });
        let resolve_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mrsl rate resolve"),
            layout: &self.resolve_layout,
            entries: &[
                uniform_entry,
                entry(2, &velocity),
                entry(4, &raw),
                entry(5, &history_in),
                entry(6, &external),
                entry(7, &target_view),
                entry(8, &history_out),
            ],
        });
        let decide = &self.decide.iter().find(|(t, _)| *t == tile).expect("a pipeline per supported tile size").1;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("mrsl rate decide"),
                timestamp_writes: None,
            });
            pass.set_pipeline(decide);
            pass.set_bind_group(0, &decide_group, &[]);
            // One invocation per tile, 8x8 tiles per workgroup.
            pass.dispatch_workgroups(rate_size.0.div_ceil(8), rate_size.1.div_ceil(8), 1);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("mrsl rate resolve"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.resolve);
            pass.set_bind_group(0, &resolve_group, &[]);
            pass.dispatch_workgroups(rate_size.0.div_ceil(8), rate_size.1.div_ceil(8), 1);
        }
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(describe(&error)));
        }
        state.current = 1 - state.current;
        state.first = false;
        Ok(())
    }
}

/// Checks the inputs against each other and the options; returns the image size.
fn validate_inputs(inputs: &RateInputs, options: &RateOptions) -> Result<(u32, u32), Error> {
    use wgpu::TextureFormat as F;
    let color = inputs.color;
    if !matches!(color.format(), F::Rgba32Float | F::Rgba16Float) {
        return Err(Error::RateFormat {
            what: "the colour input",
            expected: "Rgba32Float or Rgba16Float",
            found: color.format(),
        });
    }
    if !color.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(Error::RateUsage { what: "the colour input", missing: "TEXTURE_BINDING" });
    }
    let size = (color.width(), color.height());
    if size.0 == 0 || size.1 == 0 {
        return Err(Error::BadSize { width: size.0, height: size.1, reason: "the colour input is empty".into() });
    }
    match inputs.velocity {
        None if options.motion => return Err(Error::MissingVelocity),
        None => {}
        Some(v) => {
            if !matches!(v.format(), F::Rg16Float | F::Rg32Float | F::Rgba16Float | F::Rgba32Float) {
                return Err(Error::RateFormat {
                    what: "the velocity input",
                    expected: "Rg16Float or Rg32Float (or Rgba16Float, Rgba32Float)",
                    found: v.format(),
                });
            }
            if !v.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
                return Err(Error::RateUsage { what: "the velocity input", missing: "TEXTURE_BINDING" });
            }
            if (v.width(), v.height()) != size {
                return Err(Error::SizeMismatch {
                    what: "velocity",
                    name: "velocity".into(),
                    width: size.0,
                    height: size.1,
                    found_width: v.width(),
                    found_height: v.height(),
                });
            }
        }
    }
    if let Some(e) = inputs.external {
        let what = "the external rate image";
        check_rate_texture(e.texture, what, size, options.tile, &[F::R8Uint, F::R16Uint, F::R32Uint], "R8Uint")?;
        if !e.texture.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return Err(Error::RateUsage { what, missing: "TEXTURE_BINDING" });
        }
    }
    Ok(size)
}

/// Checks a rate image's format and size for an image of `size` pixels.
fn check_rate_texture(
    texture: &wgpu::Texture,
    what: &'static str,
    size: (u32, u32),
    tile: u32,
    formats: &[wgpu::TextureFormat],
    expected: &'static str,
) -> Result<(), Error> {
    if !formats.contains(&texture.format()) {
        return Err(Error::RateFormat { what, expected, found: texture.format() });
    }
    let want = rate_image_size(size, tile);
    let found = (texture.width(), texture.height());
    if found != want {
        return Err(Error::RateImageSize { what, image: size, tile, expected: want, found });
    }
    Ok(())
}

/// Creates the rate image for an image of `size` pixels and `tile`-pixel
/// tiles: [`RATE_IMAGE_FORMAT`], [`rate_image_size`] texels, usable as the
/// rate source's target (`STORAGE_BINDING`), by the `rate-image` kernels
/// (`TEXTURE_BINDING`) and by [`read_rate_image`] (`COPY_SRC`).
pub fn create_rate_image(device: &wgpu::Device, size: (u32, u32), tile: u32) -> Result<wgpu::Texture, Error> {
    if !RATE_TILE_SIZES.contains(&tile) {
        return Err(Error::BadTileSize(tile));
    }
    if size.0 == 0 || size.1 == 0 {
        return Err(Error::BadSize { width: size.0, height: size.1, reason: "an empty image has no tiles".into() });
    }
    Ok(texture(device, "mrsl rate image", rate_image_size(size, tile), RATE_IMAGE_FORMAT))
}

/// Uploads an engine-side rate image: `rates` row by row, `size` texels
/// (one per tile), as an `R8Uint` texture of D3D12/Vulkan codes usable as
/// [`ExternalRates::texture`].
pub fn upload_rate_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    size: (u32, u32),
    rates: &[ShadingRate],
) -> Result<wgpu::Texture, Error> {
    if size.0 == 0 || size.1 == 0 || rates.len() as u64 != u64::from(size.0) * u64::from(size.1) {
        return Err(Error::BadSize {
            width: size.0,
            height: size.1,
            reason: format!("{} rates were given for {} texels", rates.len(), u64::from(size.0) * u64::from(size.1)),
        });
    }
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("mrsl external rate image"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R8Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let codes: Vec<u8> = rates.iter().map(|r| r.code()).collect();
    queue.write_texture(
        texture.as_image_copy(),
        &codes,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(size.0), rows_per_image: Some(size.1) },
        texture.size(),
    );
    Ok(texture)
}

/// Reads a rate image back (waits for the GPU): one rate per texel, row by
/// row. Takes the `R32Uint` images the rate source writes and engines'
/// `R8Uint` (or `R16Uint`) ones; the texture needs `COPY_SRC`.
pub fn read_rate_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<Vec<ShadingRate>, Error> {
    use wgpu::TextureFormat as F;
    let what = "the rate image to read back";
    let bytes_per_texel = match texture.format() {
        F::R8Uint => 1,
        F::R16Uint => 2,
        F::R32Uint => 4,
        found => return Err(Error::RateFormat { what, expected: "R8Uint, R16Uint or R32Uint", found }),
    };
    if !texture.usage().contains(wgpu::TextureUsages::COPY_SRC) {
        return Err(Error::RateUsage { what, missing: "COPY_SRC" });
    }
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_texel;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mrsl rate image readback"),
        size: u64::from(padded) * u64::from(height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        texture.size(),
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Readback(e.to_string()))?;
    rx.recv().map_err(|e| Error::Readback(e.to_string()))?.map_err(|e| Error::Readback(e.to_string()))?;
    let view = slice.get_mapped_range().map_err(|e| Error::Readback(e.to_string()))?;
    let mut rates = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        let line = &view[y * padded as usize..][..row as usize];
        for (x, texel) in line.chunks_exact(bytes_per_texel as usize).enumerate() {
            let mut word = [0u8; 4];
            word[..texel.len()].copy_from_slice(texel);
            let code = u32::from_le_bytes(word);
            let rate = u8::try_from(code).ok().and_then(ShadingRate::from_code).ok_or_else(|| {
                Error::Readback(format!("rate image texel ({x}, {y}) holds {code:#x}, which is not a rate's code"))
            })?;
            rates.push(rate);
        }
    }
    Ok(rates)
}

/// The fraction of per-pixel shading work `rates` (one per tile, row by row,
/// as [`read_rate_image`] returns them) asks for over an image of `size`
/// pixels: shading cells (cut by the image border where partial) per pixel;
/// 1 for 1x1 everywhere, 1/16 for 4x4 on a multiple of 4. `None` when the
/// count of rates does not match the image.
pub fn rate_fraction(rates: &[ShadingRate], size: (u32, u32), tile: u32) -> Option<f64> {
    let (tw, th) = rate_image_size(size, tile.max(1));
    if tile == 0 || size.0 == 0 || size.1 == 0 || rates.len() as u64 != u64::from(tw) * u64::from(th) {
        return None;
    }
    let mut cells = 0u64;
    for (i, rate) in rates.iter().enumerate() {
        let (tx, ty) = (i as u32 % tw, i as u32 / tw);
        let w = (size.0 - tx * tile).min(tile);
        let h = (size.1 - ty * tile).min(tile);
        let (a, b) = rate.size();
        cells += u64::from(w.div_ceil(a)) * u64::from(h.div_ceil(b));
    }
    Some(cells as f64 / (f64::from(size.0) * f64::from(size.1)))
}

/// VALAR's dynamic threshold: t = GPU time / (1000 / FPS target), the
/// fraction of the frame budget the GPU took, clamped to [0, 1] (VALAR's
/// slider range). `None` for a non-finite or negative time or a target that
/// is not a positive frame rate.
pub fn valar_sensitivity(gpu_time_ms: f64, fps_target: f64) -> Option<f64> {
    let valid = gpu_time_ms.is_finite() && gpu_time_ms >= 0.0 && fps_target.is_finite() && fps_target > 0.0;
    valid.then(|| (gpu_time_ms / (1000.0 / fps_target)).clamp(0.0, 1.0))
}

/// A [`ThresholdController`] whose knob is the sensitivity t (within
/// [`SENSITIVITY_RANGE`]), starting at `initial`: the shaded fraction and the
/// pass time both fall as t rises, as the controller assumes. Measure the
/// fraction of a frame's rates with [`rate_fraction`] and set
/// [`RateOptions::sensitivity`] to `threshold()` each frame.
pub fn sensitivity_controller(target: Target, initial: f32) -> ThresholdController {
    ThresholdController::new(target, f64::from(initial), SENSITIVITY_RANGE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valars() {
        let t: Vec<f32> = Preset::ALL.iter().map(|p| p.sensitivity()).collect();
        assert_eq!(t, [0.25, 0.5, 0.75]);
        let o = RateOptions::default();
        assert_eq!((o.tile, o.sensitivity, o.k, o.env_luma, o.weber_fechner_constant), (8, 0.5, 2.13, 0.05, 1.0));
    }

    #[test]
    fn budget_rule_is_valars() {
        // 10 ms of a 30 FPS budget (33.3 ms) is t = 0.3.
        assert!((valar_sensitivity(10.0, 30.0).unwrap() - 0.3).abs() < 1e-12);
        assert_eq!(valar_sensitivity(50.0, 30.0), Some(1.0));
        assert_eq!(valar_sensitivity(0.0, 60.0), Some(0.0));
        assert_eq!(valar_sensitivity(5.0, 0.0), None);
        assert_eq!(valar_sensitivity(f64::NAN, 60.0), None);
        assert_eq!(valar_sensitivity(-1.0, 60.0), None);
    }

    #[test]
    fn options_are_validated_without_panicking() {
        let bad = |o: RateOptions| o.validate().unwrap_err();
        assert_eq!(bad(RateOptions { tile: 4, ..Default::default() }), Error::BadTileSize(4));
        assert!(matches!(
            bad(RateOptions { sensitivity: f32::NAN, ..Default::default() }),
            Error::BadRateOption { name: "sensitivity", .. }
        ));
        assert_eq!(bad(RateOptions { k: -1.0, ..Default::default() }), Error::BadRateOption { name: "k", value: -1.0 });
        let fovea =
            Foveation { gaze: [-5.0, 3.0], inner_radius: 1.0, outer_radius: f32::INFINITY, combiner: Combiner::Min };
        assert_eq!(
            bad(RateOptions { foveation: Some(fovea), ..Default::default() }),
            Error::BadRateOption { name: "foveation.outer_radius", value: f32::INFINITY }
        );
        let fovea = Foveation { outer_radius: 2.0, ..fovea };
        assert_eq!(RateOptions { foveation: Some(fovea), tile: 16, ..Default::default() }.validate(), Ok(()));
    }

    #[test]
    fn rate_fraction_counts_cells_cut_by_the_border() {
        assert_eq!(rate_fraction(&[ShadingRate::R1x1; 4], (16, 16), 8), Some(1.0));
        assert_eq!(rate_fraction(&[ShadingRate::R4x4; 4], (16, 16), 8), Some(1.0 / 16.0));
        // 10x10 pixels, tiles 8: the 2x2 tiles hold 8x8, 2x8, 8x2, 2x2 pixels;
        // at 4x4: 4 + 2 + 2 + 1 cells.
        assert_eq!(rate_fraction(&[ShadingRate::R4x4; 4], (10, 10), 8), Some(9.0 / 100.0));
        assert_eq!(rate_fraction(&[ShadingRate::R2x4; 2], (16, 8), 8), Some(16.0 / 128.0));
        assert_eq!(rate_fraction(&[ShadingRate::R1x1; 3], (16, 16), 8), None);
    }

    #[test]
    fn foveation_rings_are_measured_from_the_nearest_point_of_a_tile() {
        let f = Foveation { gaze: [20.0, 20.0], inner_radius: 4.0, outer_radius: 12.0, combiner: Combiner::Override };
        // The gaze's own tile, a tile whose edge lies 4 px away, then 12 and 20 px.
        assert_eq!(f.rate((64, 64), 8, (2, 2)), ShadingRate::R1x1);
        assert_eq!(f.rate((64, 64), 8, (3, 2)), ShadingRate::R1x1);
        assert_eq!(f.rate((64, 64), 8, (4, 2)), ShadingRate::R2x2);
        assert_eq!(f.rate((64, 64), 8, (5, 2)), ShadingRate::R4x4);
    }

    #[test]
    fn combiners_are_those_of_the_abi() {
        use ShadingRate::*;
        assert_eq!(Combiner::Min.apply(R4x2, R2x4), R2x2);
        assert_eq!(Combiner::Max.apply(R4x2, R1x2), R4x2);
        assert_eq!(Combiner::Override.apply(R4x4, R1x2), R1x2);
    }
}
