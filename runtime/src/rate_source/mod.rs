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

mod images;
mod interface;
mod options;

pub use images::{RATE_IMAGE_FORMAT, create_rate_image, rate_fraction, read_rate_image, upload_rate_image};
pub use options::{
    Combiner, DEFAULT_ENV_LUMA, DEFAULT_K, DEFAULT_WEBER_FECHNER_CONSTANT, ExternalRates, Foveation, Preset,
    RateInputs, RateOptions, SENSITIVITY_RANGE, WEBER_FLOOR, sensitivity_controller, valar_sensitivity,
};

use crate::Error;
use crate::gpu::describe;
use images::{check_rate_texture, texture};
use interface::{Binding, Entry, Flag, Params};
use mrsl_abi::shading_rate::{RATE_TILE_SIZES, rate_image_size};
use wgpu::util::DeviceExt;

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

impl History {
    fn new(device: &wgpu::Device, size: (u32, u32), tile: u32) -> History {
        let rate_size = rate_image_size(size, tile);
        History {
            size,
            tile,
            raw: texture(device, "mrsl rate decisions", rate_size, RATE_IMAGE_FORMAT),
            history: [
                texture(device, "mrsl rate history a", rate_size, RATE_IMAGE_FORMAT),
                texture(device, "mrsl rate history b", rate_size, RATE_IMAGE_FORMAT),
            ],
            current: 0,
            first: true,
        }
    }
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

impl RateSource {
    /// Creates the pipelines (both tile sizes) on `device`.
    pub fn new(device: &wgpu::Device) -> Result<RateSource, Error> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let decide_layout = interface::layout(device, Entry::Decide);
        let resolve_layout = interface::layout(device, Entry::Resolve);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mrsl rate source"),
            source: wgpu::ShaderSource::Wgsl(
                format!("{}{}", interface::wgsl_declarations(), include_str!("rate_source.wgsl")).into(),
            ),
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
            self.state = Some(History::new(device, size, tile));
        }
        let state = self.state.as_mut().expect("the history was just ensured");
        let params = params(inputs, options, size, state.first);
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        // A buffer per call rather than `queue.write_buffer`: two frames
        // encoded before one submit each keep their own parameters.
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mrsl rate params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let texture_of = |binding: Binding| match binding {
            Binding::Color => view(inputs.color),
            Binding::Velocity => view(inputs.velocity.unwrap_or(&self.no_velocity)),
            Binding::ExternalRates => view(inputs.external.map_or(&self.no_external, |e| e.texture)),
            Binding::RawOut | Binding::RawIn => view(&state.raw),
            Binding::HistoryIn => view(&state.history[state.current]),
            Binding::HistoryOut => view(&state.history[1 - state.current]),
            Binding::TargetOut => view(target),
            Binding::Params => unreachable!("the parameters are a buffer"),
        };
        let decide_group = interface::group(device, &self.decide_layout, Entry::Decide, &uniform, texture_of);
        let resolve_group = interface::group(device, &self.resolve_layout, Entry::Resolve, &uniform, texture_of);
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

/// The rate kernels' parameters for a frame of `size` pixels (`first`: no
/// frame recorded before it).
fn params(inputs: &RateInputs, options: &RateOptions, size: (u32, u32), first: bool) -> Params {
    let tile = options.tile;
    let rate_size = rate_image_size(size, tile);
    let mut bits = 0;
    for (on, flag) in [
        (options.weber_fechner, Flag::WeberFechner),
        (options.motion, Flag::Motion),
        (first, Flag::FirstFrame),
        (options.reproject && inputs.velocity.is_some(), Flag::Reproject),
        (inputs.external.is_some(), Flag::External),
        (options.foveation.is_some(), Flag::Foveation),
        (options.hysteresis, Flag::Hysteresis),
    ] {
        if on {
            bits |= flag.bit();
        }
    }
    let fovea = options.foveation;
    Params {
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
        color_channels: color_channels(inputs.color.format()).expect("validated"),
    }
}

/// The colour formats the rate source reads.
const COLOR_FORMATS: &str =
    "a float format of one, two or four channels (R32Float, R16Float, Rg32Float, Rg16Float, Rgba32Float, Rgba16Float)";

/// The channels of a colour input the rate source reads, by format.
fn color_channels(format: wgpu::TextureFormat) -> Option<u32> {
    use wgpu::TextureFormat as F;
    match format {
        F::R32Float | F::R16Float => Some(1),
        F::Rg32Float | F::Rg16Float => Some(2),
        F::Rgba32Float | F::Rgba16Float => Some(4),
        _ => None,
    }
}

/// Checks the inputs against each other and the options; returns the image size.
fn validate_inputs(inputs: &RateInputs, options: &RateOptions) -> Result<(u32, u32), Error> {
    use wgpu::TextureFormat as F;
    let color = inputs.color;
    if color_channels(color.format()).is_none() {
        return Err(Error::RateFormat { what: "the colour input", expected: COLOR_FORMATS, found: color.format() });
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
