//! Figures of a mode's plan that any device can report, next to its time:
//! what a GPU engineer reads to judge a frame before timing it.
//!
//! - **Dispatches per frame**: the plan's dispatches (each a launch, and a
//!   barrier before the next one that reads what it wrote).
//! - **Global bytes per pixel**: a model of the memory traffic, from the
//!   plan's data alone: every pass touches, once, each resource its stage
//!   group binds (at its size for the image), the G-buffer channels at the
//!   positions it runs over (every pixel, or every coarse sample), and the
//!   outputs it writes. Timed runs leave out the statistics and the refine
//!   mask, and so does the model. Caches make repeated reads of one
//!   resource cheaper than this says; a resource read at several places per
//!   pixel (the four corners of a block) costs more than once in time but
//!   is counted once. Of it, the bytes of the coarse-to-fine interface
//!   (records and neighbour values), which the tile kernel keeps in
//!   workgroup memory.
//! - **Workgroup memory**: the most any of the mode's kernels declares per
//!   workgroup (`Pass::workgroup_bytes`, measured on the kernel by the
//!   compiler), against the device's `maxComputeWorkgroupStorageSize`
//!   (WebGPU's default: 16 KiB).
//! - **Evaluations per coarse sample**: the most any coarse effect's body
//!   runs per coarse sample in the block modes (`EffectLayout::sample_evaluations`
//!   in the tile kernel, `coarse_kernel_sample_evaluations` in the two-pass
//!   coarse kernel), and for the tile kernel how many samples a workgroup evaluates per
//!   sample it owns (its tile's border overlaps the next tile's).

use mrsl_abi::plan::{BindingType, ModePlan, ResourceId, Shape, Step, Workgroups};
use mrsl_abi::{KernelKind, Layout, Plan};
use serde::Serialize;

/// A mode's figures for one image size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlanFigures {
    pub dispatches: u32,
    /// Modelled bytes of global memory read and written per pixel.
    pub global_bytes_per_pixel: f64,
    /// The part of it that is the coarse-to-fine interface: records and
    /// neighbour values written by one pass and read by a later one (0 for
    /// the tile kernel, which keeps them in workgroup memory).
    pub interface_bytes_per_pixel: f64,
    /// The largest workgroup memory of the mode's kernels, in bytes.
    pub workgroup_bytes: u32,
    /// The most times a coarse effect's body runs per coarse sample (the block modes).
    pub sample_evaluations: Option<u32>,
    /// The tile kernel's samples evaluated per sample it owns (the block modes on a GPU).
    pub tile_overlap: Option<f64>,
}

impl PlanFigures {
    /// The figures of `mode` (one of `layout.plan`'s) for a `size` image.
    pub fn of(layout: &Layout, mode: &ModePlan, size: (u32, u32)) -> PlanFigures {
        let plan = &layout.plan;
        let pixels = f64::from(size.0) * f64::from(size.1);
        let mut dispatches = 0;
        let (mut bytes, mut interface) = (0.0, 0.0);
        let mut workgroup_bytes = 0;
        let mut tile = false;
        for pass in mode.steps.iter().filter_map(|s| match s {
            Step::Pass(p) => Some(p),
            _ => None,
        }) {
            dispatches += pass.dispatches.len() as u32;
            workgroup_bytes = workgroup_bytes.max(pass.workgroup_bytes);
            tile |= pass.kernel.kind == KernelKind::Tile;
            let over_samples = pass.dispatches.iter().all(|d| matches!(d.workgroups, Workgroups::SampleGrid { .. }));
            let positions = match (over_samples, pass.kernel.block) {
                (true, Some(block)) => {
                    let (x, y) = mrsl_abi::geometry::sample_grid(size, block);
                    f64::from(x) * f64::from(y)
                }
                _ => pixels,
            };
            bytes += positions * channel_bytes(layout);
            for binding in &pass.bindings {
                if statistics_only(binding.resource) {
                    continue;
                }
                let touched = resource_bytes(plan, binding.resource, binding.ty, size);
                bytes += touched;
                if is_interface(binding.resource) {
                    interface += touched;
                }
            }
        }
        let sample_evaluations =
            mode.mode.block_size().filter(|_| mode.mode != mrsl_abi::Mode::Dynamic).and_then(|_| {
                let count = |e: &mrsl_abi::EffectLayout| {
                    if tile { e.sample_evaluations } else { e.coarse_kernel_sample_evaluations }
                };
                layout.effects.iter().filter_map(count).max()
            });
        let tile_overlap = tile.then(|| {
            let t = layout.tile;
            f64::from(t.record_side().pow(2)) / f64::from(t.samples.pow(2))
        });
        PlanFigures {
            dispatches,
            global_bytes_per_pixel: bytes / pixels,
            interface_bytes_per_pixel: interface / pixels,
            workgroup_bytes,
            sample_evaluations,
            tile_overlap,
        }
    }
}

/// Bytes of one texel of every G-buffer channel.
fn channel_bytes(layout: &Layout) -> f64 {
    layout.channels.iter().map(|c| f64::from(c.format.texel_bytes())).sum()
}

/// Whether a resource carries coarse values from the pass that computes
/// them to a later one: the coarse-to-fine interface.
fn is_interface(id: ResourceId) -> bool {
    use ResourceId as R;
    matches!(
        id,
        R::Records { .. }
            | R::NeighbourValues { .. }
            | R::TaggedRecords { .. }
            | R::PixelRecords
            | R::PackedPixelRecords
            | R::RateRecords
            | R::LevelRecords { .. }
            | R::LevelValues
    )
}

/// What a timed run does not touch: the statistics and the refine mask.
fn statistics_only(id: ResourceId) -> bool {
    matches!(id, ResourceId::Statistics | ResourceId::RefineMask)
}

/// The bytes of resource `id` for a `size` image: a runtime-owned one from
/// its descriptor, an output (a storage texture the engine binds) from its format.
fn resource_bytes(plan: &Plan, id: ResourceId, ty: BindingType, size: (u32, u32)) -> f64 {
    let pixels = f64::from(size.0) * f64::from(size.1);
    match plan.resource(id).map(|d| d.shape) {
        Some(Shape::Buffer { elements, words }) => elements.count(size) as f64 * f64::from(words) * 4.0,
        Some(Shape::TextureArray { texels, layers, format }) => {
            texels.count(size) as f64 * f64::from(layers) * f64::from(format.texel_bytes())
        }
        Some(Shape::Texture { format }) => pixels * f64::from(format.texel_bytes()),
        None => match ty {
            BindingType::StorageTexture { format } => pixels * f64::from(format.texel_bytes()),
            // The shading-rate image: a texel per tile, a byte or a few.
            _ => 0.0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrsl_abi::{Device, Mode};

    /// The block modes on a GPU are one dispatch with no interface in global
    /// memory; on a CPU device the records go through global memory, written
    /// by the coarse pass and read by the fine pass: twice the record
    /// texture's bytes (two layers of 16-byte texels per 4x4 sample here).
    #[test]
    fn the_tile_kernel_keeps_the_interface_out_of_global_memory() {
        let source = "in float3 normal;\ncoarse effect float3 d {\n    d = normal;\n    if (d.x > 0.5) refine;\n}\n\
                      coarse effect float e = normal.z * 2.0;\nfine out float4 color = float4(d, e);\n";
        let program = mrsl::compile(source, &mrsl::Options::for_modes(&[Mode::Coarse4x4])).unwrap();
        let layout = &program.layout;
        let size = (64, 48);
        let gpu = PlanFigures::of(layout, layout.plan.mode_on(Mode::Coarse4x4, Device::Gpu).unwrap(), size);
        let cpu = PlanFigures::of(layout, layout.plan.mode_on(Mode::Coarse4x4, Device::Cpu).unwrap(), size);
        assert_eq!((gpu.dispatches, gpu.interface_bytes_per_pixel), (1, 0.0));
        assert!(gpu.workgroup_bytes > 0 && gpu.tile_overlap == Some(81.0 / 64.0), "{gpu:?}");
        assert_eq!(gpu.sample_evaluations, Some(1));
        assert_eq!(cpu.dispatches, 2);
        assert_eq!(layout.interface.stride_words, 5, "a flag word and four values");
        let (nx, ny) = mrsl_abi::geometry::sample_grid(size, 4);
        let records = f64::from(nx * ny) * 2.0 * 16.0;
        assert_eq!(cpu.interface_bytes_per_pixel, 2.0 * records / (64.0 * 48.0));
        // The G-buffer (one rgba32float channel) per pixel and per sample, the output, the records.
        let coarse = f64::from(nx * ny) * 16.0 / (64.0 * 48.0);
        assert_eq!(cpu.global_bytes_per_pixel, coarse + 16.0 + 16.0 + cpu.interface_bytes_per_pixel);
        assert_eq!(gpu.global_bytes_per_pixel, 16.0 + 16.0);
    }

    /// A neighbour value that refines runs once per sample in the tile
    /// kernel, which keeps its flag, and twice in the two-pass coarse
    /// kernel, whose neighbour pass stores values alone.
    #[test]
    fn evaluations_per_sample_are_the_plans_kernels() {
        let source = "in float3 normal;
coarse effect float a {
    a = normal.x;
    if (a > 0.5) refine;
}
                      coarse effect float b {
    b = a * 2.0;
    if (fwidth(a) > 0.1) refine;
}
                      fine out float4 color = float4(b);
";
        let program = mrsl::compile(source, &mrsl::Options::for_modes(&[Mode::Coarse2x2])).unwrap();
        let layout = &program.layout;
        let figures = |device| PlanFigures::of(layout, layout.plan.mode_on(Mode::Coarse2x2, device).unwrap(), (64, 48));
        assert_eq!(figures(Device::Gpu).sample_evaluations, Some(1));
        assert_eq!(figures(Device::Cpu).sample_evaluations, Some(2));
    }
}
