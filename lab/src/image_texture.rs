//! Textures from image files, for the `texture2d` uniforms a scene file
//! binds (`albedo_map = "brick.png"`): decoding, the colour-space
//! convention, and a full mip chain.
//!
//! - Formats: PNG and JPEG (the `image` crate). Every image becomes 8-bit
//!   RGBA: grey images expand to r = g = b, images without alpha get a = 1,
//!   and 16-bit channels are rounded to 8 bits.
//! - Colour space: 8-bit colour images are sRGB-encoded by convention, so by
//!   default ([`ColorSpace::Srgb`]) the texels are uploaded as
//!   `Rgba8UnormSrgb` and the GPU decodes them to linear values before
//!   filtering: `sample` returns linear colour, which is what lighting
//!   needs. Data images (roughness, metalness, normal maps, masks) are not
//!   colours; with [`ColorSpace::Linear`] (`srgb = false` in a scene file)
//!   they are uploaded as `Rgba8Unorm`, texel values / 255. Alpha is linear
//!   in both.
//! - Mipmaps: programs `sample` with the level of detail their derivatives
//!   give (a coarse sample spans a whole block), so a texture without mips
//!   would alias. Every level down to 1x1 is made on the CPU by averaging
//!   2x2 texels (a box filter; at odd sizes the last row or column is
//!   averaged with itself), in linear space for sRGB images so that
//!   averaging does not darken them.

use crate::color::{linear_to_srgb8, srgb_to_linear};
use crate::gpu::Gpu;
use std::path::{Path, PathBuf};

/// How an image's 8-bit values are to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorSpace {
    /// sRGB-encoded colour (the default for images): sampled as linear colour.
    #[default]
    Srgb,
    /// Data, sampled as stored (value / 255).
    Linear,
}

/// Largest side accepted: WebGPU's default `max_texture_dimension_2d`.
pub const MAX_SIDE: u32 = 8192;

/// Why an image could not be made a texture; names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("cannot read image {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot decode image {}: {message} (PNG and JPEG are supported)", path.display())]
    Decode { path: PathBuf, message: String },
    #[error("image {} is {width}x{height}; the largest side a texture may have is {MAX_SIDE}", path.display())]
    TooLarge { path: PathBuf, width: u32, height: u32 },
}

/// An RGBA8 image and its mip chain, ready to upload.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageTexture {
    pub color_space: ColorSpace,
    /// Level 0 first; each `(width, height, rgba8 texels)`, down to 1x1.
    pub levels: Vec<(u32, u32, Vec<u8>)>,
}

impl ImageTexture {
    /// Decodes the image file at `path`.
    pub fn load(path: &Path, color_space: ColorSpace) -> Result<ImageTexture, ImageError> {
        let bytes = std::fs::read(path).map_err(|source| ImageError::Io { path: path.to_path_buf(), source })?;
        let decoded = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| ImageError::Decode { path: path.to_path_buf(), message: e.to_string() })?
            .decode()
            .map_err(|e| ImageError::Decode { path: path.to_path_buf(), message: e.to_string() })?;
        let (width, height) = (decoded.width(), decoded.height());
        if width > MAX_SIDE || height > MAX_SIDE {
            return Err(ImageError::TooLarge { path: path.to_path_buf(), width, height });
        }
        Ok(ImageTexture::from_image(decoded.to_rgba8(), color_space))
    }

    /// An RGBA8 image (rows top to bottom) with its mip chain.
    pub fn from_image(image: image::RgbaImage, color_space: ColorSpace) -> ImageTexture {
        let (width, height) = image.dimensions();
        let mut levels = vec![(width, height, image.into_raw())];
        while let Some((w, h, data)) = levels.last().filter(|(w, h, _)| *w > 1 || *h > 1) {
            let next = downsample(*w, *h, data, color_space);
            levels.push(next);
        }
        ImageTexture { color_space, levels }
    }

    /// The size of level 0.
    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].0, self.levels[0].1)
    }

    /// The texture format it is uploaded as.
    pub fn format(&self) -> wgpu::TextureFormat {
        match self.color_space {
            ColorSpace::Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
            ColorSpace::Linear => wgpu::TextureFormat::Rgba8Unorm,
        }
    }

    /// Uploads every level into a new texture (it can be sampled and copied).
    pub fn upload(&self, gpu: &Gpu, label: &str) -> wgpu::Texture {
        let (width, height) = self.size();
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: self.levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format(),
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        for (level, (w, h, data)) in self.levels.iter().enumerate() {
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                data,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(w * 4), rows_per_image: Some(*h) },
                wgpu::Extent3d { width: *w, height: *h, depth_or_array_layers: 1 },
            );
        }
        texture
    }
}

/// The next mip level: each texel the mean of (up to) 2x2 texels, colour
/// averaged in linear space for sRGB images.
fn downsample(width: u32, height: u32, data: &[u8], color_space: ColorSpace) -> (u32, u32, Vec<u8>) {
    let (w, h) = ((width / 2).max(1), (height / 2).max(1));
    let decode: Vec<f32> = (0..=255u8)
        .map(|v| match color_space {
            ColorSpace::Srgb => srgb_to_linear(v),
            ColorSpace::Linear => f32::from(v) / 255.0,
        })
        .collect();
    let mut out = Vec::with_capacity(w as usize * h as usize * 4);
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let sx = (2 * x + dx).min(width - 1) as usize;
                let sy = (2 * y + dy).min(height - 1) as usize;
                let texel = &data[(sy * width as usize + sx) * 4..][..4];
                for (s, &v) in sum.iter_mut().zip(&texel[..3]) {
                    *s += decode[usize::from(v)];
                }
                sum[3] += f32::from(texel[3]) / 255.0;
            }
            for (c, s) in sum.iter().enumerate() {
                let mean = s / 4.0;
                out.push(match (c, color_space) {
                    (0..=2, ColorSpace::Srgb) => linear_to_srgb8(mean),
                    _ => (mean.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
                });
            }
        }
    }
    (w, h, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rgba(width: u32, height: u32, texels: Vec<u8>) -> image::RgbaImage {
        image::RgbaImage::from_raw(width, height, texels).expect("texels of the size given")
    }

    #[test]
    fn the_mip_chain_goes_down_to_one_texel() {
        let t = ImageTexture::from_image(rgba(5, 2, vec![100; 5 * 2 * 4]), ColorSpace::Linear);
        let sizes: Vec<(u32, u32)> = t.levels.iter().map(|(w, h, _)| (*w, *h)).collect();
        assert_eq!(sizes, [(5, 2), (2, 1), (1, 1)]);
        for (w, h, data) in &t.levels {
            assert_eq!(data.len(), (w * h * 4) as usize);
            assert!(data.iter().all(|&v| v == 100), "a flat image stays flat");
        }
        assert_eq!(t.format(), wgpu::TextureFormat::Rgba8Unorm);
    }

    #[test]
    fn srgb_images_are_averaged_in_linear_space() {
        // Black and white texels: the mean of their light is half white,
        // which sRGB encodes as 188, not 128 (averaging the encoded values
        // would darken every minified texture).
        let texels = [[0u8, 0, 0, 255], [255, 255, 255, 255], [0, 0, 0, 255], [255, 255, 255, 255]].concat();
        let srgb = ImageTexture::from_image(rgba(2, 2, texels.clone()), ColorSpace::Srgb);
        assert_eq!(srgb.levels[1].2, [188, 188, 188, 255]);
        assert_eq!(srgb.format(), wgpu::TextureFormat::Rgba8UnormSrgb);
        let linear = ImageTexture::from_image(rgba(2, 2, texels), ColorSpace::Linear);
        assert_eq!(linear.levels[1].2, [128, 128, 128, 255]);
    }

    #[test]
    fn files_decode_and_errors_name_the_file() {
        let dir = std::env::temp_dir().join(format!("mrsl-image-texture-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A 3x1 grey PNG: grey expands to r = g = b, alpha 1.
        let path = dir.join("grey.png");
        image::GrayImage::from_raw(3, 1, vec![0, 128, 255]).unwrap().save(&path).unwrap();
        let t = ImageTexture::load(&path, ColorSpace::Linear).unwrap();
        assert_eq!(t.size(), (3, 1));
        assert_eq!(t.levels[0].2, [0, 0, 0, 255, 128, 128, 128, 255, 255, 255, 255, 255]);
        let bad = dir.join("bad.png");
        std::fs::write(&bad, b"not an image").unwrap();
        let e = ImageTexture::load(&bad, ColorSpace::Srgb).unwrap_err();
        assert!(matches!(e, ImageError::Decode { .. }) && e.to_string().contains("bad.png"), "{e}");
        let e = ImageTexture::load(&dir.join("gone.png"), ColorSpace::Srgb).unwrap_err();
        assert!(matches!(e, ImageError::Io { .. }) && e.to_string().contains("gone.png"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
