//! The pass plan: what every mode runs, as data a runtime interprets.
//!
//! For each mode a program was compiled for, [`ModePlan::steps`] lists the
//! commands to record, in order: buffers to clear, compute passes (a kernel,
//! the resources its stage group binds, and its dispatches with their
//! workgroup counts), and buffers to copy out for the statistics. Every
//! resource a step names is a [`ResourceId`]: either one the engine binds
//! (an output, the shading-rate image) or one the runtime owns, made once
//! per image size from its [`ResourceDesc`] in [`Plan::resources`]. A
//! runtime is one loop over the steps and a pool of resources keyed by id;
//! adding a mode is kernels plus a plan entry (plus its resources).
//!
//! The compiler writes the plan into the layout (`Layout::plan`), so the
//! files of `mrslc compile -o DIR` carry it; the Rust runtime and any other
//! runtime read it instead of restating which kernel runs when.

use crate::geometry::{self, Lattice};
use crate::{KernelRef, Mode, TextureFormat};
use serde::{Deserialize, Serialize};

/// Every mode's passes and the resources they use.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The modes the program was compiled for, in [`Mode::ALL`] order.
    pub modes: Vec<ModePlan>,
    /// Every runtime-owned resource a step names, each once.
    pub resources: Vec<ResourceDesc>,
    /// The numbers [`Workgroups`] and [`Extent`] are evaluated with, the
    /// limits sizes are checked against, and where indirect arguments bind:
    /// what a runtime in another language reads instead of restating
    /// [`geometry`].
    #[serde(default)]
    pub constants: PlanConstants,
}

/// The dispatch geometry's numbers ([`geometry`]) as the plan carries them.
/// The formulas that use them are the ones documented on [`Workgroups`],
/// [`Extent`], [`geometry::sample_grid`] and [`Lattice`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanConstants {
    /// Pixels per side of a [`Workgroups::Tiles`] workgroup ([`geometry::TILE`]).
    pub tile: u32,
    /// Invocations per side of a [`Workgroups::SampleGrid`] or
    /// [`Workgroups::Lattice`] workgroup ([`geometry::COARSE_WORKGROUP`]).
    pub coarse_workgroup: u32,
    /// Shading-rate tiles per side of a [`Workgroups::RateTiles`] workgroup
    /// ([`geometry::RATE_LIST_TILES`]).
    pub rate_list_tiles: u32,
    /// Shaded quads per [`Workgroups::CheckerboardQuads`] workgroup
    /// ([`geometry::CHECKERBOARD_QUADS_PER_WORKGROUP`]).
    pub checkerboard_quads_per_workgroup: u32,
    /// The lattices of hierarchical levels 1 to 4, whose points
    /// [`Extent::HierarchicalLevels`] counts ([`geometry::HIERARCHICAL_LEVELS`]).
    pub hierarchical_levels: Vec<LatticeDesc>,
    /// The largest image side ([`geometry::MAX_SIDE`]).
    pub max_side: u32,
    /// The largest storage binding in bytes ([`geometry::MAX_STORAGE_BINDING_BYTES`]).
    pub max_storage_binding_bytes: u64,
    /// The largest side of a texture ([`geometry::MAX_TEXTURE_SIDE`]).
    pub max_texture_side: u32,
    /// The most layers of a texture array ([`geometry::MAX_TEXTURE_LAYERS`]).
    pub max_texture_layers: u32,
    /// The most workgroups along one axis of a dispatch ([`MAX_WORKGROUPS_PER_DIMENSION`]).
    pub max_workgroups_per_dimension: u32,
    /// The bind group and binding of a [`Dispatch::arguments`] buffer
    /// ([`crate::GROUP_ARGS`], [`crate::BINDING_ARGS`]).
    pub arguments_group: u32,
    pub arguments_binding: u32,
    /// The refine-mask texel of a background pixel ([`crate::BACKGROUND_MARK`]).
    pub background_mark: [u32; 2],
}

/// A [`Lattice`] as data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LatticeDesc {
    pub start: u32,
    pub step: u32,
    pub odd_only: bool,
}

impl Default for PlanConstants {
    /// The numbers of this version of [`geometry`].
    fn default() -> PlanConstants {
        PlanConstants {
            tile: geometry::TILE,
            coarse_workgroup: geometry::COARSE_WORKGROUP,
            rate_list_tiles: geometry::RATE_LIST_TILES,
            checkerboard_quads_per_workgroup: geometry::CHECKERBOARD_QUADS_PER_WORKGROUP,
            hierarchical_levels: geometry::HIERARCHICAL_LEVELS
                .iter()
                .map(|l| LatticeDesc { start: l.start, step: l.step, odd_only: l.odd_only })
                .collect(),
            max_side: geometry::MAX_SIDE,
            max_storage_binding_bytes: geometry::MAX_STORAGE_BINDING_BYTES,
            max_texture_side: geometry::MAX_TEXTURE_SIDE,
            max_texture_layers: geometry::MAX_TEXTURE_LAYERS,
            max_workgroups_per_dimension: MAX_WORKGROUPS_PER_DIMENSION,
            arguments_group: crate::GROUP_ARGS,
            arguments_binding: crate::BINDING_ARGS,
            background_mark: crate::BACKGROUND_MARK,
        }
    }
}

impl Plan {
    /// The plan of `mode` on a GPU, if the program was compiled for it.
    pub fn mode(&self, mode: Mode) -> Option<&ModePlan> {
        self.mode_on(mode, Device::Gpu)
    }

    /// The plan of `mode` on `device`: the mode's plan for that kind of
    /// device, else its plan for every device.
    pub fn mode_on(&self, mode: Mode, device: Device) -> Option<&ModePlan> {
        let of_mode = || self.modes.iter().filter(move |m| m.mode == mode);
        of_mode().find(|m| m.device == Some(device)).or_else(|| of_mode().find(|m| m.device.is_none()))
    }

    /// The descriptor of a runtime-owned resource (`None` for engine-bound ones).
    pub fn resource(&self, id: ResourceId) -> Option<&ResourceDesc> {
        self.resources.iter().find(|r| r.id == id)
    }

    /// The most passes any mode records: timestamp slots a runtime reserves.
    pub fn most_passes(&self) -> usize {
        self.modes.iter().map(|m| m.passes().count()).max().unwrap_or(0)
    }
}

/// The kind of device a mode's plan is for ([`ModePlan::device`]).
///
/// A mode has one plan for every device unless measurement showed another
/// layout of its kernels faster on one kind: the block modes run one tile
/// kernel per frame on GPUs, and on CPU devices (lavapipe, SwiftShader),
/// which run every lane of a workgroup's masked-off code and pay for each
/// workgroup-memory word, their coarse and fine kernels
/// (docs/eval/evaluation.md, "One tile kernel"). Both give the same image and
/// statistics, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Device {
    Gpu,
    Cpu,
}

impl Device {
    pub const ALL: [Device; 2] = [Device::Gpu, Device::Cpu];

    /// The name in messages and on the command line (`gpu`, `cpu`).
    pub fn name(self) -> &'static str {
        match self {
            Device::Gpu => "gpu",
            Device::Cpu => "cpu",
        }
    }
}

/// What one mode records, and how its statistics are read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModePlan {
    pub mode: Mode,
    /// The kind of device this plan is for; `None`: every device
    /// ([`Plan::mode_on`] picks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<Device>,
    /// The kernels its passes use (those of [`Mode::kernels`]).
    pub kernels: Vec<KernelRef>,
    pub steps: Vec<Step>,
    pub counts: Counts,
}

impl ModePlan {
    /// The compute passes, in order.
    pub fn passes(&self) -> impl Iterator<Item = &Pass> {
        self.steps.iter().filter_map(|s| match s {
            Step::Pass(pass) => Some(pass),
            _ => None,
        })
    }

    /// Every resource the steps name, each once, in order of first mention.
    pub fn resources(&self) -> Vec<ResourceId> {
        let mut ids = vec![];
        let mut add = |id: ResourceId| {
            if !ids.contains(&id) {
                ids.push(id);
            }
        };
        for step in &self.steps {
            match step {
                Step::Clear { resource } | Step::Readback { resource, .. } => add(*resource),
                Step::Pass(pass) => {
                    pass.bindings.iter().for_each(|b| add(b.resource));
                    for d in &pass.dispatches {
                        if let Some(arguments) = d.arguments {
                            add(arguments);
                        }
                        if let Workgroups::Indirect { buffer, .. } = d.workgroups {
                            add(buffer);
                        }
                    }
                }
            }
        }
        ids
    }
}

/// One command of a mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "step", rename_all = "snake_case")]
pub enum Step {
    /// Zero a runtime-owned buffer.
    Clear { resource: ResourceId },
    /// A compute pass.
    Pass(Pass),
    /// Copy a runtime-owned buffer (its first `bytes`, or all of it) into
    /// its read-back buffer, for [`Counts`] to read after submission.
    Readback { resource: ResourceId, bytes: Option<u64> },
}

/// A compute pass: one kernel, its stage group, its dispatches in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pass {
    /// The pass's debug label.
    pub label: String,
    /// Which part of the frame the pass's timestamps count towards.
    pub stage: Stage,
    pub kernel: KernelRef,
    /// The stage group ([`crate::GROUP_STAGE`]): what each binding holds,
    /// in binding order. The same for every pass of the kernel.
    pub bindings: Vec<PassBinding>,
    pub dispatches: Vec<Dispatch>,
    /// Bytes of workgroup memory the kernel declares (its `var<workgroup>`
    /// variables, as WGSL lays them out): the device's
    /// `maxComputeWorkgroupStorageSize` must hold them.
    #[serde(default)]
    pub workgroup_bytes: u32,
}

/// One binding of a pass's stage group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PassBinding {
    pub binding: u32,
    pub resource: ResourceId,
    #[serde(rename = "type")]
    pub ty: BindingType,
}

/// One dispatch of an entry point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dispatch {
    pub entry: String,
    /// The buffer bound as [`crate::GROUP_ARGS`] (binding
    /// [`crate::BINDING_ARGS`]), which only this entry point writes: the
    /// indirect arguments of a later dispatch.
    pub arguments: Option<ResourceId>,
    pub workgroups: Workgroups,
}

/// Which part of the frame a pass's time counts towards (`Timings`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Coarse samples (the first level of a multi-level mode).
    Coarse,
    /// The dynamic mode's second (2x2) level.
    Coarse2x2,
    /// The per-pixel pass.
    Fine,
}

/// A resource a pass binds or a step names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(tag = "id", rename_all = "snake_case")]
pub enum ResourceId {
    /// The block modes' coarse-to-fine records over the sample grid of `block`.
    Records { block: u32 },
    /// The block coarse kernel's neighbour values over the sample grid of `block`.
    NeighbourValues { block: u32 },
    /// The dynamic mode's second level: tagged records over the sample grid of `block`.
    TaggedRecords { block: u32 },
    /// The hierarchical and checkerboard modes' record per pixel.
    PixelRecords,
    /// The hierarchical mode's record per pixel packed four words to a
    /// texel ([`crate::HierarchicalLayout::packed`]).
    PackedPixelRecords,
    /// The hierarchical work lists, levels 1 to 4 one after another.
    WorkLists,
    /// The hierarchical per-level counters (the first word of each level's four).
    LevelCounts,
    /// The hierarchical per-level indirect dispatch arguments.
    LevelArguments,
    /// The rate-image mode's record per pixel.
    RateRecords,
    /// The rate-image mode's list of samples to shade.
    SampleList,
    /// The rate-image mode's count of listed samples.
    SampleCount,
    /// The indirect dispatch arguments of the rate-image mode's sample shading.
    SampleArguments,
    /// The block and dynamic fine kernels' tile lists: a word per tile
    /// (`x | y << 16`), the surface tiles from the front, the background
    /// tiles from the back.
    TileLists,
    /// The lengths of the two tile lists (surface, background).
    TileCounts,
    /// The indirect dispatch arguments of the two tile lists.
    TileArguments,
    /// The statistics counters ([`crate::StatsLayout`]).
    Statistics,
    /// The per-pixel refine mask ([`crate::Layout::refine_mask`]).
    RefineMask,
    /// The multi-rate mode's records over the sample grid of `block`: its
    /// 4x4 level or its 2x2 level, each laid out as [`crate::LevelsLayout`] says.
    LevelRecords { block: u32 },
    /// The multi-rate mode's `coarse(4)` values resolved at every pixel
    /// ([`crate::LevelsLayout::values`]).
    LevelValues,
    /// Engine-bound: the rate-image mode's shading-rate image.
    ShadingRate,
    /// Engine-bound: output `index` of [`crate::Layout::outputs`].
    Output { index: usize },
}

impl ResourceId {
    /// Whether the engine binds it (else the runtime owns it).
    pub fn engine_bound(self) -> bool {
        matches!(self, ResourceId::ShadingRate | ResourceId::Output { .. })
    }
}

/// What a stage-group binding declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BindingType {
    /// A storage buffer of `u32` words (atomic for the statistics and counters).
    Buffer { read_only: bool },
    /// A write-only 2D storage texture (an output, or the refine mask).
    StorageTexture { format: TextureFormat },
    /// A sampled `texture_2d<u32>` read with `textureLoad` (the shading-rate image).
    UintTexture,
    /// The block modes' records as the fine kernels read them: a sampled
    /// `texture_2d_array<u32>` of format `rgba32uint`, read with `textureLoad`.
    RecordTexture,
    /// The same texture as the coarse kernel writes it: a write-only
    /// `texture_storage_2d_array<rgba32uint, write>`.
    RecordStorageTexture,
    /// A `texture_storage_2d_array<r32uint, read_write>` with a layer per
    /// word: the per-pixel records and the neighbour values.
    WordTexture,
    /// A `texture_storage_2d_array<rgba32uint, read_write>`, four words per
    /// texel: the hierarchical mode's packed records. Not in core WebGPU:
    /// the device needs read-write storage access to `rgba32uint` (wgpu's
    /// `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES` where the adapter has it,
    /// WebGPU's `texture-formats-tier2`).
    PackedWordTexture,
}

impl BindingType {
    /// Whether it counts towards a stage's storage-texture limit.
    pub fn is_storage_texture(self) -> bool {
        matches!(
            self,
            BindingType::StorageTexture { .. }
                | BindingType::RecordStorageTexture
                | BindingType::WordTexture
                | BindingType::PackedWordTexture
        )
    }
}

/// A runtime-owned resource: what it is called in errors and how it is sized.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResourceDesc {
    pub id: ResourceId,
    /// How an error names it ("the record texture").
    pub what: String,
    pub shape: Shape,
    /// Whether the runtime hands it to the engine to copy out (the refine mask).
    #[serde(default)]
    pub readable: bool,
}

/// How a runtime-owned resource is sized from the image size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Shape {
    /// A buffer of `words` 32-bit words per element of `elements` (at least
    /// one word in all). It must fit one storage binding
    /// ([`geometry::MAX_STORAGE_BINDING_BYTES`]).
    Buffer { elements: Extent, words: u32 },
    /// A 2D texture array of `layers` layers (at least one) over `texels`.
    /// It must fit WebGPU's default texture limits
    /// ([`geometry::MAX_TEXTURE_SIDE`], [`geometry::MAX_TEXTURE_LAYERS`]).
    TextureArray { texels: Extent, layers: u32, format: TextureFormat },
    /// A 2D texture of the image's size (which the image-size limit covers).
    Texture { format: TextureFormat },
}

/// A count derived from the image size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Extent {
    /// One per pixel, W x H.
    Pixels,
    /// One per coarse sample of block size `block` ([`geometry::sample_grid`]).
    SampleGrid { block: u32 },
    /// One per point of the hierarchical levels 1 to 4 ([`geometry::work_list_words`]).
    HierarchicalLevels,
    /// One per point of a lattice ([`Lattice::points`]); with `odd_only`,
    /// one per point whose coordinate sum is odd (half of them, rounded down).
    Lattice { start: u32, step: u32, odd_only: bool },
    /// A fixed number.
    Fixed { count: u64 },
}

impl Extent {
    /// The 2D grid of a `size` image, for the extents that are grids.
    pub fn grid(self, size: (u32, u32)) -> Option<(u32, u32)> {
        match self {
            Extent::Pixels => Some(size),
            Extent::SampleGrid { block } => Some(geometry::sample_grid(size, block)),
            Extent::HierarchicalLevels | Extent::Lattice { .. } | Extent::Fixed { .. } => None,
        }
    }

    /// How many there are for a `size` image.
    pub fn count(self, size: (u32, u32)) -> u64 {
        match self {
            Extent::HierarchicalLevels => geometry::work_list_words(size),
            Extent::Lattice { start, step, odd_only } => {
                let points = Lattice { start, step, odd_only }.points(size);
                if odd_only { points / 2 } else { points }
            }
            Extent::Fixed { count } => count,
            grid => {
                let (x, y) = grid.grid(size).expect("the other extents are grids");
                u64::from(x) * u64::from(y)
            }
        }
    }
}

/// Why a resource or dispatch of a mode cannot be made for an image size.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TooLarge(pub String);

impl Shape {
    /// Checks the shape against the limits the runtime relies on for a
    /// `size` image; the error says what it would need and which limit.
    pub fn check(&self, what: &str, size: (u32, u32)) -> Result<(), TooLarge> {
        match *self {
            Shape::Buffer { elements, words } => {
                let bytes = elements.count(size) * u64::from(words) * 4;
                if bytes > geometry::MAX_STORAGE_BINDING_BYTES {
                    let limit = geometry::MAX_STORAGE_BINDING_BYTES >> 20;
                    return Err(TooLarge(format!(
                        "{what} would need {} MiB, more than a {limit} MiB storage binding",
                        bytes >> 20
                    )));
                }
            }
            Shape::TextureArray { texels, layers, .. } => {
                let (w, h) = texels.grid(size).unwrap_or((1, 1));
                let (side, most) = (geometry::MAX_TEXTURE_SIDE, geometry::MAX_TEXTURE_LAYERS);
                if w.max(h) > side || layers > most {
                    return Err(TooLarge(format!(
                        "{what} would need {w}x{h} texels and {layers} layers, more than \
                         {side}x{side} texels and {most} layers"
                    )));
                }
            }
            Shape::Texture { .. } => {}
        }
        Ok(())
    }

    /// Bytes of the buffer for a `size` image (at least 4), for buffers.
    pub fn buffer_bytes(&self, size: (u32, u32)) -> Option<u64> {
        match *self {
            Shape::Buffer { elements, words } => Some((elements.count(size) * u64::from(words) * 4).max(4)),
            _ => None,
        }
    }
}

/// What the dispatch of a runtime may depend on besides the plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DispatchContext {
    pub size: (u32, u32),
    /// Refinement is forced (the checkerboard shades every quad).
    pub forced: bool,
    /// The rate-image mode's tile size.
    pub rate_tile: u32,
}

/// How many workgroups a dispatch runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Workgroups {
    /// One per [`geometry::TILE`]² tile of pixels ([`geometry::pixel_workgroups`]).
    Tiles,
    /// One per `side` x `side` pixels ([`geometry::tile_workgroups`]): the tile kernel.
    PixelTiles { side: u32 },
    /// One per [`geometry::COARSE_WORKGROUP`]² coarse samples of `block`
    /// ([`geometry::coarse_workgroups`]).
    SampleGrid { block: u32 },
    /// Over a lattice of pixels ([`Lattice::workgroups`]); with `odd_only`,
    /// over the half of its points with an odd coordinate sum.
    Lattice {
        start: u32,
        step: u32,
        #[serde(default)]
        odd_only: bool,
    },
    /// A single workgroup.
    One,
    /// One per [`geometry::RATE_LIST_TILES`]² shading-rate tiles
    /// ([`geometry::rate_list_workgroups`]).
    RateTiles,
    /// Rows of checkerboard quads ([`geometry::checkerboard_workgroups`]).
    CheckerboardQuads,
    /// Read from `buffer` at byte `offset`, written by an earlier dispatch
    /// of the pass. `at_most` bounds the invocations it can ask for, in
    /// workgroups of `per_workgroup`: each axis of a dispatch may have at
    /// most 65535 workgroups, which the runtime checks before recording.
    Indirect { buffer: ResourceId, offset: u64, at_most: Option<Extent>, per_workgroup: u32 },
}

/// The most workgroups along one axis of a dispatch (WebGPU's default
/// `maxComputeWorkgroupsPerDimension`).
pub const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65535;

impl Workgroups {
    /// The workgroups of a direct dispatch (`None` for an indirect one).
    pub fn direct(self, context: DispatchContext) -> Option<(u32, u32)> {
        let size = context.size;
        Some(match self {
            Workgroups::Tiles => geometry::pixel_workgroups(size),
            Workgroups::PixelTiles { side } => geometry::tile_workgroups(size, side),
            Workgroups::SampleGrid { block } => geometry::coarse_workgroups(size, block),
            Workgroups::Lattice { start, step, odd_only } => Lattice { start, step, odd_only }.workgroups(size),
            Workgroups::One => (1, 1),
            Workgroups::RateTiles => geometry::rate_list_workgroups(size, context.rate_tile),
            Workgroups::CheckerboardQuads => geometry::checkerboard_workgroups(size, context.forced),
            Workgroups::Indirect { .. } => return None,
        })
    }
}

/// How a mode's statistics are read from its counters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    /// The coarse samples the mode shades.
    pub samples: SampleCount,
    /// What a coarse effect's evaluations are.
    pub evaluations: Evaluations,
    /// Per-level work-list lengths, if the mode has work lists.
    pub work_lists: Option<WorkListCounts>,
    /// With a background rule: the statistics counters of the background
    /// pixels and of the background coarse samples (where the mode has samples).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<BackgroundCounts>,
}

/// The statistics counters that count what the background rule skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct BackgroundCounts {
    pub pixels: usize,
    pub samples: Option<usize>,
}

/// Where the number of shaded coarse samples comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SampleCount {
    /// No coarse samples (per-pixel modes).
    None,
    /// The sample grid of `block`, plus the statistics counter `counter`
    /// (the dynamic mode's shaded 2x2 samples) when given.
    Grid { block: u32, counter: Option<usize> },
    /// Word `word` of `resource`'s read-back (the rate-image mode's listed samples).
    Listed { resource: ResourceId, word: usize },
    /// Each coarse effect's own sample grid, of the block size
    /// [`crate::LevelsLayout::block`] gives it (the multi-rate mode).
    Levels,
}

/// What a live coarse effect's evaluations are in a mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Evaluations {
    /// Every effect is evaluated at every pixel (the reference).
    EveryPixel,
    /// The pixels its statistics counter counted (the per-pixel adaptive modes).
    Counted,
    /// One per coarse sample, plus the pixels its counter counted.
    SamplesAndCounted,
}

/// The lengths of a mode's work lists: word `words_per_level * level` of
/// `resource`'s read-back for each level in `levels`, dispatched in
/// workgroups of `lanes` invocations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkListCounts {
    pub resource: ResourceId,
    pub words_per_level: u32,
    pub levels: Vec<u32>,
    pub lanes: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extents_count_what_the_geometry_does() {
        let size = (37, 21);
        assert_eq!(Extent::Pixels.count(size), 37 * 21);
        let (nx, ny) = geometry::sample_grid(size, 4);
        assert_eq!(Extent::SampleGrid { block: 4 }.count(size), u64::from(nx * ny));
        assert_eq!(Extent::HierarchicalLevels.count(size), geometry::work_list_words(size));
        assert_eq!(Extent::Fixed { count: 20 }.count(size), 20);
        assert_eq!(Extent::SampleGrid { block: 1 }.grid(size), Some(size));
    }

    /// The constants travel with the plan under their own names, and a plan
    /// written without them reads as this version's.
    #[test]
    fn the_plan_carries_the_geometry_constants() {
        let plan = Plan { modes: vec![], resources: vec![], constants: PlanConstants::default() };
        let json = serde_json::to_value(&plan).unwrap();
        assert_eq!(json["constants"]["tile"], geometry::TILE);
        assert_eq!(json["constants"]["hierarchical_levels"][1]["odd_only"], true);
        assert_eq!(json["constants"]["arguments_group"], crate::GROUP_ARGS);
        let old: Plan = serde_json::from_str(r#"{"modes": [], "resources": []}"#).unwrap();
        assert_eq!(old, plan);
    }

    #[test]
    fn shapes_past_the_limits_say_what_they_would_need() {
        let array = Shape::TextureArray {
            texels: Extent::SampleGrid { block: 2 },
            layers: 3,
            format: TextureFormat::Rgba32Uint,
        };
        let TooLarge(reason) = array.check("the record texture", (16384, 8)).unwrap_err();
        assert!(reason.contains("the record texture") && reason.contains("8193x5"), "{reason}");
        array.check("the record texture", (1920, 1080)).unwrap();
        let buffer = Shape::Buffer { elements: Extent::Pixels, words: 40 };
        assert!(buffer.check("the records", (4096, 4096)).unwrap_err().0.contains("MiB"));
        assert_eq!(buffer.buffer_bytes((2, 2)), Some(640));
        assert_eq!(Shape::Buffer { elements: Extent::Pixels, words: 0 }.buffer_bytes((2, 2)), Some(4));
    }
}
