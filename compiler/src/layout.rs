//! Builds the [`Layout`] (the contract type of `mrsl-abi`) of a checked
//! program: binding numbers, uniform offsets, channel formats, interface
//! slots, statistics counters and the hierarchical records.

use crate::budget::Costs;
use crate::check::{Checked, EffectId, UniformKind};
use crate::deriv::DerivInfo;
use crate::graph::EffectGraph;
use crate::interface::Interface;
use crate::syntax::ast::Rate;
use crate::types::{Scalar, Type, round_up};
use mrsl_abi::geometry;
use mrsl_abi::{
    BINDING_CONTROL, BINDING_UNIFORMS, CONTROL_FIELDS, Channel, ChannelAccess, Control, ControlBlock, Decode,
    EffectLayout, Field, GROUP_ARGS, GROUP_GBUFFER, GROUP_RESOURCES, GROUP_STAGE, HierarchicalLayout, InterfaceLayout,
    LAYOUT_FORMAT, Layout, Output, Plan, Resample, ResourceBinding, ResourceKind, SampleType, SlotLayout, StatsLayout,
    TextureFormat, TileLayout, UniformBlock, ValueType,
};
use std::collections::HashMap;

/// The layout's type of a checked value type (checked programs only declare value types where the layout has them).
fn value_type(ty: &Type) -> ValueType {
    ty.value_type().unwrap_or(ValueType::Scalar(Scalar::Float))
}

/// Texture format and sample type of a G-buffer channel of type `ty`.
pub fn channel_format(ty: &Type) -> (TextureFormat, SampleType) {
    let scalar = ty.scalar().unwrap_or(Scalar::Float);
    let format = match (scalar, ty.components()) {
        (Scalar::Float, 1) => TextureFormat::R32Float,
        (Scalar::Float, 2) => TextureFormat::Rg32Float,
        (Scalar::Float, _) => TextureFormat::Rgba32Float,
        (Scalar::Uint | Scalar::Bool, 1) => TextureFormat::R32Uint,
        (Scalar::Uint | Scalar::Bool, 2) => TextureFormat::Rg32Uint,
        (Scalar::Uint | Scalar::Bool, _) => TextureFormat::Rgba32Uint,
        (Scalar::Int, 1) => TextureFormat::R32Sint,
        (Scalar::Int, 2) => TextureFormat::Rg32Sint,
        (Scalar::Int, _) => TextureFormat::Rgba32Sint,
    };
    (format, SampleType::of(format.scalar()))
}

/// Texture format and sample type of a channel the engine stores encoded:
/// what the tools create for it (the runtime accepts the others the
/// encoding fits, docs/runtime.md).
fn decoded_channel_format(decode: &Decode, ty: &Type) -> (TextureFormat, SampleType) {
    match decode {
        Decode::Depth { .. } => (TextureFormat::Depth32Float, SampleType::Depth),
        Decode::Octahedral | Decode::OctahedralUnorm => (TextureFormat::Rg32Float, SampleType::UnfilterableFloat),
        Decode::Unorm if ty.components() >= 3 => (TextureFormat::Rgba8Unorm, SampleType::UnfilterableFloat),
        Decode::Unorm => channel_format(ty),
        Decode::BevyDeferred { .. } => (TextureFormat::Rgba32Uint, SampleType::Uint),
    }
}

/// The layout of a checked program (mode plans and the multi-rate levels are
/// filled in after it by `plan::build` and `rates::levels_layout`).
pub fn build(
    checked: &Checked,
    graph: &EffectGraph,
    deriv: &DerivInfo,
    interface: &Interface,
    costs: &Costs,
) -> Layout {
    let (uniforms, textures, samplers) = uniform_block_and_resources(checked);
    let stage_resource = |slot: StageSlot, name: &str, kind: ResourceKind| ResourceBinding {
        name: name.into(),
        group: GROUP_STAGE,
        binding: stage_binding(checked, slot),
        kind,
    };
    let mut layout = Layout {
        format: LAYOUT_FORMAT.into(),
        control: control_block(),
        uniforms,
        textures,
        samplers,
        channels: channels(checked),
        interface: interface_layout(checked, interface),
        stats: StatsLayout {
            group: GROUP_STAGE,
            binding: stage_binding(checked, StageSlot::Stats),
            counters: graph
                .order
                .iter()
                .filter(|e| checked.effects[e.index()].rate == Rate::Coarse)
                .map(|e| checked.effects[e.index()].name.clone())
                .collect(),
        },
        refine_mask: stage_resource(StageSlot::RefineMask, "mrsl_refine_mask", ResourceKind::RefineMask),
        interface2: stage_resource(StageSlot::Interface2, "mrsl_interface2", ResourceKind::Storage),
        shading_rate: stage_resource(StageSlot::ShadingRate, "mrsl_shading_rate", ResourceKind::ShadingRate),
        neighbours: crate::neighbours::layout(
            checked,
            graph,
            deriv,
            interface,
            stage_binding(checked, StageSlot::Neighbours),
        ),
        tile: TileLayout { samples: 0, ring: u32::from(pixels_read_coarse_at_neighbours(checked, graph, deriv)) },
        hierarchical: hierarchical_layout(checked, graph, interface),
        outputs: outputs(checked),
        effects: effect_layouts(checked, graph, interface, costs),
        // Filled in by `rates::levels_layout` when the modes include the multi-rate one.
        levels: None,
        // Filled in from the modes by `plan::build`.
        plan: Plan { modes: vec![], resources: vec![], constants: Default::default() },
    };
    let evaluations = crate::neighbours::sample_evaluations(checked, graph, deriv, &layout.neighbours);
    for (effect, counts) in layout.effects.iter_mut().zip(evaluations) {
        effect.sample_evaluations = counts.map(|c| c.tile);
        effect.coarse_kernel_sample_evaluations = counts.map(|c| c.coarse_kernel);
    }
    layout
}

/// What the stage group binds after the interface record (binding 0) and the
/// outputs (from 1), in this order: every binding number past the outputs
/// comes from [`stage_binding`], so that none is counted in two places.
#[derive(Clone, Copy)]
enum StageSlot {
    Stats,
    RefineMask,
    Interface2,
    Work,
    Queue,
    ShadingRate,
    Neighbours,
    LevelValues,
}

/// The stage group's binding of `slot`.
fn stage_binding(checked: &Checked, slot: StageSlot) -> u32 {
    1 + output_count(checked) + slot as u32
}

fn output_count(checked: &Checked) -> u32 {
    checked.effects.iter().filter(|e| e.rate == Rate::Out).count() as u32
}

/// The control block every kernel binds: the contract's fields, as data.
fn control_block() -> ControlBlock {
    ControlBlock {
        group: GROUP_RESOURCES,
        binding: BINDING_CONTROL,
        size: Control::SIZE,
        fields: CONTROL_FIELDS
            .iter()
            .map(|f| Field {
                name: f.name.into(),
                ty: f.ty.clone(),
                wgsl_type: f.wgsl_type.into(),
                offset: f.offset,
                size: f.size,
                default: f.default.map(|d| vec![d]),
            })
            .collect(),
    }
}

/// The program's value uniforms laid out in one block (WGSL's uniform
/// alignment), and its textures and samplers bound after the block, in
/// declaration order.
fn uniform_block_and_resources(
    checked: &Checked,
) -> (Option<UniformBlock>, Vec<ResourceBinding>, Vec<ResourceBinding>) {
    let mut fields = vec![];
    let (mut offset, mut max_align) = (0u32, 16u32);
    let (mut textures, mut samplers) = (vec![], vec![]);
    let mut binding = BINDING_UNIFORMS + 1;
    for u in &checked.uniforms {
        let resource = |kind| ResourceBinding { name: u.name.clone(), group: GROUP_RESOURCES, binding, kind };
        match &u.kind {
            UniformKind::Value { default } => {
                let host = u.ty.host_type();
                let (align, size) = host.uniform_align_size();
                offset = round_up(offset, align);
                max_align = max_align.max(align);
                fields.push(Field {
                    name: u.name.clone(),
                    ty: value_type(&u.ty),
                    wgsl_type: host.wgsl(),
                    offset,
                    size,
                    default: default.as_ref().map(|d| d.values.clone()),
                });
                offset += size;
            }
            UniformKind::Texture => {
                textures.push(resource(ResourceKind::Texture));
                binding += 1;
            }
            UniformKind::Sampler => {
                samplers.push(resource(ResourceKind::Sampler));
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
    (uniforms, textures, samplers)
}

/// The G-buffer channels, a binding each in declaration order, sampled
/// (`read_channels_from_storage` switches those it can to storage).
fn channels(checked: &Checked) -> Vec<Channel> {
    checked
        .inputs
        .iter()
        .enumerate()
        .map(|(i, input)| {
            let (format, sample_type) = match &input.decode {
                Some(decode) => decoded_channel_format(decode, &input.ty),
                None => channel_format(&input.ty),
            };
            Channel {
                name: input.name.clone(),
                ty: value_type(&input.ty),
                group: GROUP_GBUFFER,
                binding: i as u32,
                format,
                sample_type,
                key: input.key.clone(),
                background: input.background,
                decode: input.decode.clone(),
                access: ChannelAccess::Sampled,
            }
        })
        .collect()
}

/// The `out` effects, bound from 1 in the stage group.
fn outputs(checked: &Checked) -> Vec<Output> {
    checked
        .effects
        .iter()
        .filter(|e| e.rate == Rate::Out)
        .enumerate()
        .map(|(i, e)| Output {
            name: e.name.clone(),
            ty: value_type(&e.ty),
            format: e.format.unwrap_or(TextureFormat::Rgba32Float),
            group: GROUP_STAGE,
            binding: 1 + i as u32,
        })
        .collect()
}

/// Every effect as the runtimes see it: its rate, refine bit, interface
/// slot, resampling, dependencies, keys, the condition under which a coarse
/// pass must evaluate it, and its operation counts.
fn effect_layouts(checked: &Checked, graph: &EffectGraph, interface: &Interface, costs: &Costs) -> Vec<EffectLayout> {
    let operations: HashMap<EffectId, u64> = costs.effects.iter().copied().collect();
    let value_operations: HashMap<EffectId, u64> = costs.values.iter().copied().collect();
    let name = |e: &EffectId| checked.effects[e.index()].name.clone();
    checked
        .effects
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let id = EffectId(i as u32);
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
                ty: value_type(&e.ty),
                live: graph.live[i],
                refine_bit: interface.refine_bit[i],
                slot: interface.slot_of[i],
                resample: (e.rate == Rate::Coarse)
                    .then(|| if uses_nearest(checked, id) { Resample::Nearest } else { Resample::Bilinear }),
                depends_on: e.deps.iter().map(|(d, _)| name(d)).collect(),
                keys: if e.rate == Rate::Coarse && graph.live[i] {
                    graph.keys[i].iter().map(|k| checked.inputs[k.index()].name.clone()).collect()
                } else {
                    vec![]
                },
                pass_condition: condition,
                operations: operations.get(&id).copied(),
                value_operations: value_operations.get(&id).copied(),
                // Filled in with the neighbour values, by `build`.
                sample_evaluations: None,
                coarse_kernel_sample_evaluations: None,
            }
        })
        .collect()
}

/// The hierarchical mode's per-pixel record: the interface's flag words, a
/// mask word per 32 coarse effects, then every coarse effect's value in
/// evaluation order; and its work-list bindings.
fn hierarchical_layout(checked: &Checked, graph: &EffectGraph, interface: &Interface) -> HierarchicalLayout {
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
        // Set by `compile` from `Options::packed_records`.
        packed: false,
        work_binding: stage_binding(checked, StageSlot::Work),
        queue_binding: stage_binding(checked, StageSlot::Queue),
        args_group: GROUP_ARGS,
    }
}

/// Binds every channel whose format a storage binding can read (all but
/// those rebuilt from depth) as a read-only storage texture
/// ([`crate::Options::storage_channels`]).
pub fn read_channels_from_storage(layout: &mut Layout) {
    for channel in &mut layout.channels {
        if channel.format.storage_readable() && channel.sample_type != SampleType::Depth {
            channel.access = ChannelAccess::Storage;
        }
    }
}

/// The binding of the multi-rate mode's stored values in the stage group,
/// after the neighbour values'.
pub fn level_values_binding(checked: &Checked) -> u32 {
    stage_binding(checked, StageSlot::LevelValues)
}

/// The record of an interface: its slots by effect name, at binding 0 of the stage group.
pub fn interface_layout(checked: &Checked, interface: &Interface) -> InterfaceLayout {
    let name = |e: &EffectId| checked.effects[e.index()].name.clone();
    let slots = interface
        .slots
        .iter()
        .map(|s| SlotLayout { offset: s.offset, size: s.size, effects: s.effects.iter().map(name).collect() })
        .collect();
    InterfaceLayout {
        group: GROUP_STAGE,
        binding: 0,
        stride_words: interface.stride,
        flag_words: interface.flag_words,
        slots,
        minimal: interface.exact,
        samples: mrsl_abi::geometry::SAMPLE_GRID_RULE.into(),
    }
}

/// Whether a per-pixel evaluation (a fine effect, or a refined coarse effect
/// evaluated for its value) takes a derivative of an operand that reads a
/// coarse effect: then the value at the neighbouring pixel is resolved from
/// that pixel's corners, which at the image's last column or row (the quad
/// pair taken to the left) can be the previous tile's.
fn pixels_read_coarse_at_neighbours(checked: &Checked, graph: &EffectGraph, deriv: &DerivInfo) -> bool {
    let coarse = |e: EffectId| checked.effects[e.index()].rate == Rate::Coarse;
    deriv.sites.iter().filter(|site| graph.live[site.effect.index()] && !site.decides_only).any(|site| {
        site.effects.iter().any(|&e| graph.live[e.index()] && graph.closure(e, checked).into_iter().any(coarse))
    })
}

/// The tile kernel's tile ([`TileLayout`]): the most samples per side of
/// [`geometry::TILE_SAMPLES`] whose workgroup memory fits WebGPU's default
/// limit, else the fewest (its kernel then runs on devices that grant more).
pub fn tile_layout(layout: &Layout) -> TileLayout {
    let ring = layout.tile.ring;
    let fits = |samples| tile_workgroup_bytes(layout, TileLayout { samples, ring }) <= geometry::TILE_WORKGROUP_BYTES;
    let all = geometry::TILE_SAMPLES;
    let samples = all.iter().copied().find(|&s| fits(s)).unwrap_or(all[all.len() - 1]);
    TileLayout { samples, ring }
}

/// The workgroup memory of the tile kernel with `tile`, as WebGPU counts it
/// (each variable rounded up to 16 bytes): the records, the neighbour
/// values and the refine flags kept beside them, the statistics counters
/// and, with a background rule, a word per
/// 8x8 pixels of the 4x4 blocks' tile. A test holds the kernels to it.
pub fn tile_workgroup_bytes(layout: &Layout, tile: TileLayout) -> u32 {
    let records = layout.interface.stride_words.max(1) * tile.record_side().pow(2);
    let neighbours = layout.neighbours.words * tile.neighbour_side().pow(2);
    let surface_tiles = if layout.has_background() { (tile.side(4) / geometry::TILE).pow(2) } else { 0 };
    let flags = if crate::neighbours::tile_keeps_flags(layout) {
        layout.interface.flag_words * tile.record_side().pow(2)
    } else {
        0
    };
    let variable = |words: u32| (4 * words).div_ceil(16) * 16;
    variable(records)
        + variable(neighbours)
        + variable(flags)
        + variable(layout.stats_counters() as u32)
        + variable(surface_tiles)
}

/// The storage textures WebGPU guarantees a shader stage
/// (`maxStorageTexturesPerShaderStage`'s default): the hierarchical kernel
/// adds the neighbour values to its stage group only within it.
const DEFAULT_STORAGE_TEXTURES_PER_STAGE: u32 = 4;

/// Whether the hierarchical kernel stores the neighbour values at level 0's
/// pixels (`hier_level0_values`, docs/language.md section 9): where the
/// program has them, and its stage group's storage textures (the records,
/// the outputs, the refine mask where there are counters) leave room for
/// one more within WebGPU's default limit, so that a program whose
/// hierarchical kernel ran on a default device still does. Otherwise level
/// 0 keeps the quad pair. The plan and the code generator both ask this.
pub fn hierarchical_level0_values(layout: &Layout) -> bool {
    let refine_mask = u32::from(!layout.stats.counters.is_empty());
    let stage = 1 + layout.outputs.len() as u32 + refine_mask;
    layout.neighbours.words > 0 && stage < DEFAULT_STORAGE_TEXTURES_PER_STAGE
}

/// Whether a coarse effect is resampled by the nearest corner: `@nearest`, or
/// a type that cannot be blended (int, uint, bool).
pub fn uses_nearest(checked: &Checked, id: EffectId) -> bool {
    let e = &checked.effects[id.index()];
    e.nearest || e.ty.scalar() != Some(Scalar::Float)
}

#[cfg(test)]
mod tests {
    use mrsl_abi::Layout;

    fn layout(source: &str) -> Layout {
        crate::compile(source, &crate::Options::for_modes(&[mrsl_abi::Mode::Coarse4x4])).unwrap().layout.clone()
    }

    /// Each effect's evaluations per sample: in the tile kernel, in the two-pass coarse kernel.
    fn evaluations(layout: &Layout) -> Vec<(&str, Option<(u32, u32)>)> {
        let counts = |e: &mrsl_abi::EffectLayout| e.sample_evaluations.zip(e.coarse_kernel_sample_evaluations);
        layout.effects.iter().map(|e| (e.name.as_str(), counts(e))).collect()
    }

    /// A derivative of an effect reads the neighbour values: every body runs
    /// once per sample, the stored one in the neighbour pass. A stored effect
    /// that refines runs again at the sample, for its flag, in the two-pass
    /// coarse kernel; the tile kernel keeps its flag beside its value. An
    /// effect whose neighbour evaluation takes a derivative of another effect
    /// in turn is evaluated in place: once at the sample and once per
    /// position of each difference that reads it (`fwidth`: two).
    #[test]
    fn sample_evaluations_count_the_bodies_a_sample_runs() {
        let head = "in float3 normal;\ncoarse effect float a = normal.x * normal.y;\n";
        let stored = format!(
            "{head}coarse effect float b {{\n    b = a * 2.0;\n    if (fwidth(a) > 0.1) refine;\n}}\n\
             fine out float4 color = float4(b);\n"
        );
        assert_eq!(evaluations(&layout(&stored)), [("a", Some((1, 1))), ("b", Some((1, 1))), ("color", None)]);
        let refining = stored.replace(
            "coarse effect float a = normal.x * normal.y;",
            "coarse effect float a {\n    a = normal.x;\n    if (a > 0.5) refine;\n}",
        );
        assert_eq!(evaluations(&layout(&refining)), [("a", Some((1, 2))), ("b", Some((1, 1))), ("color", None)]);
        let nested = format!(
            "{head}coarse effect float b = ddx(a);\ncoarse effect float c {{\n    c = b;\n    if (fwidth(b) > 0.1) refine;\n}}\n\
             fine out float4 color = float4(c);\n"
        );
        // A chain of refining neighbour values: b's flag takes a difference
        // of a, c's of b: three waves, each body once in the tile kernel.
        let chain = format!(
            "{head}coarse effect float b {{\n    b = a * 2.0;\n    if (fwidth(a) > 0.1) refine;\n}}\n\
             coarse effect float c {{\n    c = b + 1.0;\n    if (fwidth(b) > 0.1) refine;\n}}\n\
             coarse effect float d {{\n    d = c;\n    if (fwidth(c) > 0.1) refine;\n}}\n\
             fine out float4 color = float4(d);\n"
        )
        .replace(
            "coarse effect float a = normal.x * normal.y;",
            "coarse effect float a {\n    a = normal.x;\n    if (a > 0.5) refine;\n}",
        );
        let chain = layout(&chain);
        let waves: Vec<(&str, u32)> = chain.neighbours.effects.iter().map(|v| (v.name.as_str(), v.wave)).collect();
        assert_eq!(waves, [("a", 0), ("b", 1), ("c", 2)]);
        let expected = [("a", Some((1, 2))), ("b", Some((1, 2))), ("c", Some((1, 2))), ("d", Some((1, 1)))];
        assert_eq!(evaluations(&chain)[..4], expected);
        let nested = layout(&nested);
        assert_eq!(nested.neighbours.words, 0, "b's value takes a derivative of a: evaluated in place");
        // c: once. b: once, and at two positions for c's fwidth. a: once for
        // b at the sample, and per evaluation of b elsewhere once for itself
        // and once for b's ddx: 1 + 1 + 2 x 2.
        assert_eq!(
            evaluations(&nested),
            [("a", Some((6, 6))), ("b", Some((3, 3))), ("c", Some((1, 1))), ("color", None)]
        );
    }
}
