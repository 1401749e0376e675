//! mrsl-runtime: executes compiled mrsl programs with wgpu.
//!
//! The engine owns the device, the G-buffer textures and the output
//! textures; [`Shader`] owns the pipelines, the uniform and control blocks
//! and the coarse-to-fine interface buffer, and records its passes into the
//! engine's command encoder:
//!
//! ```no_run
//! # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, program: &mrsl::Program,
//! #         normal: &wgpu::Texture, color: &wgpu::Texture) -> Result<(), mrsl_runtime::Error> {
//! use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
//! let mut shader = Shader::new(device, program)?;
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

pub mod controller;
mod error;
pub mod gpu;
pub mod mesh;
pub mod mesh_scene;
pub mod metrics;
pub mod raster;
pub mod rig;
pub mod scene;
pub mod scene_file;
mod shader;
mod stats;

pub use error::Error;
pub use shader::{Bindings, DispatchOptions, Shader, components};
pub use stats::{EffectStats, Stats, Timings};

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
}

impl Mode {
    pub const ALL: [Mode; 6] =
        [Mode::Reference, Mode::Coarse2x2, Mode::Coarse4x4, Mode::Dynamic, Mode::Hierarchical, Mode::Checkerboard];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Reference => "reference",
            Mode::Coarse2x2 => "coarse2x2",
            Mode::Coarse4x4 => "coarse4x4",
            Mode::Dynamic => "dynamic",
            Mode::Hierarchical => "hierarchical",
            Mode::Checkerboard => "checkerboard",
        }
    }

    /// The (first) coarse block size, or `None` for per-pixel shading.
    pub fn block_size(self) -> Option<u32> {
        match self {
            Mode::Reference | Mode::Hierarchical | Mode::Checkerboard => None,
            Mode::Coarse2x2 => Some(2),
            Mode::Coarse4x4 | Mode::Dynamic => Some(4),
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
