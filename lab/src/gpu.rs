//! Device acquisition for tools and tests, and texture upload/readback helpers
//! (the read-back itself is the runtime's).

/// Why no device could be had, or a readback failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GpuError {
    #[error("no adapter: {0}")]
    NoAdapter(String),
    #[error("device request failed: {0}")]
    Device(String),
    #[error("reading results back failed: {0}")]
    Readback(String),
}

use GpuError as Error;

/// A headless device: the first adapter wgpu finds (lavapipe on a machine
/// without a GPU), with timestamp queries when the adapter has them.
pub struct Gpu {
    pub adapter_info: wgpu::AdapterInfo,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Whether the device runs kernels compiled with packed records
    /// (`mrsl::Options::packed_records`): made by [`Gpu::with_packed_records`]
    /// on an adapter whose `Rgba32Uint` allows read-write storage access.
    pub packs_records: bool,
}

/// Every adapter the machine offers (what [`Gpu::new`] chooses from: it
/// prefers a discrete GPU, by wgpu's high-performance preference).
pub fn adapters() -> Vec<wgpu::AdapterInfo> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
    adapters.iter().map(|a| a.get_info()).collect()
}

impl Gpu {
    /// Milliseconds per dispatch of `pipeline` over `workgroups`, averaged
    /// over `dispatches` submissions and the wait for them: the timing of
    /// the lab's microbenchmarks (`record_loads`, `record_access`, `uniform_branch`, `uniform_loads`).
    pub fn time_dispatches(
        &self,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
        workgroups: (u32, u32),
        dispatches: u32,
    ) -> f64 {
        let start = std::time::Instant::now();
        for _ in 0..dispatches {
            let mut encoder = self.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(workgroups.0, workgroups.1, 1);
            }
            self.queue.submit([encoder.finish()]);
        }
        self.device.poll(wgpu::PollType::wait_indefinitely()).expect("the device is alive");
        start.elapsed().as_secs_f64() * 1000.0 / f64::from(dispatches)
    }

    /// A microbenchmark's kernel: the pipeline of `module`'s entry point
    /// `entry` (its layout derived from the shader) and its bind group 0 of
    /// `entries`.
    pub fn entry_kernel(
        &self,
        module: &wgpu::ShaderModule,
        entry: &str,
        entries: &[wgpu::BindGroupEntry],
    ) -> (wgpu::ComputePipeline, wgpu::BindGroup) {
        let pipeline = self.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: None,
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(entry),
            layout: &pipeline.get_bind_group_layout(0),
            entries,
        });
        (pipeline, group)
    }

    /// The default adapter with WebGPU's default limits (those every
    /// browser gives), at the adapter's largest image sizes.
    pub fn new() -> Result<Gpu, Error> {
        Gpu::with_storage_textures(wgpu::Limits::default().max_storage_textures_per_shader_stage)
    }

    /// The same, with up to `per_stage` storage textures per shader stage
    /// where the adapter allows as many (else the adapter's most): what
    /// kernels that read the G-buffer through storage bindings need
    /// (`mrsl::Options::storage_channels`).
    pub fn with_storage_textures(per_stage: u32) -> Result<Gpu, Error> {
        Gpu::make(per_stage, false)
    }

    /// The same, with read-write storage access to `Rgba32Uint` where the
    /// adapter has it (wgpu's `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`),
    /// which kernels compiled with `mrsl::Options::packed_records` need:
    /// [`Gpu::packs_records`] says whether it has.
    pub fn with_packed_records(per_stage: u32) -> Result<Gpu, Error> {
        Gpu::make(per_stage, true)
    }

    fn make(per_stage: u32, packed_records: bool) -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| Error::NoAdapter(format!("{e} (on a machine without a GPU, install Mesa's lavapipe: apt-get install mesa-vulkan-drivers libvulkan1)")))?;
        let read_write = wgpu::TextureFormatFeatureFlags::STORAGE_READ_WRITE;
        let packs_records = packed_records
            && adapter.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
            && adapter.get_texture_format_features(wgpu::TextureFormat::Rgba32Uint).flags.contains(read_write);
        let mut wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        wanted.set(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES, packs_records);
        let features = adapter.features() & wanted;
        let (device, queue) = pollster::block_on(
            adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("mrsl"),
                required_features: features,
                required_limits: wgpu::Limits {
                    max_storage_textures_per_shader_stage: per_stage
                        .min(adapter.limits().max_storage_textures_per_shader_stage)
                        .max(wgpu::Limits::default().max_storage_textures_per_shader_stage),
                    ..wgpu::Limits::default().using_resolution(adapter.limits())
                },
                ..Default::default()
            }),
        )
        .map_err(|e| Error::Device(e.to_string()))?;
        Ok(Gpu { adapter_info: adapter.get_info(), device, queue, packs_records })
    }

    /// Creates a 2D texture and fills it with `data` (tightly packed rows);
    /// it can be sampled, read through a storage binding where its format
    /// allows ([`storage_readable`]), and read back with [`Gpu::read_texture`].
    pub fn texture_with_data(
        &self,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        data: &[u8],
    ) -> wgpu::Texture {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC
            | storage_readable(format);
        let texture = self.texture_2d(label, size, format, usage);
        let bytes_per_pixel = format.block_copy_size(None).unwrap_or(4);
        self.queue.write_texture(
            texture.as_image_copy(),
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size.0 * bytes_per_pixel),
                rows_per_image: Some(size.1),
            },
            texture.size(),
        );
        texture
    }

    /// A single-level 2D texture.
    pub fn texture_2d(
        &self,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    }

    /// Creates an output texture a kernel can write and a copy can read.
    pub fn output_texture(&self, label: &str, size: (u32, u32), format: wgpu::TextureFormat) -> wgpu::Texture {
        self.texture_2d(
            label,
            size,
            format,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING,
        )
    }

    /// Reads a texture back as rows of raw texel bytes, tightly packed
    /// (the runtime's read-back, [`mrsl_runtime::gpu::read_texture`]).
    pub fn read_texture(&self, texture: &wgpu::Texture) -> Result<Vec<u8>, Error> {
        mrsl_runtime::gpu::read_texture(&self.device, &self.queue, texture).map_err(|e| match e {
            mrsl_runtime::Error::Readback(message) => Error::Readback(message),
            other => Error::Readback(other.to_string()),
        })
    }

    /// Reads mip level `level` of a texture back as rows of raw texel bytes,
    /// tightly packed ([`mrsl_runtime::gpu::read_texture_level`]).
    pub fn read_texture_level(&self, texture: &wgpu::Texture, level: u32) -> Result<Vec<u8>, Error> {
        mrsl_runtime::gpu::read_texture_level(&self.device, &self.queue, texture, level).map_err(|e| match e {
            mrsl_runtime::Error::Readback(message) => Error::Readback(message),
            other => Error::Readback(other.to_string()),
        })
    }

    /// Reads an `rgba32float` texture as RGBA pixels.
    pub fn read_rgba32f(&self, texture: &wgpu::Texture) -> Result<Vec<[f32; 4]>, Error> {
        Ok(bytemuck::pod_collect_to_vec(&self.read_texture(texture)?))
    }
}

/// `STORAGE_BINDING` where every device can read `format` through a storage
/// binding, else no usage: the G-buffer textures the lab makes can then be
/// bound either way (`mrsl_abi::ChannelAccess`).
pub fn storage_readable(format: wgpu::TextureFormat) -> wgpu::TextureUsages {
    let features = format.guaranteed_format_features(wgpu::Features::empty());
    features.allowed_usages & wgpu::TextureUsages::STORAGE_BINDING
}
