//! Keys drawn into the heatmaps and error images that `mrslc render`
//! writes: a strip below the image with the colour scale, its tick labels
//! and a caption, so that a PNG read on its own says what its colours mean.
//!
//! The text is drawn by plotters with the bench charts' font
//! (`report::register_font`: Ubuntu Light from `epaint_default_fonts`, since
//! the machines have no system fonts); both crates are already dependencies
//! of `mrslc` for those charts. The strip goes below the image rather than
//! over it, so that every pixel of the map stays visible; the canvas is
//! widened (with white) when the image is too narrow for the key.

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Height of the key strip below the image.
pub const STRIP: u32 = 52;

/// The narrowest canvas the key fits.
pub const MIN_WIDTH: u32 = 520;

/// What a map shows.
pub enum Legend {
    /// The overall heatmap: the fraction of coarse effects evaluated per
    /// pixel (blue 0, yellow 0.5, red 1), green for the 2x2 level.
    Fraction,
    /// One coarse effect's map: blue, green or red.
    Effect(String),
    /// An error image: Magma over the mean absolute difference times `scale`.
    Error { scale: f32 },
    /// A shading-rate image over its frame ([`rate_color`]), tiles of `tile` pixels.
    Rates { tile: u32 },
}

/// The colour of a shading rate in the rate visualisations, after NVIDIA's
/// VRS debug view (by the pixels one shading cell covers): 1x1 none (the
/// frame shows through), 2 pixels (1x2, 2x1) blue, 4 (2x2) green, 8 (2x4,
/// 4x2) yellow, 16 (4x4) red.
pub fn rate_color(rate: mrsl_abi::ShadingRate) -> Option<[u8; 3]> {
    match rate.pixels() {
        1 => None,
        2 => Some([40, 100, 255]),
        4 => Some([30, 200, 60]),
        8 => Some([250, 220, 20]),
        _ => Some([240, 30, 30]),
    }
}

/// The heatmaps' colour for a background pixel, which no mode shades.
pub const BACKGROUND: [u8; 3] = [150, 150, 150];

/// The heatmaps' colour for a pixel where a fraction `f` (0 to 1) of the
/// coarse effects was evaluated per pixel; `level2`: none was, but some came
/// from the dynamic mode's 2x2 level. In the style of He et al.'s heatmaps.
pub fn heat(f: f32, level2: bool) -> [u8; 3] {
    if f <= 0.0 && level2 {
        [60, 190, 80]
    } else if f <= 0.0 {
        [40, 70, 200]
    } else if f < 0.5 {
        let t = f / 0.5;
        [(40.0 + t * 215.0) as u8, (70.0 + t * 150.0) as u8, (200.0 - t * 160.0) as u8]
    } else {
        let t = ((f - 0.5) / 0.5).min(1.0);
        [255, (220.0 - t * 180.0) as u8, 40]
    }
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// `image` with its key drawn below it.
pub fn with_legend(image: &image::RgbImage, legend: &Legend) -> Result<image::RgbImage> {
    crate::report::register_font()?;
    let (w, h) = image.dimensions();
    let (cw, ch) = (w.max(MIN_WIDTH), h + STRIP);
    let mut buffer = vec![255u8; cw as usize * ch as usize * 3];
    for (y, row) in image.as_raw().chunks_exact(w as usize * 3).enumerate() {
        let start = y * cw as usize * 3;
        buffer[start..start + row.len()].copy_from_slice(row);
    }
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (cw, ch)).into_drawing_area();
        draw(&root, legend, h as i32, cw as i32).map_err(|e| anyhow!("drawing the key: {e}"))?;
        root.present().map_err(|e| anyhow!("drawing the key: {e}"))?;
    }
    image::RgbImage::from_raw(cw, ch, buffer).context("the key's canvas has the wrong size")
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type DrawResult = Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

fn draw(root: &Area, legend: &Legend, top: i32, width: i32) -> DrawResult {
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    let (bar_top, bar_bottom) = (top + 6, top + 20);
    match legend {
        Legend::Fraction => {
            let (x0, x1) = (10, width - 240);
            bar(root, (x0, x1), (bar_top, bar_bottom), |t| rgb(heat(t, false)))?;
            ticks(root, (x0, x1), bar_bottom, &[(0.0, "0"), (0.25, "0.25"), (0.5, "0.5"), (0.75, "0.75"), (1.0, "1")])?;
            swatch(root, (width - 225, bar_top), rgb(heat(0.0, true)), "2x2 level")?;
            swatch(root, (width - 115, bar_top), rgb(BACKGROUND), "background")?;
            root.draw(&Text::new(
                "fraction of the coarse effects evaluated per pixel (0: all resampled)",
                (x0, top + 36),
                font.clone(),
            ))?;
        }
        Legend::Effect(name) => {
            swatch(root, (10, bar_top), rgb(heat(0.0, false)), "resampled")?;
            swatch(root, (120, bar_top), rgb(heat(0.0, true)), "from the 2x2 level")?;
            swatch(root, (275, bar_top), rgb(heat(1.0, false)), "evaluated per pixel")?;
            swatch(root, (420, bar_top), rgb(BACKGROUND), "background")?;
            root.draw(&Text::new(format!("coarse effect `{name}`"), (10, top + 32), font.clone()))?;
        }
        Legend::Error { scale } => {
            let (x0, x1) = (10, width - 30);
            bar(root, (x0, x1), (bar_top, bar_bottom), |t| {
                let [r, g, b, _] = mrsl_lab::metrics::magma_rgba8(t);
                RGBColor(r, g, b)
            })?;
            let top_value = 1.0 / scale;
            let labels: Vec<(f32, String)> = (0..=4)
                .map(|k| {
                    let t = k as f32 / 4.0;
                    let label = format!("{}", t * top_value);
                    (t, if k == 4 { format!("{label}+") } else { label })
                })
                .collect();
            let labels: Vec<(f32, &str)> = labels.iter().map(|(t, l)| (*t, l.as_str())).collect();
            ticks(root, (x0, x1), bar_bottom, &labels)?;
            root.draw(&Text::new(
                "mean |mode - reference| over R, G, B (linear values)",
                (x0, top + 36),
                font.clone(),
            ))?;
        }
        Legend::Rates { tile } => {
            use mrsl_abi::ShadingRate as R;
            let keys = [
                (R::R1x1, "1x1 (none)"),
                (R::R1x2, "1x2, 2x1"),
                (R::R2x2, "2x2"),
                (R::R2x4, "2x4, 4x2"),
                (R::R4x4, "4x4"),
            ];
            for (k, (rate, label)) in keys.into_iter().enumerate() {
                // 1x1 has no colour: its swatch is the dimmed frame's grey.
                let color = rate_color(rate).map_or(RGBColor(128, 128, 128), rgb);
                swatch(root, (10 + 82 * k as i32, bar_top), color, label)?;
            }
            root.draw(&Text::new(
                format!("shading rate of each {tile}x{tile} tile, over the frame dimmed"),
                (10, top + 32),
                font.clone(),
            ))?;
        }
    }
    Ok(())
}

/// A horizontal colour bar: `color(t)` for t from 0 (left) to 1 (right).
fn bar(root: &Area, (x0, x1): (i32, i32), (y0, y1): (i32, i32), color: impl Fn(f32) -> RGBColor) -> DrawResult {
    for x in x0..x1 {
        let t = (x - x0) as f32 / (x1 - x0 - 1).max(1) as f32;
        root.draw(&Rectangle::new([(x, y0), (x + 1, y1)], color(t).filled()))?;
    }
    root.draw(&Rectangle::new([(x0 - 1, y0 - 1), (x1, y1)], BLACK))?;
    Ok(())
}

/// Tick marks below a bar and their labels, centred on them.
fn ticks(root: &Area, (x0, x1): (i32, i32), y: i32, labels: &[(f32, &str)]) -> DrawResult {
    let font = ("sans-serif", 12).into_font().color(&BLACK).pos(Pos::new(HPos::Center, VPos::Top));
    for &(t, label) in labels {
        let x = x0 + (t * (x1 - x0 - 1) as f32).round() as i32;
        root.draw(&PathElement::new([(x, y), (x, y + 3)], BLACK))?;
        root.draw(&Text::new(label.to_string(), (x, y + 3), font.clone()))?;
    }
    Ok(())
}

/// A square of `color` and its label to the right.
fn swatch(root: &Area, (x, y): (i32, i32), color: RGBColor, label: &str) -> DrawResult {
    root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], color.filled()))?;
    root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], BLACK))?;
    root.draw(&Text::new(label.to_string(), (x + 19, y), ("sans-serif", 13).into_font().color(&BLACK)))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_is_drawn_below_an_unchanged_image() {
        let image = image::RgbImage::from_fn(64, 40, |x, y| image::Rgb([x as u8 * 3, y as u8 * 5, 7]));
        for legend in [
            Legend::Fraction,
            Legend::Effect("diffuse".into()),
            Legend::Error { scale: 10.0 },
            Legend::Rates { tile: 8 },
        ] {
            let keyed = with_legend(&image, &legend).unwrap();
            assert_eq!(keyed.dimensions(), (MIN_WIDTH, 40 + STRIP));
            for (x, y, p) in image.enumerate_pixels() {
                assert_eq!(keyed.get_pixel(x, y), p, "pixel ({x}, {y}) of the map");
            }
            // The strip holds the scale's colours and dark text, not only white.
            let strip: Vec<&image::Rgb<u8>> = (40..40 + STRIP)
                .flat_map(|y| (0..MIN_WIDTH).map(move |x| (x, y)))
                .map(|(x, y)| keyed.get_pixel(x, y))
                .collect();
            let dark = strip.iter().filter(|p| p.0.iter().all(|&c| c < 60)).count();
            let coloured = strip.iter().filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 60).count();
            assert!(dark > 100 && coloured > 300, "{dark} dark, {coloured} coloured pixels in the key");
        }
    }

    #[test]
    fn rates_are_coloured_by_pixels_per_cell_as_nvidia_shows_them() {
        use mrsl_abi::ShadingRate as R;
        assert_eq!(rate_color(R::R1x1), None);
        assert_eq!(rate_color(R::R1x2), rate_color(R::R2x1));
        assert_eq!(rate_color(R::R2x4), rate_color(R::R4x2));
        let distinct: std::collections::HashSet<_> =
            [R::R1x2, R::R2x2, R::R2x4, R::R4x4].into_iter().filter_map(rate_color).collect();
        assert_eq!(distinct.len(), 4);
        assert_eq!(rate_color(R::R4x4), Some([240, 30, 30]), "4x4 is red");
    }

    #[test]
    fn the_fraction_scale_runs_blue_yellow_red() {
        assert_eq!(heat(0.0, false), [40, 70, 200]);
        assert_eq!(heat(0.0, true), [60, 190, 80]);
        assert_eq!(heat(0.5, false), [255, 220, 40]);
        assert_eq!(heat(1.0, false), [255, 40, 40]);
        // Per-pixel work shows even when some of the 2x2 level was used.
        assert_eq!(heat(1.0, true), [255, 40, 40]);
    }
}
