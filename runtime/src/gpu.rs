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
    }
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
        let view = slice.get_mapped_range().map_err(|e| Error::Readback(e.to_string()))?;
        bytemuck::cast_slice(&view).to_vec()
    };
    buffer.unmap();
    Ok(data)
}

/// A wgpu error's full description (its Display is only "Validation Error").
pub fn describe(error: &wgpu::Error) -> String {
    match error {
        wgpu::Error::Validation { description, .. } => description.clone(),
        other => other.to_string(),
    }
}
