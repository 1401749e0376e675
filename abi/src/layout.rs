//! The binding layout and interface description of a compiled program.
//!
//! Engines and the runtime build their bind group layouts, buffers and
//! dispatches from this description; nothing about the generated code has
//! to be guessed. It is written as JSON (`STEM.layout.json`) and read back
//! into the same value ([`Layout::from_json`]).

use crate::Plan;
use crate::types::{SampleType, TextureFormat, ValueType};
use serde::{Deserialize, Serialize};

/// The layout format this crate reads and writes (the `format` field).
pub const LAYOUT_FORMAT: &str = "mrsl-layout/8";

/// The refine mask's texel at a background pixel (x: no effect evaluated per
/// pixel, y: all ones). A shaded pixel holds it only in a program with at
/// least 32 coarse effects that took every one of them from the dynamic
/// mode's 2x2 level; the statistics' background count is exact regardless.
pub const BACKGROUND_MARK: [u32; 2] = [0, u32::MAX];

/// One texel of the refine mask decoded by effect name
/// ([`Layout::decode_refine_mask`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RefineMaskTexel<'a> {
    /// A background pixel: no coarse effect was evaluated, refined or
    /// resampled there. (In a program of 32 or more coarse effects, a shaded
    /// pixel that took all of them from the 2x2 level holds the same texel;
    /// see [`BACKGROUND_MARK`].)
    Background,
    /// A shaded pixel: the coarse effects it evaluated itself (`.x`: per
    /// pixel, shaded at that pixel in the hierarchical mode, in a shaded quad
    /// or in place in the checkerboard mode) and those it took from the
    /// dynamic mode's 2x2 level (`.y`), each in declaration order. A coarse
    /// effect in neither was resampled from coarse samples.
    Shaded { per_pixel: Vec<&'a str>, from_2x2: Vec<&'a str> },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Layout {
    /// The format version, [`LAYOUT_FORMAT`].
    pub format: String,
    pub control: ControlBlock,
    pub uniforms: Option<UniformBlock>,
    pub textures: Vec<ResourceBinding>,
    pub samplers: Vec<ResourceBinding>,
    pub channels: Vec<Channel>,
    pub interface: InterfaceLayout,
    pub outputs: Vec<Output>,
    pub stats: StatsLayout,
    /// The per-pixel kernels' refine mask (`rg32uint`: x bit k = coarse effect k
    /// (stats counter k) evaluated per pixel; y bit k = taken from the dynamic mode's 2x2 level).
    /// A background pixel holds [`BACKGROUND_MARK`].
    pub refine_mask: ResourceBinding,
    /// The dynamic mode's second (2x2) level of coarse samples: records of
    /// `interface.stride_words + 1` words, the last being a validity tag.
    pub interface2: ResourceBinding,
    /// The hierarchical (DACS) and checkerboard modes' buffers. The block
    /// and dynamic fine kernels' tile lists and their counts (with a
    /// background rule) take the binding numbers of its `work_binding` and
    /// `queue_binding` (the plan says which resource each binds).
    pub hierarchical: HierarchicalLayout,
    /// The rate-image mode's shading-rate image (`texture_2d<u32>`, one texel
    /// per tile, codes of [`crate::ShadingRate`]), read by both its kernels.
    /// Its coarse kernel's sample list and count take the binding numbers of
    /// the hierarchical mode's `work_binding` and `queue_binding` (the plan
    /// says which resource each binds).
    pub shading_rate: ResourceBinding,
    /// The block coarse kernel's neighbour values (its `coarse_neighbours`
    /// entry point writes them, `coarse_main` reads them).
    pub neighbours: NeighbourLayout,
    /// The block modes' tile kernel: its tile and what it holds in workgroup memory.
    pub tile: TileLayout,
    pub effects: Vec<EffectLayout>,
    /// The multi-rate mode's levels, when the program was compiled for it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub levels: Option<LevelsLayout>,
    /// What every mode the program was compiled for runs ([`Plan`]).
    pub plan: Plan,
}

impl Layout {
    /// The most storage textures one kernel's pipeline binds in its compute
    /// stage: the channels read through storage bindings (group 1, in every
    /// kernel's pipeline) and the storage textures of its stage group. A
    /// device whose `maxStorageTexturesPerShaderStage` is lower refuses that
    /// kernel (WebGPU's default is 4).
    pub fn storage_textures_per_stage(&self) -> u32 {
        let channels = self.channels.iter().filter(|c| c.access == ChannelAccess::Storage).count() as u32;
        let stage = self
            .plan
            .modes
            .iter()
            .flat_map(|m| m.passes())
            .map(|p| p.bindings.iter().filter(|b| b.ty.is_storage_texture()).count() as u32);
        channels + stage.max().unwrap_or(0)
    }

    /// Parses a layout written by [`Layout::to_json`] (or `mrslc compile`),
    /// rejecting another format version.
    pub fn from_json(text: &str) -> Result<Layout, String> {
        #[derive(Deserialize)]
        struct Version {
            format: Option<String>,
        }
        let version: Version = serde_json::from_str(text).map_err(|e| e.to_string())?;
        match version.format.as_deref() {
            Some(LAYOUT_FORMAT) => serde_json::from_str(text).map_err(|e| e.to_string()),
            Some(other) => Err(format!("layout format `{other}` is not supported (expected `{LAYOUT_FORMAT}`)")),
            None => Err(format!("no `format` field (expected `{LAYOUT_FORMAT}`)")),
        }
    }

    /// The refine-mask bit of coarse effect `effect`, the same in the
    /// texel's `.x` (evaluated per pixel) and `.y` (taken from the dynamic
    /// mode's 2x2 level): its index in `stats.counters`, which follows the
    /// effects' dependency order rather than their declaration order (that
    /// of `Stats::effects`). `None` for a name that is not a live coarse
    /// effect, or one past the mask's 32 bits.
    pub fn refine_mask_bit(&self, effect: &str) -> Option<u32> {
        let bit = self.stats.counters.iter().position(|c| c == effect)?;
        u32::try_from(bit).ok().filter(|&b| b < 32)
    }

    /// Decodes one texel of the refine mask (the `rg32uint` texture
    /// `Shader::refine_mask` returns) into effect names, in declaration
    /// order (the order of `Layout::effects` and of `Stats::effects`).
    /// [`BACKGROUND_MARK`] decodes as [`RefineMaskTexel::Background`].
    pub fn decode_refine_mask(&self, texel: [u32; 2]) -> RefineMaskTexel<'_> {
        if texel == BACKGROUND_MARK {
            return RefineMaskTexel::Background;
        }
        let set = |word: u32| -> Vec<&str> {
            self.effects
                .iter()
                .filter(|e| self.refine_mask_bit(&e.name).is_some_and(|bit| word >> bit & 1 == 1))
                .map(|e| e.name.as_str())
                .collect()
        };
        RefineMaskTexel::Shaded { per_pixel: set(texel[0]), from_2x2: set(texel[1]) }
    }

    /// The layout as pretty-printed JSON, as `mrslc compile` writes it.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a layout always serialises")
    }

    /// Number of statistics counters: one per coarse effect, the dynamic
    /// mode's count of shaded 2x2 samples, and with a background rule the
    /// background pixels and the background coarse samples.
    pub fn stats_counters(&self) -> usize {
        self.stats.counters.len() + if self.has_background() { 3 } else { 1 }
    }

    /// Whether a channel has a background rule ([`Background`]).
    pub fn has_background(&self) -> bool {
        self.channels.iter().any(|c| c.background.is_some())
    }

    /// The statistics counter of the background pixels, and of the
    /// background coarse samples, with a background rule.
    pub fn background_counters(&self) -> Option<(usize, usize)> {
        let k = self.stats.counters.len();
        self.has_background().then_some((k + 1, k + 2))
    }
}

/// Resources of the hierarchical and checkerboard modes (group 2): a record
/// per pixel, and (hierarchical only) the work lists of pixels to shade per
/// level and per-level counters that double as indirect dispatch arguments.
/// The records are an `r32uint` texture array, read and written in place:
/// word k of pixel (x, y)'s record is texel (x, y) of layer k. (A texture
/// rather than a storage buffer for the reason [`InterfaceLayout`] gives:
/// llvmpipe reads and writes it for all lanes at once, a buffer word lane
/// by lane.) With `packed`, the hierarchical kernel's records are an
/// `rgba32uint` array instead, four words per texel: word k is component
/// k % 4 of layer k / 4 (the checkerboard kernel's stay as above).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HierarchicalLayout {
    /// Per pixel: `flag_words` refine flags, `mask_words` "evaluated here" bits
    /// (bit k = coarse effect k), then every live coarse effect's value; one
    /// layer of the record texture per word.
    pub values_binding: u32,
    pub record_words: u32,
    pub flag_words: u32,
    pub mask_words: u32,
    /// Word offset of each live coarse effect's value in a record, in stats-counter order.
    pub value_offsets: Vec<u32>,
    /// Whether the hierarchical kernel packs its records four words to a
    /// texel (`ResourceId::PackedPixelRecords`, bound as a
    /// `BindingType::PackedWordTexture`), which needs read-write storage
    /// access to `rgba32uint` on the device. Left out of the JSON when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub packed: bool,
    /// `array<u32>`: pixel indices to shade, level 1 to 4 one after another;
    /// with a background rule, the tile list at the back of level 4's
    /// (`geometry::tile_list_offset`).
    pub work_binding: u32,
    /// `array<atomic<u32>>` of 4 words per level (index 0..4): the first counts queued
    /// pixels; level 0's first two count the surface and background tiles
    /// (`geometry::HIERARCHICAL_TILE_COUNTS`).
    pub queue_binding: u32,
    /// Indirect dispatch arguments (x, y, z, unused) per level (index 0..4), then of
    /// the dispatches over the tile lists (`geometry::HIERARCHICAL_ARGUMENT_WORDS`),
    /// written by the `hier_args_*` and `hier_tile_args` entry points only: bind group
    /// `args_group`, binding 0. It is a separate group because a buffer cannot be
    /// indirect and writable in one dispatch.
    pub args_group: u32,
}

/// The coarse effects that the block coarse kernel's derivatives read at
/// neighbouring samples, stored once per sample by a first entry point,
/// `coarse_neighbours`, so that `coarse_main` reads a neighbour's value
/// instead of evaluating the effect there again (at each of the two
/// neighbours of every derivative). An `r32uint` texture array of `nx` x
/// `ny` texels (the sample grid) and `words` layers, bound at `binding` of
/// the stage group; effect `name`'s value starts at layer `offset`. `words`
/// is 0 (no binding, and no dispatch of `coarse_neighbours`) when no
/// derivative reads an effect, or when evaluating those effects for their
/// values would itself read effects at neighbours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NeighbourLayout {
    pub binding: u32,
    pub words: u32,
    pub effects: Vec<NeighbourValue>,
}

/// The block modes' tile kernel ([`crate::KernelKind::Tile`]): a workgroup
/// shades one tile of `samples` x `samples` blocks. It evaluates, into
/// workgroup memory, the records of the tile's samples and of the next
/// tile's first row and column (whose samples the tile's last blocks
/// resample from), and of `ring` samples before the tile on each axis
/// (where a per-pixel derivative can read a pixel of the previous tile);
/// and before them the neighbour values ([`NeighbourLayout`]) of one more
/// sample on every side, which the samples' derivatives read. Nothing of the
/// interface goes through global memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TileLayout {
    /// Coarse samples per side of a tile: the tile is `samples * B` pixels wide.
    pub samples: u32,
    /// 1 where the records of the samples just before the tile are held too, else 0.
    pub ring: u32,
}

impl TileLayout {
    /// Samples per side whose records the workgroup holds: `ring + samples + 1`.
    pub fn record_side(self) -> u32 {
        self.ring + self.samples + 1
    }

    /// Samples per side whose neighbour values the workgroup holds: one more on each side.
    pub fn neighbour_side(self) -> u32 {
        self.record_side() + 2
    }

    /// The tile's side in pixels for block size `block`.
    pub fn side(self, block: u32) -> u32 {
        self.samples * block
    }
}

/// Where one effect's value sits in the neighbour values ([`NeighbourLayout`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NeighbourValue {
    pub name: String,
    pub offset: u32,
    /// In the tile kernel, the step of its neighbour phase (a barrier
    /// between steps) that evaluates this effect, at every sample the
    /// workgroup holds: for its value, and at the tile's samples for its
    /// refine flag too when it refines. A flag whose predicate takes a
    /// derivative of another neighbour value needs that value at the
    /// neighbouring samples first: its step is one past that value's.
    /// The two-pass coarse kernel evaluates every value in one pass.
    #[serde(default)]
    pub wave: u32,
}

/// Counters the fine kernels accumulate (when the program has live coarse effects).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StatsLayout {
    pub group: u32,
    pub binding: u32,
    /// Counter `k` counts the pixels that re-evaluated this coarse effect;
    /// one more counter after them counts the 2x2 samples the dynamic mode shaded.
    pub counters: Vec<String>,
}

/// The runtime-owned uniform block every kernel reads (see [`crate::Control`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControlBlock {
    pub group: u32,
    pub binding: u32,
    pub size: u32,
    pub fields: Vec<Field>,
}

/// A field of a uniform block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Field {
    pub name: String,
    /// mrsl type (`float3`); `bool` fields are stored as `uint`.
    #[serde(rename = "type")]
    pub ty: ValueType,
    /// The WGSL type of the stored value (`vec3<f32>`; `u32` for `bool`).
    pub wgsl_type: String,
    pub offset: u32,
    pub size: u32,
    /// Default value, components in order (columns for matrices), if any.
    pub default: Option<Vec<f64>>,
}

/// The user uniform block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UniformBlock {
    pub group: u32,
    pub binding: u32,
    /// Size in bytes (a multiple of 16).
    pub size: u32,
    pub fields: Vec<Field>,
}

/// What a [`ResourceBinding`] binds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ResourceKind {
    /// A filterable float `texture_2d<f32>`.
    #[serde(rename = "float")]
    Texture,
    /// A filtering sampler.
    #[serde(rename = "filtering")]
    Sampler,
    /// An `rg32uint` write-only storage texture (the refine mask).
    #[serde(rename = "rg32uint")]
    RefineMask,
    /// A read-write storage buffer.
    #[serde(rename = "storage")]
    Storage,
    /// A `texture_2d<u32>` of shading-rate codes.
    #[serde(rename = "shading_rate")]
    ShadingRate,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResourceBinding {
    pub name: String,
    pub group: u32,
    pub binding: u32,
    pub kind: ResourceKind,
}

/// A G-buffer channel (`in` declaration).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    pub name: String,
    #[serde(rename = "type")]
    pub ty: ValueType,
    pub group: u32,
    pub binding: u32,
    /// The texture format the tools create for it. The runtime also accepts
    /// other colour formats of the same sample type: at least the type's
    /// components for one or two, exactly 4 for three or four
    /// (docs/runtime.md, section 4).
    pub format: TextureFormat,
    /// The sample type of the binding.
    pub sample_type: SampleType,
    /// Discontinuity key comparison, if this channel is a key.
    pub key: Option<KeyCompare>,
    /// Which of the channel's values mark background pixels (where nothing
    /// was drawn), if the channel says (absent from the JSON otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<Background>,
    /// How the kernels decode the channel from what the engine stores, if
    /// it is not stored as its type (absent from the JSON otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decode: Option<Decode>,
    /// How the kernels bind the channel's texture (absent from the JSON when
    /// sampled, the default).
    #[serde(default, skip_serializing_if = "ChannelAccess::is_sampled")]
    pub access: ChannelAccess,
}

/// How the kernels bind a G-buffer channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelAccess {
    /// A sampled texture (`texture_2d<T>` or `texture_depth_2d`) read with
    /// `textureLoad`: any format of the channel's sample type with enough
    /// components, `TEXTURE_BINDING`.
    #[default]
    Sampled,
    /// A read-only storage texture (`texture_storage_2d<FORMAT, read>`):
    /// exactly the channel's format, `STORAGE_BINDING`, and one storage
    /// texture more per shader stage in every kernel's pipeline. llvmpipe
    /// (lavapipe) reads a storage texel for about a third of what a sampled
    /// one costs, through its sampler code.
    Storage,
}

impl ChannelAccess {
    pub fn is_sampled(&self) -> bool {
        *self == ChannelAccess::Sampled
    }
}

/// How a channel is computed from an engine's encoding of it (`@depth`,
/// `@encoded`; docs/language.md). Every kernel decodes it the same way, in
/// the channel's one loader, so forced refinement still equals the reference.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Decode {
    /// A `float3` position rebuilt from a depth texture (WebGPU's clip
    /// space: depth 0 to 1, y up) and the `float4x4` uniform
    /// `inverse_view_projection` names: the world position of the pixel's
    /// centre at its depth.
    Depth { inverse_view_projection: String },
    /// Stored as unorm (0 to 1), read as `2 v - 1` (normals in `Rgb10a2Unorm`
    /// or `Rgba8Unorm`).
    Unorm,
    /// A unit `float3` stored as two octahedral components in -1 to 1
    /// (`Rg16Float`, `Rg16Snorm`, `Rg8Snorm`, ...).
    Octahedral,
    /// The same, the components stored as unorm (0 to 1; `Rg16Unorm`, `Rg8Unorm`).
    OctahedralUnorm,
    /// One field of Bevy's deferred G-buffer (`Rgba32Uint`, as Bevy 0.19's
    /// `pbr_deferred_functions.wgsl` packs it); every such channel binds
    /// the same texture.
    BevyDeferred { field: BevyField },
}

/// The fields of Bevy's deferred G-buffer texel: x the base colour (stored
/// with a 1/2.2 gamma) and perceptual roughness as unorm4x8, y the emissive
/// colour as rgb9e5, z reflectance, metallic and occlusion as unorm4x8, w a
/// 24-bit octahedral normal (two 12-bit unorm halves) and 8 flag bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BevyField {
    BaseColor,
    PerceptualRoughness,
    Emissive,
    Reflectance,
    Metallic,
    Occlusion,
    Normal,
    Flags,
}

impl BevyField {
    /// Every field, as `@packed(bevy_deferred, ..)` names it, with its type.
    pub const ALL: [(BevyField, &'static str, &'static str); 8] = [
        (BevyField::BaseColor, "base_color", "float3"),
        (BevyField::PerceptualRoughness, "perceptual_roughness", "float"),
        (BevyField::Emissive, "emissive", "float3"),
        (BevyField::Reflectance, "reflectance", "float"),
        (BevyField::Metallic, "metallic", "float"),
        (BevyField::Occlusion, "occlusion", "float"),
        (BevyField::Normal, "normal", "float3"),
        (BevyField::Flags, "flags", "uint"),
    ];
}

impl Decode {
    /// The components the engine's texture must hold for a channel of type `ty`.
    pub fn stored_components(&self, ty: &ValueType) -> u32 {
        match self {
            Decode::Depth { .. } => 1,
            Decode::Octahedral | Decode::OctahedralUnorm => 2,
            Decode::Unorm => ty.components(),
            Decode::BevyDeferred { .. } => 4,
        }
    }
}

/// How a discontinuity-key channel is compared between samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum KeyCompare {
    /// Any difference is a discontinuity.
    Exact,
    /// `distance(a, b) > threshold` is a discontinuity.
    Threshold { threshold: f64 },
    /// A position key compared against the surface: a discontinuity where
    /// the offset between the two samples leaves either one's tangent plane
    /// (the plane through it across its `normal` channel) by more than
    /// `threshold` of the offset's length, `|dot(b - a, n)| > threshold *
    /// |b - a|`. A ratio, so it means the same at any scale.
    Surface { normal: String, threshold: f64 },
}

/// The background rule of a channel: the pixels where its value equals
/// `value` (`@background(value)`), or differs from it (`@foreground(value)`),
/// are background. There, every coarse effect reads as the zero of its
/// type, in every kernel; coarse effects are neither evaluated nor refined
/// nor resampled from there; fine effects and outputs are evaluated as
/// everywhere.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Background {
    Equal { value: f64 },
    NotEqual { value: f64 },
}

/// The coarse-to-fine interface of the block modes: a record per coarse
/// sample. The block modes (and the dynamic mode's 4x4 level) keep the
/// records in an `rgba32uint` texture array of `nx` x `ny` texels (the
/// sample grid, [`InterfaceLayout::samples`]) and [`InterfaceLayout::layers`]
/// layers: word `w` of sample `(i, j)` is component `w % 4` of texel `(i, j)`
/// of layer `w / 4`. (A texture and not a storage buffer: llvmpipe loads a
/// storage-buffer word lane by lane behind a branch, a texel for all lanes
/// at once, about 6x cheaper for the fine kernels' corner loads.) The
/// rate-image mode keeps one record per pixel in a storage buffer of
/// `stride_words` words per record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InterfaceLayout {
    pub group: u32,
    pub binding: u32,
    /// 32-bit words per coarse sample record.
    pub stride_words: u32,
    /// Leading words of refine flags in each record.
    pub flag_words: u32,
    pub slots: Vec<SlotLayout>,
    /// Whether the slot allocation is proven minimal.
    pub minimal: bool,
    /// How many coarse samples there are for a `W`x`H` image and block size `B`
    /// ([`crate::geometry::SAMPLE_GRID_RULE`]).
    pub samples: String,
}

impl InterfaceLayout {
    /// Words per texel of the record texture.
    pub const WORDS_PER_TEXEL: u32 = 4;

    /// Layers of the record texture: the record's words, four per texel (at least one).
    pub fn layers(&self) -> u32 {
        self.stride_words.div_ceil(Self::WORDS_PER_TEXEL).max(1)
    }
}

/// The multi-rate mode's boundaries. The 4x4 samples shade the `coarse(4)`
/// effects and keep `outer`'s records; the `multi_resolve` pass resolves
/// at every pixel the `coarse(4)` effects that cross the 4x4 boundary (read
/// by a `coarse(2)`, plain `coarse` or fine effect) into `values`; the 2x2
/// samples shade the other coarse effects, reading those values at their
/// pixels, and keep `inner`'s records, which the pixels resample. Each
/// record is allocated as the block modes' is, over the effects of its
/// level, and minimal when its `minimal` says so.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevelsLayout {
    /// The 4x4 level's records (`coarse(4)` effects: the 4x4 to 1x1 boundary).
    pub outer: InterfaceLayout,
    /// The `coarse(4)` values per pixel (the 4x4 to 2x2 boundary and the
    /// values read per pixel): an `r32uint` texture array over the pixels
    /// with `words` layers, a layer per word.
    pub values: NeighbourLayout,
    /// The 2x2 level's records (`coarse(2)` and plain `coarse` effects: the 2x2 to 1x1 boundary).
    pub inner: InterfaceLayout,
    /// Each effect's level, in the order of [`Layout::effects`]: 4 or 2
    /// for a coarse effect, 1 for a fine effect or output.
    pub block: Vec<u32>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SlotLayout {
    pub offset: u32,
    pub size: u32,
    pub effects: Vec<String>,
}

/// An output (`fine out` declaration): a storage texture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Output {
    pub name: String,
    #[serde(rename = "type")]
    pub ty: ValueType,
    pub format: TextureFormat,
    pub group: u32,
    pub binding: u32,
}

/// The rate of an effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Rate {
    /// `coarse effect`: once per coarse sample, resampled or refined.
    Coarse,
    /// `fine effect`: once per pixel.
    Fine,
    /// `fine out`: once per pixel, written to an output target.
    Out,
}

/// How a coarse effect's value is reconstructed at a pixel from coarse samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Resample {
    Nearest,
    Bilinear,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EffectLayout {
    pub name: String,
    pub rate: Rate,
    #[serde(rename = "type")]
    pub ty: ValueType,
    /// Computed at all (reaches an output).
    pub live: bool,
    pub refine_bit: Option<u32>,
    pub slot: Option<usize>,
    pub resample: Option<Resample>,
    pub depends_on: Vec<String>,
    /// For a live coarse effect, the discontinuity keys whose discontinuities
    /// refine it: the key channels it reads, directly or through the effects
    /// it reads (empty otherwise).
    pub keys: Vec<String>,
    /// When the effect is passed, as a formula over refine flags `r_X`.
    pub pass_condition: Option<String>,
    /// The compiler's cost model for a live effect: the operations one
    /// evaluation executes (expression nodes and statements, inlined calls
    /// and derivative neighbour evaluations included, loop bodies times their
    /// static trip counts, texture reads weighted 4). Times the evaluations
    /// a mode makes, a platform-independent measure of shading work.
    pub operations: Option<u64>,
    /// The same model for an evaluation of the value alone, without the
    /// statements that only decide the refine flag: what the per-pixel
    /// kernels (reference, fine, final passes) execute, since refinement is
    /// decided before they run. Equal to `operations` for an effect that
    /// cannot refine.
    #[serde(default)]
    pub value_operations: Option<u64>,
    /// For a live coarse effect: how many times the block modes' tile kernel
    /// (their plan on a GPU) evaluates its body per coarse sample: 1 where
    /// every derivative at a sample reads the neighbour values (a neighbour
    /// value that refines keeps its flag beside its value, [`NeighbourValue::wave`]);
    /// more for an effect that is not a neighbour value but is read by one
    /// (evaluated for it, then again at the sample), for each position of a
    /// derivative whose operand is taken by running the body's statements
    /// before it there (a local built by a loop), or where derivatives
    /// evaluate effects at the neighbouring samples in place
    /// (`neighbours.words` 0). The tile kernel evaluates each of the samples
    /// its workgroup holds ([`TileLayout`]) this often.
    #[serde(default)]
    pub sample_evaluations: Option<u32>,
    /// The same count for the two-pass coarse kernel (the block modes' plan
    /// on a CPU), whose neighbour pass stores values alone: a neighbour
    /// value that refines is evaluated again at the sample for its flag (2).
    #[serde(default)]
    pub coarse_kernel_sample_evaluations: Option<u32>,
}
