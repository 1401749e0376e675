//! The rate source's GPU interface, stated once: the `Params` uniform block
//! ([`Params`] and its fields), the flag bits and combiner codes, and the
//! bindings of its two entry points. The WGSL declarations of all of them
//! are written from here ([`wgsl_declarations`]) in front of
//! `rate_source.wgsl`, and the bind group layouts and groups are built from
//! the same tables, so the shader and the Rust side cannot disagree.

use super::{Combiner, WEBER_FLOOR};

/// The uniform block `Params` as the runtime uploads it.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Params {
    pub size: [u32; 2],
    pub rate_size: [u32; 2],
    pub tile: u32,
    pub flags: u32,
    pub sensitivity: f32,
    pub env_luma: f32,
    pub k: f32,
    pub weber_fechner: f32,
    pub fovea_inner: f32,
    pub fovea_outer: f32,
    pub gaze: [f32; 2],
    /// The external combiner in bits 0..3, the foveation combiner in bits 4..7.
    pub combiners: u32,
    /// Channels of the colour input (1, 2 or 4): what its luminance is made of.
    pub color_channels: u32,
}

/// The fields of [`Params`] in order: name, WGSL type, byte offset.
const PARAMS_FIELDS: [(&str, &str, usize); 13] = [
    ("size", "vec2<u32>", 0),
    ("rate_size", "vec2<u32>", 8),
    ("tile", "u32", 16),
    ("flags", "u32", 20),
    ("sensitivity", "f32", 24),
    ("env_luma", "f32", 28),
    ("k", "f32", 32),
    ("weber_fechner", "f32", 36),
    ("fovea_inner", "f32", 40),
    ("fovea_outer", "f32", 44),
    ("gaze", "vec2<f32>", 48),
    ("combiners", "u32", 56),
    ("color_channels", "u32", 60),
];

/// A bit of `Params::flags`; the shader tests them as `FLAG_<NAME>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Flag {
    WeberFechner,
    Motion,
    FirstFrame,
    Reproject,
    External,
    Foveation,
    Hysteresis,
}

impl Flag {
    const ALL: [Flag; 7] = [
        Flag::WeberFechner,
        Flag::Motion,
        Flag::FirstFrame,
        Flag::Reproject,
        Flag::External,
        Flag::Foveation,
        Flag::Hysteresis,
    ];

    pub fn bit(self) -> u32 {
        1 << self as u32
    }

    fn wgsl_name(self) -> &'static str {
        match self {
            Flag::WeberFechner => "FLAG_WEBER_FECHNER",
            Flag::Motion => "FLAG_MOTION",
            Flag::FirstFrame => "FLAG_FIRST_FRAME",
            Flag::Reproject => "FLAG_REPROJECT",
            Flag::External => "FLAG_EXTERNAL",
            Flag::Foveation => "FLAG_FOVEATION",
            Flag::Hysteresis => "FLAG_HYSTERESIS",
        }
    }
}

/// The entry points, each with a bind group of its own (group 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Entry {
    /// Per tile: the raw decision from the colour (and motion).
    Decide,
    /// Per tile: damping, reprojection, combiners; writes the target.
    Resolve,
}

/// A binding of group 0, by what it holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Binding {
    Params,
    Color,
    Velocity,
    RawOut,
    RawIn,
    HistoryIn,
    ExternalRates,
    TargetOut,
    HistoryOut,
}

/// How a binding is declared.
#[derive(Clone, Copy)]
enum Kind {
    Uniform,
    FloatTexture,
    UintTexture,
    /// A write-only storage texture of [`super::RATE_IMAGE_FORMAT`].
    RateStorage,
}

/// Every binding: what it holds, its WGSL name and kind, and the entry points that use it.
const BINDINGS: [(Binding, &str, Kind, &[Entry]); 9] = [
    (Binding::Params, "params", Kind::Uniform, &[Entry::Decide, Entry::Resolve]),
    (Binding::Color, "color", Kind::FloatTexture, &[Entry::Decide]),
    (Binding::Velocity, "velocity", Kind::FloatTexture, &[Entry::Decide, Entry::Resolve]),
    (Binding::RawOut, "raw_out", Kind::RateStorage, &[Entry::Decide]),
    (Binding::RawIn, "raw_in", Kind::UintTexture, &[Entry::Resolve]),
    (Binding::HistoryIn, "history_in", Kind::UintTexture, &[Entry::Resolve]),
    (Binding::ExternalRates, "external_rates", Kind::UintTexture, &[Entry::Resolve]),
    (Binding::TargetOut, "target_out", Kind::RateStorage, &[Entry::Resolve]),
    (Binding::HistoryOut, "history_out", Kind::RateStorage, &[Entry::Resolve]),
];

impl Binding {
    /// The binding number (its place in [`BINDINGS`]).
    pub fn number(self) -> u32 {
        BINDINGS.iter().position(|(b, ..)| *b == self).expect("every binding is listed") as u32
    }
}

/// The WGSL that declares the interface: `Params`, the flag and combiner
/// constants, `WEBER_FLOOR`, and every binding.
pub(super) fn wgsl_declarations() -> String {
    let mut out = String::from("// Written by rate_source/interface.rs.\nstruct Params {\n");
    for (name, ty, _) in PARAMS_FIELDS {
        if name == "combiners" {
            out.push_str("    // External combiner in bits 0..3, foveation combiner in bits 4..7.\n");
        }
        out.push_str(&format!("    {name}: {ty},\n"));
    }
    out.push_str("}\n\n");
    for flag in Flag::ALL {
        out.push_str(&format!("const {}: u32 = {}u;\n", flag.wgsl_name(), flag.bit()));
    }
    out.push('\n');
    for combiner in Combiner::ALL {
        out.push_str(&format!("const {}: u32 = {}u;\n", combiner.wgsl_name(), combiner.code()));
    }
    out.push_str(&format!("\n// The smallest Weber–Fechner divisor.\nconst WEBER_FLOOR: f32 = {WEBER_FLOOR:?};\n\n"));
    for (number, (_, name, kind, _)) in BINDINGS.iter().enumerate() {
        let ty = match kind {
            Kind::Uniform => "<uniform> ",
            _ => " ",
        };
        let declared = match kind {
            Kind::Uniform => "Params",
            Kind::FloatTexture => "texture_2d<f32>",
            Kind::UintTexture => "texture_2d<u32>",
            Kind::RateStorage => "texture_storage_2d<r32uint, write>",
        };
        out.push_str(&format!("@group(0) @binding({number}) var{ty}{name}: {declared};\n"));
    }
    out.push('\n');
    out
}

/// The bind group layout of `entry`: the bindings it uses.
pub(super) fn layout(device: &wgpu::Device, entry: Entry) -> wgpu::BindGroupLayout {
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let texture = |sample_type| wgpu::BindingType::Texture {
        sample_type,
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    };
    let entries: Vec<wgpu::BindGroupLayoutEntry> = BINDINGS
        .iter()
        .enumerate()
        .filter(|(_, (.., used_by))| used_by.contains(&entry))
        .map(|(number, (_, _, kind, _))| wgpu::BindGroupLayoutEntry {
            binding: number as u32,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: match kind {
                Kind::Uniform => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Kind::FloatTexture => texture(float),
                Kind::UintTexture => texture(wgpu::TextureSampleType::Uint),
                Kind::RateStorage => wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: super::RATE_IMAGE_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: label(entry), entries: &entries })
}

/// The bind group of `entry`: the parameters, and a view for each texture binding it uses.
pub(super) fn group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    entry: Entry,
    params: &wgpu::Buffer,
    view: impl Fn(Binding) -> wgpu::TextureView,
) -> wgpu::BindGroup {
    let views: Vec<(u32, Option<wgpu::TextureView>)> = BINDINGS
        .iter()
        .filter(|(.., used_by)| used_by.contains(&entry))
        .map(|&(binding, ..)| (binding.number(), (binding != Binding::Params).then(|| view(binding))))
        .collect();
    let entries: Vec<wgpu::BindGroupEntry> = views
        .iter()
        .map(|(number, view)| wgpu::BindGroupEntry {
            binding: *number,
            resource: match view {
                Some(view) => wgpu::BindingResource::TextureView(view),
                None => params.as_entire_binding(),
            },
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: label(entry), layout, entries: &entries })
}

fn label(entry: Entry) -> Option<&'static str> {
    Some(match entry {
        Entry::Decide => "mrsl rate decide",
        Entry::Resolve => "mrsl rate resolve",
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_table_matches_the_struct() {
        use std::mem::offset_of;
        let offsets = [
            offset_of!(Params, size),
            offset_of!(Params, rate_size),
            offset_of!(Params, tile),
            offset_of!(Params, flags),
            offset_of!(Params, sensitivity),
            offset_of!(Params, env_luma),
            offset_of!(Params, k),
            offset_of!(Params, weber_fechner),
            offset_of!(Params, fovea_inner),
            offset_of!(Params, fovea_outer),
            offset_of!(Params, gaze),
            offset_of!(Params, combiners),
            offset_of!(Params, color_channels),
        ];
        let table: Vec<usize> = PARAMS_FIELDS.iter().map(|(.., offset)| *offset).collect();
        assert_eq!(table, offsets);
        assert_eq!(std::mem::size_of::<Params>(), 64, "a multiple of 16, as a uniform block");
    }

    /// The declarations and the shader's text are one valid WGSL module.
    #[test]
    fn the_declarations_complete_the_shader() {
        let source = format!("{}{}", wgsl_declarations(), include_str!("rate_source.wgsl"));
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        let mut validator = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), Default::default());
        validator.validate(&module).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        assert!(
            source.contains("const FLAG_HYSTERESIS: u32 = 64u;")
                && source.contains("const COMBINE_OVERRIDE: u32 = 2u;")
        );
    }
}
