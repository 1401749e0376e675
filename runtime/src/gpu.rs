//! Small wgpu helpers: format conversion, buffer read-back and error
//! descriptions, shared by the runtime's modules and the tools built on it.

use crate::error::Error;
use mrsl_abi::TextureFormat;

/// The wgpu format of a layout format.
pub fn wgpu_format(format: TextureFormat) -> wgpu::TextureFormat {
    use wgpu::TextureFormat as F;
    match format {
        TextureFormat::R32Float => F::R32Float,
        TextureFormat::Rg32Float => F::Rg32Float,
        TextureFormat::Rgba32Float => F::Rgba32Float,
        TextureFormat::Rgba16Float => F::Rgba16Float,
        TextureFormat::Rgba8Unorm => F::Rgba8Unorm,
        TextureFormat::R32Uint => F::R32Uint,
        TextureFormat::Rg32Uint => F::Rg32Uint,
        TextureFormat::Rgba32Uint => F::Rgba32Uint,
        TextureFormat::R32Sint => F::R32Sint,
        TextureFormat::Rg32Sint => F::Rg32Sint,
        TextureFormat::Rgba32Sint => F::Rgba32Sint,
        TextureFormat::Depth32Float => F::Depth32Float,
    }
}

/// The layout format of a wgpu format, if the layout has it (the formats a
/// program can declare for its outputs and the exact channel formats).
pub fn layout_format(format: wgpu::TextureFormat) -> Option<TextureFormat> {
    TextureFormat::ALL.into_iter().find(|f| wgpu_format(*f) == format)
}

/// Maps `buffer` and copies its contents out (waits for the GPU).
pub fn read_buffer<T: bytemuck::Pod>(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<T>, Error> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Readback(e.to_string()))?;
    rx.recv().map_err(|e| Error::Readback(e.to_string()))?.map_err(|e| Error::Readback(e.to_string()))?;
    let data = {
        // wgpu 30 returns the mapped view as a `Result`; wgpu 29 (built by
        // mrsl-runtime-wgpu29, for Bevy 0.19) returns the view itself.
        #[cfg(not(feature = "wgpu29"))]
        let view = slice.get_mapped_range().map_err(|e| Error::Readback(e.to_string()))?;
        #[cfg(feature = "wgpu29")]
        let view = slice.get_mapped_range();
        bytemuck::cast_slice(&view).to_vec()
    };
    buffer.unmap();
    Ok(data)
}

/// Copies a single-level 2D texture out and returns its texels row by row,
/// tightly packed (waits for the GPU). The texture needs `COPY_SRC`.
pub fn read_texture(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Result<Vec<u8>, Error> {
    read_texture_level(device, queue, texture, 0)
}

/// Copies mip level `level` of a 2D texture out and returns its texels row
/// by row, tightly packed (waits for the GPU). The texture needs `COPY_SRC`.
pub fn read_texture_level(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    level: u32,
) -> Result<Vec<u8>, Error> {
    if level >= texture.mip_level_count() {
        return Err(Error::Readback(format!("the texture has no mip level {level}")));
    }
    let bytes_per_texel = texture.format().block_copy_size(None).unwrap_or(4);
    let size = texture.size().mip_level_size(level, texture.dimension());
    let (width, height) = (size.width, size.height);
    let row = width * bytes_per_texel;
    // Rows of a texture-to-buffer copy are padded to 256 bytes.
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mrsl texture readback"),
        size: u64::from(padded) * u64::from(height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        size,
    );
    queue.submit([encoder.finish()]);
    let padded_rows: Vec<u8> = read_buffer(device, &buffer)?;
    Ok(padded_rows.chunks(padded as usize).flat_map(|line| &line[..row as usize]).copied().collect())
}

/// A wgpu error's full description (its Display is only "Validation Error").
pub fn describe(error: &wgpu::Error) -> String {
    match error {
        wgpu::Error::Validation { description, .. } => description.clone(),
        other => other.to_string(),
    }
}

/// The kind of device `device` is, for the plans it runs by default: a CPU
/// device (a software rasteriser such as lavapipe or SwiftShader) or a GPU.
pub fn device_kind(device: &wgpu::Device) -> mrsl_abi::Device {
    match device.adapter_info().device_type {
        wgpu::DeviceType::Cpu => mrsl_abi::Device::Cpu,
        _ => mrsl_abi::Device::Gpu,
    }
}
