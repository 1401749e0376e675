//! The files the commands write: outputs as sRGB PNGs, the refinement
//! heatmaps with their keys, and the names they are given.

use crate::legend::{self, Legend};
use anyhow::{Result, anyhow, bail};
use mrsl_lab::color::linear_to_srgb8;
use mrsl_lab::gpu::Gpu;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path`; the error names the file.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// Saves an image; the error names the file.
pub fn save_image<P, C>(image: &image::ImageBuffer<P, C>, path: &Path) -> Result<()>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    image.save(path).map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// `path` with `suffix` before its extension (`out/heat.png`, `.dynamic`:
/// `out/heat.dynamic.png`).
pub fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    if suffix.is_empty() {
        return path.to_path_buf();
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    let ext = path.extension().and_then(|s| s.to_str()).unwrap_or("png");
    path.with_file_name(format!("{stem}{suffix}.{ext}"))
}

/// Writes an output texture as an 8-bit sRGB PNG (the outputs are linear
/// radiance): `rgba32float` as RGB, `r32float` as grey, `rgba8unorm` as
/// stored values over 255; alpha is not kept.
pub fn save_output(gpu: &Gpu, texture: &wgpu::Texture, path: &Path) -> Result<()> {
    save_texels(texture, &gpu.read_texture(texture)?, path)
}

/// [`save_output`] of `texture`'s texels already read back (`bytes`, rows
/// tightly packed).
pub fn save_texels(texture: &wgpu::Texture, bytes: &[u8], path: &Path) -> Result<()> {
    let (w, h) = (texture.width(), texture.height());
    let pixels: Vec<[f32; 4]> = match texture.format() {
        wgpu::TextureFormat::Rgba32Float => bytemuck::pod_collect_to_vec(bytes),
        wgpu::TextureFormat::R32Float => {
            bytemuck::pod_collect_to_vec::<u8, f32>(bytes).into_iter().map(|v| [v, v, v, 1.0]).collect()
        }
        wgpu::TextureFormat::Rgba8Unorm => bytes
            .chunks_exact(4)
            .map(|b| [b[0] as f32 / 255.0, b[1] as f32 / 255.0, b[2] as f32 / 255.0, 1.0])
            .collect(),
        other => bail!("cannot write an output of format {other:?} as PNG yet"),
    };
    let image = image::RgbaImage::from_fn(w, h, |x, y| {
        let p = pixels[(y * w + x) as usize];
        image::Rgba([linear_to_srgb8(p[0]), linear_to_srgb8(p[1]), linear_to_srgb8(p[2]), 255])
    });
    save_image(&image, path)
}

/// Colours each pixel by the rate its coarse effects were shaded at, in the
/// style of He et al.'s heatmaps ([`legend::heat`]): blue = every coarse
/// effect resampled from the first (2x2 or 4x4) level, green = some taken
/// from the dynamic mode's 2x2 level, then yellow to red as the fraction
/// evaluated per pixel grows, grey at a background pixel (never shaded);
/// `only`: one effect's bit (blue, green or red).
/// `rate` is the shader's refine mask (two words a pixel: the refined
/// effects, and those taken from the 2x2 level). The key is drawn below the map.
pub fn save_heatmap(
    gpu: &Gpu,
    rate: &wgpu::Texture,
    effects: usize,
    only: Option<(u32, &str)>,
    path: &Path,
) -> Result<()> {
    let (w, h) = (rate.width(), rate.height());
    let words: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(rate)?);
    let counted = effects.clamp(1, 32) as f32;
    let image = image::RgbImage::from_fn(w, h, |x, y| {
        let [mut mask, mut level2] = words[(y * w + x) as usize];
        if [mask, level2] == mrsl_abi::BACKGROUND_MARK {
            return image::Rgb(legend::BACKGROUND);
        }
        let mut counted = counted;
        if let Some((bit, _)) = only {
            // A single effect: red where it was evaluated per pixel.
            mask = (mask >> bit) & 1;
            level2 = (level2 >> bit) & 1;
            counted = 1.0;
        }
        let f = mask.count_ones() as f32 / counted;
        image::Rgb(legend::heat(f, level2 != 0))
    });
    let key = match only {
        Some((_, effect)) => Legend::Effect(effect.to_string()),
        None => Legend::Fraction,
    };
    save_image(&legend::with_legend(&image, &key)?, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_named_after_a_path_take_the_suffix_before_the_extension() {
        assert_eq!(with_suffix(Path::new("out/heat.png"), ".dynamic"), PathBuf::from("out/heat.dynamic.png"));
        assert_eq!(with_suffix(Path::new("heat.png"), ""), PathBuf::from("heat.png"));
    }
}
