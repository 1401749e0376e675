//! mrsl-runtime: executes compiled mrsl programs with wgpu.
//!
//! The engine owns the device, the G-buffer textures and the output
//! textures; [`Shader`] owns the pipelines, the uniform and control blocks
//! and the coarse-to-fine interface buffer, and records its passes into the
//! engine's command encoder. Programs arrive as a [`CompiledProgram`]: read
//! from the files `mrslc compile -o DIR` wrote, or (with the `compile`
//! feature) compiled from source at load time.
//!
//! ```no_run
//! # fn demo(device: &wgpu::Device, queue: &wgpu::Queue,
//! #         normal: &wgpu::Texture, color: &wgpu::Texture) -> Result<(), Box<dyn std::error::Error>> {
//! use mrsl_runtime::{Bindings, CompiledProgram, DispatchOptions, Mode, Shader};
//! let program = CompiledProgram::read_dir("kernels".as_ref(), None)?;
//! let mut shader = Shader::new(device, &program)?;
//! let mut bindings = Bindings { size: (color.width(), color.height()), ..Default::default() };
//! bindings.channels.insert("normal".into(), normal);
//! bindings.outputs.insert("color".into(), color);
//! let mut encoder = device.create_command_encoder(&Default::default());
//! shader.encode(device, queue, &mut encoder, &bindings, DispatchOptions::new(Mode::Coarse4x4))?;
//! queue.submit([encoder.finish()]);
//! let stats = shader.read_stats(device)?;
//! println!("shaded {:.1}% of the reference's work", 100.0 * stats.shaded_fraction);
//! # Ok(()) }
//! ```
//!
//! The crate depends on `mrsl-abi` (the contract with the compiler), wgpu
//! without any backend (the application enables the ones it ships),
//! bytemuck, thiserror, serde and pollster.

mod bindings;
pub mod controller;
mod error;
pub mod gpu;
mod groups;
mod pool;
pub mod rate_source;
mod shader;
mod stats;
mod uniforms;
mod validate;

pub use bindings::Bindings;
pub use error::Error;
pub use gpu::wgpu_format;
pub use mrsl_abi::{CompiledProgram, KernelKind, Layout, Mode, Plan, ReadError, RefineMaskTexel};
pub use rate_source::{Combiner, ExternalRates, Foveation, Preset, RateInputs, RateOptions, RateSource};
pub use shader::{DispatchOptions, Shader};
pub use stats::{EffectStats, Stats, Timings};

/// Compiles mrsl source into the kernels and layout [`Shader::new`] takes,
/// for every mode; errors are the rendered diagnostics (`file_name` names
/// the source in them). An engine that runs fewer modes compiles faster
/// with [`compile_modes`].
#[cfg(feature = "compile")]
pub fn compile(source: &str, file_name: &str) -> Result<CompiledProgram, Error> {
    compile_modes(source, file_name, &Mode::ALL)
}

/// Compiles mrsl source into the kernels of `modes` alone (the union of
/// their [`Mode::kernels`]) and the layout; [`Shader::encode`] refuses the
/// other modes with [`Error::UnsupportedMode`].
#[cfg(feature = "compile")]
pub fn compile_modes(source: &str, file_name: &str, modes: &[Mode]) -> Result<CompiledProgram, Error> {
    let options = mrsl::Options { file_name: file_name.into(), ..mrsl::Options::for_modes(modes) };
    mrsl::compile(source, &options)
        .map(|program| program.compiled)
        .map_err(|diagnostics| Error::Compile(mrsl::render_all(&diagnostics, file_name, source)))
}
