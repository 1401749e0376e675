//! The binding layout and interface description returned with the kernels.
//!
//! Engines and the runtime build their bind group layouts, buffers and
//! dispatches from this description; nothing about the generated code has
//! to be guessed. It serialises to JSON (`mrslc compile` writes `layout.json`).

use crate::check::{Checked, KeyCompare, UniformKind};
use crate::graph::EffectGraph;
use crate::interface::Interface;
use crate::syntax::ast::Rate;
use crate::types::{Scalar, Type, round_up};
use serde::Serialize;

/// Bind group of the control block, user uniforms, textures and samplers.
pub const GROUP_RESOURCES: u32 = 0;
/// Bind group of the G-buffer channels.
pub const GROUP_GBUFFER: u32 = 1;
/// Bind group of the interface buffer and the outputs.
pub const GROUP_STAGE: u32 = 2;
/// Binding of the runtime-owned control block in [`GROUP_RESOURCES`].
pub const BINDING_CONTROL: u32 = 0;
/// Binding of the user uniform block in [`GROUP_RESOURCES`].
pub const BINDING_UNIFORMS: u32 = 1;
/// Pixels per side of the tile a fine/reference workgroup shades.
pub const TILE: u32 = 8;

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Layout {
    /// Always `mrsl-layout/1`.
    pub format: &'static str,
    pub control: ControlBlock,
    pub uniforms: Option<UniformBlock>,
    pub textures: Vec<ResourceBinding>,
    pub samplers: Vec<ResourceBinding>,
    pub channels: Vec<Channel>,
    pub interface: InterfaceLayout,
    pub outputs: Vec<Output>,
    pub stats: StatsLayout,
    /// The fine kernels' per-pixel refine mask (`rg32uint`: x bit k = coarse effect k
    /// (stats counter k) evaluated per pixel; y bit k = taken from the dynamic mode's 2x2 level).
    pub rate_image: ResourceBinding,
    /// The dynamic mode's second (2x2) level of coarse samples: records of
    /// `interface.stride_words + 1` words, the last being a validity tag.
    pub interface2: ResourceBinding,
    /// The hierarchical (DACS) mode's buffers.
    pub hierarchical: HierarchicalLayout,
    pub effects: Vec<EffectLayout>,
}

/// Buffers of the hierarchical mode (group 2): a record per pixel, the work
/// lists of pixels to shade per level, and per-level counters that double as
/// indirect dispatch arguments.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct HierarchicalLayout {
    /// Per pixel: `flag_words` refine flags, `mask_words` "evaluated here" bits
    /// (bit k = coarse effect k), then every live coarse effect's value.
    pub values_binding: u32,
    pub record_words: u32,
    pub flag_words: u32,
    pub mask_words: u32,
    /// Word offset of each live coarse effect's value in a record, in stats-counter order.
    pub value_offsets: Vec<u32>,
    /// `array<u32>`: pixel indices to shade, level 1 to 4 one after another.
    pub work_binding: u32,
    /// `array<atomic<u32>>` of 4 words per level (index 0..4): the first counts queued pixels.
    pub queue_binding: u32,
    /// Indirect dispatch arguments (x, y, z, unused) per level (index 0..4), written by
    /// the `hier_args_*` entry points only: bind group `args_group`, binding 0. It is
    /// a separate group because a buffer cannot be indirect and writable in one dispatch.
    pub args_group: u32,
}

/// Counters the fine kernel accumulates (when the program has live coarse effects).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct StatsLayout {
    pub group: u32,
    pub binding: u32,
    /// Counter `k` counts the pixels that re-evaluated this coarse effect;
    /// one more counter after them counts the 2x2 samples the dynamic mode shaded.
    pub counters: Vec<String>,
}

/// The runtime-owned uniform block every kernel reads.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ControlBlock {
    pub group: u32,
    pub binding: u32,
    pub size: u32,
    pub fields: Vec<Field>,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Field {
    pub name: String,
    /// mrsl type (`float3`); `bool` fields are stored as `uint`.
    #[serde(rename = "type")]
    pub ty: String,
    pub wgsl_type: String,
    pub offset: u32,
    pub size: u32,
    /// Default value, components in order (columns for matrices), if any.
    pub default: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct UniformBlock {
    pub group: u32,
    pub binding: u32,
    /// Size in bytes (a multiple of 16).
    pub size: u32,
    pub fields: Vec<Field>,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ResourceBinding {
    pub name: String,
    pub group: u32,
    pub binding: u32,
    /// For textures: `float` (filterable). For samplers: `filtering`.
    pub kind: &'static str,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Channel {
    pub name: String,
    #[serde(rename = "type")]
    pub ty: String,
    pub group: u32,
    pub binding: u32,
    /// The texture format the runtime creates for it.
    pub format: &'static str,
    /// `unfilterable-float`, `uint` or `sint`: the sample type of the binding.
    pub sample_type: &'static str,
    /// Discontinuity key comparison, if this channel is a key.
    pub key: Option<KeyCompare>,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
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
    /// How many coarse samples there are for a `W`x`H` image and block size `B`.
    pub samples: &'static str,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SlotLayout {
    pub offset: u32,
    pub size: u32,
    pub effects: Vec<String>,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Output {
    pub name: String,
    #[serde(rename = "type")]
    pub ty: String,
    pub format: String,
    pub group: u32,
    pub binding: u32,
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct EffectLayout {
    pub name: String,
    pub rate: Rate,
    #[serde(rename = "type")]
    pub ty: String,
    /// Computed at all (reaches an output).
    pub live: bool,
    pub refine_bit: Option<u32>,
    pub slot: Option<usize>,
    pub resample: Option<&'static str>,
    pub depends_on: Vec<String>,
    /// When the effect is passed, as a formula over refine flags `r_X`.
    pub pass_condition: Option<String>,
}

/// Texture format and sample type for a G-buffer channel of type `ty`.
pub fn channel_format(ty: &Type) -> (&'static str, &'static str) {
    match ty {
        Type::Scalar(Scalar::Float) => ("r32float", "unfilterable-float"),
        Type::Vector(Scalar::Float, 2) => ("rg32float", "unfilterable-float"),
        Type::Vector(Scalar::Float, _) => ("rgba32float", "unfilterable-float"),
        Type::Scalar(Scalar::Uint) => ("r32uint", "uint"),
        Type::Vector(Scalar::Uint, 2) => ("rg32uint", "uint"),
        Type::Vector(Scalar::Uint, _) => ("rgba32uint", "uint"),
        Type::Scalar(Scalar::Int) => ("r32sint", "sint"),
        Type::Vector(Scalar::Int, 2) => ("rg32sint", "sint"),
        _ => ("rgba32sint", "sint"),
    }
}

pub fn build(checked: &Checked, graph: &EffectGraph, interface: &Interface) -> Layout {
    let control = ControlBlock {
        group: GROUP_RESOURCES,
        binding: BINDING_CONTROL,
        size: 32,
        fields: vec![
            Field {
                name: "size".into(),
                ty: "uint2".into(),
                wgsl_type: "vec2<u32>".into(),
                offset: 0,
                size: 8,
                default: None,
            },
            Field {
                name: "force_refine".into(),
                ty: "uint".into(),
                wgsl_type: "u32".into(),
                offset: 8,
                size: 4,
                default: Some(vec![0.0]),
            },
            Field {
                name: "frame".into(),
                ty: "uint".into(),
                wgsl_type: "u32".into(),
                offset: 12,
                size: 4,
                default: Some(vec![0.0]),
            },
            Field {
                name: "similarity".into(),
                ty: "float".into(),
                wgsl_type: "f32".into(),
                offset: 16,
                size: 4,
                default: Some(vec![0.0]),
            },
        ],
    };
    let mut fields = vec![];
    let (mut offset, mut max_align) = (0u32, 16u32);
    let mut textures = vec![];
    let mut samplers = vec![];
    let mut binding = BINDING_UNIFORMS + 1;
    for u in &checked.uniforms {
        match &u.kind {
            UniformKind::Value { default } => {
                let host = u.ty.host_type();
                let (align, size) = host.uniform_align_size();
                offset = round_up(offset, align);
                max_align = max_align.max(align);
                fields.push(Field {
                    name: u.name.clone(),
                    ty: u.ty.name(),
                    wgsl_type: host.wgsl(),
                    offset,
                    size,
                    default: default.as_ref().map(|d| d.values.clone()),
                });
                offset += size;
            }
            UniformKind::Texture => {
                textures.push(ResourceBinding { name: u.name.clone(), group: GROUP_RESOURCES, binding, kind: "float" });
                binding += 1;
            }
            UniformKind::Sampler => {
                samplers.push(ResourceBinding {
                    name: u.name.clone(),
                    group: GROUP_RESOURCES,
                    binding,
                    kind: "filtering",
                });
                binding += 1;
            }
        }
    }
    let uniforms = (!fields.is_empty()).then(|| UniformBlock {
        group: GROUP_RESOURCES,
        binding: BINDING_UNIFORMS,
        size: round_up(offset, max_align),
        fields,
    });
    let channels = checked
        .inputs
        .iter()
        .enumerate()
        .map(|(i, input)| {
            let (format, sample_type) = channel_format(&input.ty);
            Channel {
                name: input.name.clone(),
                ty: input.ty.name(),
                group: GROUP_GBUFFER,
                binding: i as u32,
                format,
                sample_type,
                key: input.key,
            }
        })
        .collect();
    let name = |e: &crate::check::EffectId| checked.effects[e.index()].name.clone();
    let slots = interface
        .slots
        .iter()
        .map(|s| SlotLayout { offset: s.offset, size: s.size, effects: s.effects.iter().map(name).collect() })
        .collect();
    let outputs = checked
        .effects
        .iter()
        .filter(|e| e.rate == Rate::Out)
        .enumerate()
        .map(|(i, e)| Output {
            name: e.name.clone(),
            ty: e.ty.name(),
            format: e.format.clone().unwrap_or_default(),
            group: GROUP_STAGE,
            binding: 1 + i as u32,
        })
        .collect();
    let effects = checked
        .effects
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let id = crate::check::EffectId(i as u32);
            let condition = interface.conditions[i].as_ref().filter(|c| c.possible()).map(|c| {
                let mut terms = vec![];
                if c.fine_user {
                    terms.push("fine".to_string());
                }
                terms.extend(c.refining_users.iter().map(|u| format!("r_{}", name(u))));
                let any = if terms.len() == 1 { terms[0].clone() } else { format!("({})", terms.join(" || ")) };
                if c.self_refines { format!("!r_{} && {any}", e.name) } else { any }
            });
            EffectLayout {
                name: e.name.clone(),
                rate: e.rate,
                ty: e.ty.name(),
                live: graph.live[i],
                refine_bit: interface.refine_bit[i],
                slot: interface.slot_of[i],
                resample: (e.rate == Rate::Coarse)
                    .then(|| if uses_nearest(checked, id) { "nearest" } else { "bilinear" }),
                depends_on: e.deps.iter().map(|(d, _)| name(d)).collect(),
                pass_condition: condition,
            }
        })
        .collect();
    Layout {
        format: "mrsl-layout/1",
        control,
        uniforms,
        textures,
        samplers,
        channels,
        interface: InterfaceLayout {
            group: GROUP_STAGE,
            binding: 0,
            stride_words: interface.stride,
            flag_words: interface.flag_words,
            slots,
            minimal: interface.exact,
            samples: "nx * ny, nx = (W + B - 2) / B + 1, ny = (H + B - 2) / B + 1 (integer division); sample (i, j) shades pixel (min(i*B, W-1), min(j*B, H-1))",
        },
        stats: StatsLayout {
            group: GROUP_STAGE,
            binding: 1 + checked.effects.iter().filter(|e| e.rate == Rate::Out).count() as u32,
            counters: graph
                .order
                .iter()
                .filter(|e| checked.effects[e.index()].rate == Rate::Coarse)
                .map(|e| checked.effects[e.index()].name.clone())
                .collect(),
        },
        rate_image: ResourceBinding {
            name: "mrsl_rate".into(),
            group: GROUP_STAGE,
            binding: 2 + checked.effects.iter().filter(|e| e.rate == Rate::Out).count() as u32,
            kind: "rg32uint",
        },
        interface2: ResourceBinding {
            name: "mrsl_interface2".into(),
            group: GROUP_STAGE,
            binding: 3 + checked.effects.iter().filter(|e| e.rate == Rate::Out).count() as u32,
            kind: "storage",
        },
        hierarchical: {
            let outputs = checked.effects.iter().filter(|e| e.rate == Rate::Out).count() as u32;
            let coarse: Vec<&crate::check::EffectInfo> =
                graph.order.iter().map(|e| &checked.effects[e.index()]).filter(|e| e.rate == Rate::Coarse).collect();
            let mask_words = (coarse.len() as u32).div_ceil(32).max(1);
            let mut offset = interface.flag_words + mask_words;
            let value_offsets = coarse
                .iter()
                .map(|e| {
                    let at = offset;
                    offset += e.ty.components();
                    at
                })
                .collect();
            HierarchicalLayout {
                values_binding: 0,
                record_words: offset,
                flag_words: interface.flag_words,
                mask_words,
                value_offsets,
                work_binding: 4 + outputs,
                queue_binding: 5 + outputs,
                args_group: 3,
            }
        },
        outputs,
        effects,
    }
}

/// Whether a coarse effect is resampled by the nearest corner: `@nearest`, or
/// a type that cannot be blended (int, uint, bool).
pub fn uses_nearest(checked: &Checked, id: crate::check::EffectId) -> bool {
    let e = &checked.effects[id.index()];
    e.nearest || e.ty.scalar() != Some(Scalar::Float)
}
