//! mrsl-abi: the contract between the mrsl compiler and the runtime that
//! dispatches its kernels.
//!
//! Everything both sides must agree on is stated here once:
//!
//! - [`Layout`]: every binding, uniform offset, G-buffer channel, output and
//!   interface slot of a compiled program, with typed formats and types. It
//!   is what `mrslc compile` writes as `STEM.layout.json` and reads back
//!   unchanged ([`LAYOUT_FORMAT`] names its version).
//! - [`KernelKind`]: the kernels a program compiles to, their file names,
//!   entry points (in dispatch order) and workgroup sizes, in one table.
//! - [`Control`]: the runtime-owned uniform block every kernel reads, as one
//!   `#[repr(C)]` type.
//! - [`geometry`]: the dispatch geometry: coarse sample lattices, the
//!   hierarchical mode's levels and work lists, tiles and quads per workgroup.
//! - [`Mode`]: the modes a program is dispatched in, and the kernels each
//!   needs ([`Mode::kernels`], the one table of mode → kernels).
//! - [`Plan`]: what every mode runs (passes, dispatches, the resources each
//!   binding takes and how they are sized), as data the runtimes interpret;
//!   part of the layout.
//! - [`CompiledProgram`]: kernels plus layout, read from and written to the
//!   files `mrslc compile -o DIR` produces.
//!
//! The compiler produces these values and the runtime consumes them; neither
//! restates them. The crate depends on serde, serde_json and bytemuck only,
//! so an engine that loads precompiled kernels links no compiler code.

mod control;
pub mod geometry;
mod kernel;
mod layout;
mod mode;
pub mod plan;
mod program;
pub mod shading_rate;
mod types;

pub use control::{CONTROL_FIELDS, Control, ControlField};
pub use kernel::{KernelKind, entry};
pub use layout::{
    BACKGROUND_MARK, Background, BevyField, Channel, ChannelAccess, ControlBlock, Decode, EffectLayout, Field,
    HierarchicalLayout, InterfaceLayout, KeyCompare, LAYOUT_FORMAT, Layout, LevelsLayout, NeighbourLayout,
    NeighbourValue, Output, Rate, RefineMaskTexel, Resample, ResourceBinding, ResourceKind, SlotLayout, StatsLayout,
    TileLayout, UniformBlock,
};
pub use mode::{KernelRef, Mode, UnknownMode};
pub use plan::{BindingType, Device, Plan, ResourceId};
pub use program::{CompiledProgram, Kernel, ReadError};
pub use shading_rate::ShadingRate;
pub use types::{SampleType, Scalar, TextureFormat, ValueType};

/// Bind group of the control block, user uniforms, textures and samplers.
pub const GROUP_RESOURCES: u32 = 0;
/// Bind group of the G-buffer channels.
pub const GROUP_GBUFFER: u32 = 1;
/// Bind group of the interface buffer, the outputs and the mode's buffers.
pub const GROUP_STAGE: u32 = 2;
/// Bind group of the hierarchical mode's indirect dispatch arguments, seen only
/// by its `hier_args_*` entry points (a buffer cannot be indirect and writable
/// in one dispatch).
pub const GROUP_ARGS: u32 = 3;
/// Binding of the runtime-owned control block in [`GROUP_RESOURCES`].
pub const BINDING_CONTROL: u32 = 0;
/// Binding of the user uniform block in [`GROUP_RESOURCES`].
pub const BINDING_UNIFORMS: u32 = 1;
/// Binding of the indirect dispatch arguments in [`GROUP_ARGS`].
pub const BINDING_ARGS: u32 = 0;
