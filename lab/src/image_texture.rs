//! The kit's one image pipeline: image files decoded into 8-bit RGBA
//! ([`TextureImage`]), their mip chains ([`mip_chain`]) and the upload of a
//! chain into a texture ([`ImageTexture`]). Both the materials of meshes
//! (glTF images, MTL maps) and the `texture2d` uniforms a scene file binds
//! (`albedo_map = "brick.png"`) go through it.
//!
//! - Formats: PNG, JPEG and TGA (the `image` crate; TGA has no signature, so
//!   a file name settles it). Every image becomes 8-bit RGBA: grey images
//!   expand to r = g = b, images without alpha get a = 1, and 16-bit
//!   channels are rounded to 8 bits.
//! - Encoding: 8-bit colour images are sRGB-encoded by convention, so by
//!   default ([`ColorSpace::Srgb`], [`TexelEncoding::Srgb`]) the texels are
//!   uploaded as `Rgba8UnormSrgb` and the GPU decodes them to linear values
//!   before filtering: `sample` returns linear colour, which is what lighting
//!   needs. Data images (roughness, metalness, masks) are not colours; with
//!   [`ColorSpace::Linear`] (`srgb = false` in a scene file) they are
//!   uploaded as `Rgba8Unorm`, texel values / 255. Normal maps are linear
//!   too, but their mipmaps are renormalised ([`TexelEncoding::Normal`]).
//!   Alpha is linear in all.
//! - Mipmaps: programs `sample` with the level of detail their derivatives
//!   give (a coarse sample spans a whole block), so a texture without mips
//!   would alias. Every level down to 1x1 is made on the CPU by averaging
//!   2x2 texels (a box filter; the last row or column of an odd side is
//!   folded into its neighbours' average, so no texel is dropped), in linear
//!   light for sRGB images so that averaging does not darken them, each
//!   level from the full-precision values of the one above so that rounding
//!   does not accumulate down the chain.

use crate::color::{linear_to_srgb8, srgb_to_linear};
use crate::gpu::Gpu;
use std::path::{Path, PathBuf};

/// Largest side a scene file's image may have: WebGPU's default
/// `max_texture_dimension_2d`.
pub const MAX_SIDE: u32 = 8192;

/// A decoded image: 8-bit RGBA texels, rows top to bottom, exactly as the
/// file stores them (sRGB-encoded or linear is decided by the slot it fills).
#[derive(Clone, PartialEq)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    /// `4 * width * height` bytes.
    pub rgba: Vec<u8>,
    /// Where it came from (a file name or `image N`), for messages.
    pub source: String,
}

impl std::fmt::Debug for TextureImage {
    // The texels would drown any message that prints a mesh.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TextureImage({}, {}x{})", self.source, self.width, self.height)
    }
}

impl TextureImage {
    /// Decodes a PNG, JPEG or TGA file's bytes (the format is sniffed from
    /// the content; `source`, a file name, settles TGA, which has no signature).
    pub fn decode(bytes: &[u8], source: &str) -> Result<TextureImage, String> {
        let format = image::guess_format(bytes).ok().or_else(|| image::ImageFormat::from_path(source).ok());
        let decoded = match format {
            Some(format) => image::load_from_memory_with_format(bytes, format),
            None => image::load_from_memory(bytes),
        }
        .map_err(|e| e.to_string())?;
        let rgba = decoded.to_rgba8();
        let (width, height) = rgba.dimensions();
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        Ok(TextureImage { width, height, rgba: rgba.into_raw(), source: source.to_string() })
    }

    /// Reads and decodes an image file.
    pub fn load(path: &Path) -> Result<TextureImage, String> {
        let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
        TextureImage::decode(&bytes, &path.display().to_string())
    }
}

/// How a texture's texels are encoded, which decides its format and how its
/// mipmaps are averaged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TexelEncoding {
    /// sRGB-encoded RGB, linear alpha (base colour, colour images).
    Srgb,
    /// Linear values (metallic-roughness, data images).
    Linear,
    /// Unit vectors encoded as `n * 0.5 + 0.5` (normal maps): averaged, then renormalised.
    Normal,
}

impl TexelEncoding {
    /// The texture format it is uploaded as.
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            TexelEncoding::Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
            TexelEncoding::Linear | TexelEncoding::Normal => wgpu::TextureFormat::Rgba8Unorm,
        }
    }

    fn decode(self, t: &[u8]) -> [f32; 4] {
        let unorm = |c: usize| f32::from(t[c]) / 255.0;
        match self {
            TexelEncoding::Srgb => [srgb_to_linear(t[0]), srgb_to_linear(t[1]), srgb_to_linear(t[2]), unorm(3)],
            TexelEncoding::Linear => std::array::from_fn(unorm),
            TexelEncoding::Normal => std::array::from_fn(|c| if c < 3 { unorm(c) * 2.0 - 1.0 } else { unorm(c) }),
        }
    }

    fn encode(self, v: [f32; 4]) -> [u8; 4] {
        let unorm = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        match self {
            TexelEncoding::Srgb => [linear_to_srgb8(v[0]), linear_to_srgb8(v[1]), linear_to_srgb8(v[2]), unorm(v[3])],
            TexelEncoding::Linear => v.map(unorm),
            TexelEncoding::Normal => {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let n = if l > 1e-6 { [v[0] / l, v[1] / l, v[2] / l] } else { [0.0, 0.0, 1.0] };
                [unorm(n[0] * 0.5 + 0.5), unorm(n[1] * 0.5 + 0.5), unorm(n[2] * 0.5 + 0.5), unorm(v[3])]
            }
        }
    }
}

/// Every mip level of `image`, level 0 first, down to 1x1: each level's
/// texel is the average of the 2x2 texels below it (a 2x1 or 1x2 pair, or
/// one texel, where a side is already 1; the last row or column of an odd
/// side is folded into its neighbour's average). RGBA bytes per level.
pub fn mip_chain(image: &TextureImage, encoding: TexelEncoding) -> Vec<(u32, u32, Vec<u8>)> {
    let (mut w, mut h) = (image.width, image.height);
    let mut level: Vec<[f32; 4]> = image.rgba.chunks_exact(4).map(|t| encoding.decode(t)).collect();
    let mut out = vec![(w, h, image.rgba.clone())];
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = Vec::with_capacity((nw * nh) as usize);
        for y in 0..nh {
            // Source rows and columns of this texel: two each, three for the
            // last of an odd side (so no source texel is dropped).
            let rows = span(y, nh, h);
            for x in 0..nw {
                let cols = span(x, nw, w);
                let mut sum = [0.0f32; 4];
                let mut count = 0.0;
                for sy in rows.clone() {
                    for sx in cols.clone() {
                        let t = level[(sy * w + sx) as usize];
                        for c in 0..4 {
                            sum[c] += t[c];
                        }
                        count += 1.0;
                    }
                }
                next.push(sum.map(|s| s / count));
            }
        }
        // Each level is encoded from the one above's full-precision values,
        // so rounding does not accumulate down the chain.
        let bytes: Vec<u8> = next.iter().flat_map(|&v| encoding.encode(v)).collect();
        out.push((nw, nh, bytes));
        level = next;
        (w, h) = (nw, nh);
    }
    out
}

/// The source texels along one axis that texel `i` of a level `n` wide
/// averages, from a level `source` wide.
fn span(i: u32, n: u32, source: u32) -> std::ops::Range<u32> {
    if source == 1 {
        return 0..1;
    }
    let start = 2 * i;
    let end = if i + 1 == n { source } else { start + 2 };
    start..end
}

/// How a scene file's image is to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorSpace {
    /// sRGB-encoded colour (the default for images): sampled as linear colour.
    #[default]
    Srgb,
    /// Data, sampled as stored (value / 255).
    Linear,
}

impl ColorSpace {
    pub fn encoding(self) -> TexelEncoding {
        match self {
            ColorSpace::Srgb => TexelEncoding::Srgb,
            ColorSpace::Linear => TexelEncoding::Linear,
        }
    }
}

/// Why a scene file's image could not be made a texture; names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("cannot read image {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot decode image {}: {message} (PNG, JPEG and TGA are supported)", path.display())]
    Decode { path: PathBuf, message: String },
    #[error("image {} is {width}x{height}; the largest side a texture may have is {MAX_SIDE}", path.display())]
    TooLarge { path: PathBuf, width: u32, height: u32 },
}

/// An image's mip chain, ready to upload.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageTexture {
    pub encoding: TexelEncoding,
    /// Level 0 first; each `(width, height, rgba8 texels)`, down to 1x1.
    pub levels: Vec<(u32, u32, Vec<u8>)>,
}

impl ImageTexture {
    /// `image` with its mip chain for `encoding`.
    pub fn new(image: &TextureImage, encoding: TexelEncoding) -> ImageTexture {
        ImageTexture { encoding, levels: mip_chain(image, encoding) }
    }

    /// Decodes the image file at `path` (a scene file's image; at most
    /// [`MAX_SIDE`] on a side).
    pub fn load(path: &Path, color_space: ColorSpace) -> Result<ImageTexture, ImageError> {
        let bytes = std::fs::read(path).map_err(|source| ImageError::Io { path: path.to_path_buf(), source })?;
        let image = TextureImage::decode(&bytes, &path.display().to_string())
            .map_err(|message| ImageError::Decode { path: path.to_path_buf(), message })?;
        if image.width > MAX_SIDE || image.height > MAX_SIDE {
            return Err(ImageError::TooLarge { path: path.to_path_buf(), width: image.width, height: image.height });
        }
        Ok(ImageTexture::new(&image, color_space.encoding()))
    }

    /// The size of level 0.
    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].0, self.levels[0].1)
    }

    /// The texture format it is uploaded as.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.encoding.format()
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

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, rgba: Vec<u8>) -> TextureImage {
        TextureImage { width, height, rgba, source: "test".into() }
    }

    #[test]
    fn the_mip_chain_goes_down_to_one_texel() {
        let t = ImageTexture::new(&image(5, 2, vec![100; 5 * 2 * 4]), TexelEncoding::Linear);
        let sizes: Vec<(u32, u32)> = t.levels.iter().map(|(w, h, _)| (*w, *h)).collect();
        assert_eq!(sizes, [(5, 2), (2, 1), (1, 1)]);
        for (w, h, data) in &t.levels {
            assert_eq!(data.len(), (w * h * 4) as usize);
            assert!(data.iter().all(|&v| v == 100), "a flat image stays flat");
        }
        assert_eq!(t.format(), wgpu::TextureFormat::Rgba8Unorm);
    }

    #[test]
    fn srgb_images_are_averaged_in_linear_light() {
        // Black and white texels: the mean of their light is half white,
        // which sRGB encodes as 188, not 128 (averaging the encoded values
        // would darken every minified texture).
        let texels = [[0u8, 0, 0, 255], [255, 255, 255, 255], [0, 0, 0, 255], [255, 255, 255, 255]].concat();
        let srgb = ImageTexture::new(&image(2, 2, texels.clone()), TexelEncoding::Srgb);
        assert_eq!(srgb.levels[1].2, [188, 188, 188, 255]);
        assert_eq!(srgb.format(), wgpu::TextureFormat::Rgba8UnormSrgb);
        let linear = ImageTexture::new(&image(2, 2, texels), TexelEncoding::Linear);
        assert_eq!(linear.levels[1].2, [128, 128, 128, 255]);
    }

    #[test]
    fn a_black_and_white_checker_minifies_to_half_linear_light() {
        let n = 8u32;
        let rgba: Vec<u8> = (0..n * n)
            .flat_map(|i| {
                let v = if (i % n + i / n).is_multiple_of(2) { 255 } else { 0 };
                [v, v, v, 255]
            })
            .collect();
        let chain = mip_chain(&image(n, n, rgba), TexelEncoding::Srgb);
        assert_eq!(chain.iter().map(|l| (l.0, l.1)).collect::<Vec<_>>(), [(8, 8), (4, 4), (2, 2), (1, 1)]);
        // Half the light: sRGB 188, not the 128 that averaging bytes gives.
        assert!(chain[1].2.chunks_exact(4).all(|t| t == [188, 188, 188, 255]), "{:?}", &chain[1].2[..8]);
        assert_eq!(&chain[3].2, &[188, 188, 188, 255]);
    }

    #[test]
    fn odd_sides_keep_every_texel_and_normals_stay_unit() {
        // 3x1: one level of 1x1 averaging all three texels.
        let chain = mip_chain(&image(3, 1, vec![0, 0, 0, 0, 30, 0, 0, 0, 60, 0, 0, 0]), TexelEncoding::Linear);
        assert_eq!(chain.len(), 2);
        assert_eq!(chain[1].2, vec![30, 0, 0, 0]);
        // Two normals tilted apart average to +z, renormalised.
        let a = [(0.6f32 * 0.5 + 0.5) * 255.0, 127.5, (0.8f32 * 0.5 + 0.5) * 255.0].map(|v| v.round() as u8);
        let b = [(-0.6f32 * 0.5 + 0.5) * 255.0, 127.5, (0.8f32 * 0.5 + 0.5) * 255.0].map(|v| v.round() as u8);
        let normals = image(2, 1, vec![a[0], a[1], a[2], 255, b[0], b[1], b[2], 255]);
        let top = &mip_chain(&normals, TexelEncoding::Normal)[1].2;
        assert!((top[0] as i32 - 128).abs() <= 1 && top[2] == 255, "{top:?}");
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
