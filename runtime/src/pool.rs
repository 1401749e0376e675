//! The runtime-owned resources of a program's plan, made from their
//! descriptors ([`mrsl_abi::plan::ResourceDesc`]) the first time a mode
//! needs them and made again only when the image size changes what they
//! hold: one cache for every mode, keyed by resource id.

use mrsl_abi::plan::{BindingType, Plan, ResourceDesc, ResourceId, Shape, Step, Workgroups};
use std::collections::HashMap;

/// What the plan does with each resource, which decides its usages.
#[derive(Debug, Clone, Copy, Default)]
struct Uses {
    cleared: bool,
    read_back: bool,
    indirect: bool,
    sampled: bool,
}

/// A made resource.
enum Made {
    Buffer { buffer: wgpu::Buffer, bytes: u64 },
    Texture { texture: wgpu::Texture, view: wgpu::TextureView, extent: wgpu::Extent3d },
}

/// The resources of one program on one device.
pub(crate) struct ResourcePool {
    uses: HashMap<ResourceId, Uses>,
    made: HashMap<ResourceId, Made>,
    /// Read-back copies of buffers (`Step::Readback`), by resource.
    readbacks: HashMap<ResourceId, (wgpu::Buffer, u64)>,
}

impl ResourcePool {
    pub fn new(plan: &Plan) -> ResourcePool {
        let mut uses: HashMap<ResourceId, Uses> = HashMap::new();
        for step in plan.modes.iter().flat_map(|m| &m.steps) {
            match step {
                Step::Clear { resource } => uses.entry(*resource).or_default().cleared = true,
                Step::Readback { resource, .. } => uses.entry(*resource).or_default().read_back = true,
                Step::Pass(pass) => {
                    for b in &pass.bindings {
                        let sampled = matches!(b.ty, BindingType::RecordTexture | BindingType::UintTexture);
                        uses.entry(b.resource).or_default().sampled |= sampled;
                    }
                    for d in &pass.dispatches {
                        if let Workgroups::Indirect { buffer, .. } = d.workgroups {
                            uses.entry(buffer).or_default().indirect = true;
                        }
                    }
                }
            }
        }
        ResourcePool { uses, made: HashMap::new(), readbacks: HashMap::new() }
    }

    /// Makes the resource for a `size` image unless what exists already fits it.
    pub fn ensure(&mut self, device: &wgpu::Device, desc: &ResourceDesc, size: (u32, u32)) {
        let uses = self.uses.get(&desc.id).copied().unwrap_or_default();
        let label = format!("mrsl {}", desc.what.trim_start_matches("the "));
        match desc.shape {
            Shape::Buffer { .. } => {
                let bytes = desc.shape.buffer_bytes(size).expect("a buffer shape");
                if matches!(self.made.get(&desc.id), Some(Made::Buffer { bytes: b, .. }) if *b == bytes) {
                    return;
                }
                let mut usage = wgpu::BufferUsages::STORAGE;
                usage.set(wgpu::BufferUsages::COPY_DST, uses.cleared);
                usage.set(wgpu::BufferUsages::COPY_SRC, uses.read_back);
                usage.set(wgpu::BufferUsages::INDIRECT, uses.indirect);
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&label),
                    size: bytes,
                    usage,
                    mapped_at_creation: false,
                });
                self.made.insert(desc.id, Made::Buffer { buffer, bytes });
            }
            Shape::TextureArray { texels, layers, format } => {
                let (width, height) = texels.grid(size).expect("texture arrays span a grid");
                let extent = wgpu::Extent3d { width, height, depth_or_array_layers: layers.max(1) };
                let dimension = wgpu::TextureViewDimension::D2Array;
                self.ensure_texture(device, desc, &label, extent, format, dimension, uses);
            }
            Shape::Texture { format } => {
                let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
                self.ensure_texture(device, desc, &label, extent, format, wgpu::TextureViewDimension::D2, uses);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn ensure_texture(
        &mut self,
        device: &wgpu::Device,
        desc: &ResourceDesc,
        label: &str,
        extent: wgpu::Extent3d,
        format: mrsl_abi::TextureFormat,
        dimension: wgpu::TextureViewDimension,
        uses: Uses,
    ) {
        if matches!(self.made.get(&desc.id), Some(Made::Texture { extent: e, .. }) if *e == extent) {
            return;
        }
        let mut usage = wgpu::TextureUsages::STORAGE_BINDING;
        usage.set(wgpu::TextureUsages::TEXTURE_BINDING, uses.sampled);
        usage.set(wgpu::TextureUsages::COPY_SRC, desc.readable);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: crate::wgpu_format(format),
            usage,
            view_formats: &[],
        });
        let view =
            texture.create_view(&wgpu::TextureViewDescriptor { dimension: Some(dimension), ..Default::default() });
        self.made.insert(desc.id, Made::Texture { texture, view, extent });
    }

    /// A buffer made by [`ResourcePool::ensure`].
    pub fn buffer(&self, id: ResourceId) -> &wgpu::Buffer {
        match self.made.get(&id) {
            Some(Made::Buffer { buffer, .. }) => buffer,
            _ => panic!("{id:?} is a buffer made before the steps that use it"),
        }
    }

    /// Resource `id` as a binding.
    pub fn binding(&self, id: ResourceId) -> wgpu::BindingResource<'_> {
        match self.made.get(&id) {
            Some(Made::Buffer { buffer, .. }) => buffer.as_entire_binding(),
            Some(Made::Texture { view, .. }) => wgpu::BindingResource::TextureView(view),
            None => panic!("{id:?} is made before the steps that use it"),
        }
    }

    /// A texture, if it was made.
    pub fn texture(&self, id: ResourceId) -> Option<&wgpu::Texture> {
        match self.made.get(&id) {
            Some(Made::Texture { texture, .. }) => Some(texture),
            _ => None,
        }
    }

    /// Records a copy of `bytes` (or all) of buffer `id` into its read-back buffer.
    pub fn copy_out(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        id: ResourceId,
        bytes: Option<u64>,
    ) {
        let Some(Made::Buffer { buffer, bytes: size }) = self.made.get(&id) else {
            panic!("{id:?} is a buffer made before it is read back")
        };
        let size = *size;
        if self.readbacks.get(&id).is_none_or(|(_, b)| *b != size) {
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("mrsl readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.readbacks.insert(id, (readback, size));
        }
        encoder.copy_buffer_to_buffer(buffer, 0, &self.readbacks[&id].0, 0, bytes);
    }

    /// The read-back buffer of `id`, if it was ever copied out.
    pub fn readback(&self, id: ResourceId) -> Option<&wgpu::Buffer> {
        self.readbacks.get(&id).map(|(b, _)| b)
    }
}
