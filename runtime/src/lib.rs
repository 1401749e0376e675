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

pub mod controller;
mod error;
pub mod rate_source;
mod shader;
mod stats;

pub use error::Error;
use mrsl_abi::geometry::{DYNAMIC_INNER_BLOCK, DYNAMIC_OUTER_BLOCK};
pub use mrsl_abi::{CompiledProgram, KernelKind, Layout, ReadError};
pub use rate_source::{Combiner, ExternalRates, Foveation, Preset, RateInputs, RateOptions, RateSource};
pub use shader::{Bindings, DispatchOptions, Shader, wgpu_format};
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
    let options = mrsl::Options { file_name: file_name.into(), ..compile_options(modes) };
    mrsl::compile(source, &options)
        .map(|program| program.compiled)
        .map_err(|diagnostics| Error::Compile(mrsl::render_all(&diagnostics, file_name, source)))
}

/// The compiler options that generate exactly the kernels of `modes`.
#[cfg(feature = "compile")]
pub fn compile_options(modes: &[Mode]) -> mrsl::Options {
    let mut options = mrsl::Options::none();
    for &mode in modes {
        match mode {
            Mode::Reference => options.reference = true,
            Mode::Coarse2x2 | Mode::Coarse4x4 => {
                let block = mode.block_size().expect("block modes have a block size");
                if !options.block_sizes.contains(&block) {
                    options.block_sizes.push(block);
                }
                options.coarse = true;
                options.fine = true;
            }
            // Its 4x4 level is the ordinary 4x4 coarse kernel, which the flag adds.
            Mode::Dynamic => options.dynamic = true,
            Mode::Hierarchical => options.hierarchical = true,
            Mode::Checkerboard => options.checkerboard = true,
            Mode::RateImage => options.rate_image = true,
        }
    }
    options.block_sizes.sort();
    options
}

/// How a program is dispatched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Every effect per pixel.
    Reference,
    /// One coarse sample per 2x2 block, refined per block.
    Coarse2x2,
    /// One coarse sample per 4x4 block, refined per block.
    Coarse4x4,
    /// He et al.'s DYNAMIC: 4x4 blocks; where refined, 2x2 blocks; where
    /// refined again, per pixel.
    Dynamic,
    /// Mallett & Yuksel's DACS: every 4th pixel shaded, then four levels each
    /// interpolated from previous-level neighbours or shaded (compacted work lists).
    Hierarchical,
    /// The baseline DACS compares with: coarse effects shaded in half the 2x2
    /// quads (a checkerboard), reconstructed in the others; not adaptive.
    Checkerboard,
    /// Software variable-rate shading: coarse effects shaded at a per-tile
    /// rate (1x1 to 4x4, anisotropic ones included) read from a shading-rate
    /// image ([`Bindings::shading_rate`]), refined inside a tile as in the
    /// block modes.
    RateImage,
}

impl Mode {
    pub const ALL: [Mode; 7] = [
        Mode::Reference,
        Mode::Coarse2x2,
        Mode::Coarse4x4,
        Mode::Dynamic,
        Mode::Hierarchical,
        Mode::Checkerboard,
        Mode::RateImage,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Reference => "reference",
            Mode::Coarse2x2 => "coarse2x2",
            Mode::Coarse4x4 => "coarse4x4",
            Mode::Dynamic => "dynamic",
            Mode::Hierarchical => "hierarchical",
            Mode::Checkerboard => "checkerboard",
            Mode::RateImage => "rate-image",
        }
    }

    /// The kernels the mode dispatches, with their block sizes.
    pub fn kernels(self) -> &'static [(KernelKind, Option<u32>)] {
        match self {
            Mode::Reference => &[(KernelKind::Reference, None)],
            Mode::Coarse2x2 => &[(KernelKind::Coarse, Some(2)), (KernelKind::Fine, Some(2))],
            Mode::Coarse4x4 => &[(KernelKind::Coarse, Some(4)), (KernelKind::Fine, Some(4))],
            // The 4x4 level is the ordinary 4x4 coarse kernel; the dynamic mode has its own fine kernel.
            Mode::Dynamic => &[
                (KernelKind::Coarse, Some(DYNAMIC_OUTER_BLOCK)),
                (KernelKind::DynamicCoarse, Some(DYNAMIC_INNER_BLOCK)),
                (KernelKind::DynamicFine, Some(DYNAMIC_OUTER_BLOCK)),
            ],
            Mode::Hierarchical => &[(KernelKind::Hierarchical, None)],
            Mode::Checkerboard => &[(KernelKind::Checkerboard, None)],
            Mode::RateImage => &[(KernelKind::RateCoarse, None), (KernelKind::RateFine, None)],
        }
    }

    /// The (first) coarse block size, or `None` for per-pixel shading.
    pub fn block_size(self) -> Option<u32> {
        match self {
            Mode::Reference | Mode::Hierarchical | Mode::Checkerboard | Mode::RateImage => None,
            Mode::Coarse2x2 => Some(2),
            Mode::Coarse4x4 => Some(4),
            Mode::Dynamic => Some(DYNAMIC_OUTER_BLOCK),
        }
    }
}

impl std::str::FromStr for Mode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Mode, Error> {
        Mode::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| Error::UnknownMode(s.to_string()))
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
