//! Bind group layouts and bind groups: group 0 (the control and uniform
//! blocks, textures, samplers) and group 1 (the G-buffer) from the layout,
//! group 2 (a kernel's stage group) from a pass of the plan, and group 3
//! (indirect arguments) for the entry points that write them.

use crate::bindings::Bindings;
use crate::wgpu_format;
use mrsl_abi::plan::{BindingType, PassBinding};
use mrsl_abi::{BINDING_ARGS, Channel, ChannelAccess, Layout, SampleType};

pub(crate) fn resources_layout(device: &wgpu::Device, l: &Layout) -> wgpu::BindGroupLayout {
    let uniform = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let mut entries = vec![uniform(l.control.binding)];
    if let Some(u) = &l.uniforms {
        entries.push(uniform(u.binding));
    }
    for t in &l.textures {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: t.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
    }
    for s in &l.samplers {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: s.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("mrsl resources"), entries: &entries })
}

pub(crate) fn gbuffer_layout(device: &wgpu::Device, l: &Layout) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = l
        .channels
        .iter()
        .map(|c| wgpu::BindGroupLayoutEntry {
            binding: c.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: channel_binding_type(c),
            count: None,
        })
        .collect();
    device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("mrsl g-buffer"), entries: &entries })
}

/// How the kernels bind a channel: sampled, or read-only storage of exactly its format.
fn channel_binding_type(c: &Channel) -> wgpu::BindingType {
    match c.access {
        ChannelAccess::Storage => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::ReadOnly,
            format: wgpu_format(c.format),
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        ChannelAccess::Sampled => wgpu::BindingType::Texture {
            sample_type: match c.sample_type {
                SampleType::Uint => wgpu::TextureSampleType::Uint,
                SampleType::Sint => wgpu::TextureSampleType::Sint,
                SampleType::UnfilterableFloat => wgpu::TextureSampleType::Float { filterable: false },
                SampleType::Depth => wgpu::TextureSampleType::Depth,
            },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
    }
}

/// The stage group of a kernel, from the bindings a pass of the plan lists.
pub(crate) fn stage_layout(device: &wgpu::Device, label: &str, bindings: &[PassBinding]) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings
        .iter()
        .map(|b| wgpu::BindGroupLayoutEntry {
            binding: b.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: binding_type(b.ty),
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

/// Why `device` cannot create a stage group with `bindings`, where a binding
/// needs a device feature the device lacks: said before the group is made,
/// so that the error names the feature rather than a format.
pub(crate) fn missing_feature(device: &wgpu::Device, bindings: &[PassBinding]) -> Option<String> {
    let packed = bindings.iter().any(|b| b.ty == BindingType::PackedWordTexture);
    let granted = device.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
    (packed && !granted).then(|| {
        "its records are packed into an Rgba32Uint read-write storage texture (`Options::packed_records`), which \
         needs the device feature TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES and an adapter whose Rgba32Uint allows \
         read-write storage access: request the feature, or compile without packed records"
            .to_string()
    })
}

fn binding_type(ty: BindingType) -> wgpu::BindingType {
    let array = wgpu::TextureViewDimension::D2Array;
    match ty {
        BindingType::Buffer { read_only } => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        BindingType::StorageTexture { format } => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu_format(format),
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        BindingType::UintTexture => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        BindingType::RecordTexture => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: array,
            multisampled: false,
        },
        BindingType::RecordStorageTexture => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::Rgba32Uint,
            view_dimension: array,
        },
        BindingType::WordTexture => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::ReadWrite,
            format: wgpu::TextureFormat::R32Uint,
            view_dimension: array,
        },
        BindingType::PackedWordTexture => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::ReadWrite,
            format: wgpu::TextureFormat::Rgba32Uint,
            view_dimension: array,
        },
    }
}

/// Group 3: the indirect arguments an entry point writes.
pub(crate) fn arguments_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mrsl indirect arguments"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: BINDING_ARGS,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: binding_type(BindingType::Buffer { read_only: false }),
            count: None,
        }],
    })
}

/// Group 0 for one dispatch: the control and uniform blocks, the engine's textures and samplers.
pub(crate) fn resources_group(
    device: &wgpu::Device,
    layout: &Layout,
    group_layout: &wgpu::BindGroupLayout,
    (control, uniforms): (&wgpu::Buffer, Option<&wgpu::Buffer>),
    bindings: &Bindings,
) -> wgpu::BindGroup {
    let mut entries =
        vec![wgpu::BindGroupEntry { binding: layout.control.binding, resource: control.as_entire_binding() }];
    if let (Some(u), Some(buffer)) = (&layout.uniforms, uniforms) {
        entries.push(wgpu::BindGroupEntry { binding: u.binding, resource: buffer.as_entire_binding() });
    }
    for t in &layout.textures {
        entries.push(wgpu::BindGroupEntry {
            binding: t.binding,
            resource: wgpu::BindingResource::TextureView(bindings.textures[&t.name]),
        });
    }
    for s in &layout.samplers {
        entries.push(wgpu::BindGroupEntry {
            binding: s.binding,
            resource: wgpu::BindingResource::Sampler(bindings.samplers[&s.name]),
        });
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mrsl resources"),
        layout: group_layout,
        entries: &entries,
    })
}

/// Group 1 for one dispatch: the engine's G-buffer channels.
pub(crate) fn gbuffer_group(
    device: &wgpu::Device,
    layout: &Layout,
    group_layout: &wgpu::BindGroupLayout,
    bindings: &Bindings,
) -> wgpu::BindGroup {
    let views: Vec<(u32, wgpu::TextureView)> = layout
        .channels
        .iter()
        .map(|c| {
            // A depth-and-stencil texture is bound through its depth aspect.
            let aspect = if c.sample_type == SampleType::Depth {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            };
            // A storage binding takes one mip level: the kernels read level 0.
            let mip_level_count = (c.access == ChannelAccess::Storage).then_some(1);
            let view = wgpu::TextureViewDescriptor { aspect, mip_level_count, ..Default::default() };
            (c.binding, bindings.channels[&c.name].create_view(&view))
        })
        .collect();
    let entries: Vec<wgpu::BindGroupEntry> = views
        .iter()
        .map(|(b, v)| wgpu::BindGroupEntry { binding: *b, resource: wgpu::BindingResource::TextureView(v) })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mrsl g-buffer"),
        layout: group_layout,
        entries: &entries,
    })
}
