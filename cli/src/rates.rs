//! The shading-rate image of the rate-image mode for the tools' still
//! frames. The runtime's rate source (VALAR's decision) reads the previous
//! frame; a still frame has none, so the tools render the frames a still
//! camera would show: the reference image of the view as frame 0, then
//! rate-image frames, each deciding its rates from the one before, until the
//! rate image settles: at most [`SETTLED_FRACTION`] of the tiles change
//! from one frame to the next (the source's damping coarsens a tile only
//! after three frames agree, so this takes a few frames; a few tiles on the
//! threshold may keep alternating between two rates when each frame's small
//! resampling error tips them).

use crate::timing::median;
use anyhow::{Context, Result};
use mrsl_abi::ShadingRate;
use mrsl_lab::gpu::Gpu;
use mrsl_runtime::rate_source::{RateInputs, RateOptions, RateSource, read_rate_image};
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};
use std::time::Instant;

/// Frames after which the tools stop waiting for the rate image to settle.
pub const MAX_FRAMES: usize = 8;

/// The fraction of tiles that may still change when the rate image counts as settled.
pub const SETTLED_FRACTION: f64 = 0.005;

/// The settled rate image and what it took.
pub struct Settled {
    /// Rate-image frames rendered before the rate image stopped changing.
    pub frames: usize,
    /// Whether it settled within [`MAX_FRAMES`].
    pub stable: bool,
    /// Tiles that changed between the last two decisions.
    pub changed: usize,
    /// Tiles at each rate, finest first.
    pub histogram: Vec<(ShadingRate, usize)>,
    /// Warm wall time of one rate-source pass, in ms (median of 3).
    pub source_ms: f64,
}

impl Settled {
    /// One line for the log: `rates after 4 frames: 1x1 12%, 2x2 30%, ...`.
    pub fn describe(&self) -> String {
        let tiles: usize = self.histogram.iter().map(|(_, n)| n).sum();
        let parts: Vec<String> = self
            .histogram
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(r, n)| format!("{r} {:.0}%", 100.0 * *n as f64 / tiles.max(1) as f64))
            .collect();
        let settled = if self.stable { "settled after" } else { "still changing after" };
        format!(
            "shading rates {settled} {} frames of a still camera ({} of {tiles} tiles changed in the last): {} (rate source {:.1} ms warm wall time)",
            self.frames,
            self.changed,
            parts.join(", "),
            self.source_ms
        )
    }
}

/// Settles the rate image in `bindings.shading_rate` for the view of
/// `bindings`: renders the reference into `color` (the program's first
/// output), then alternates the rate source and rate-image frames. `dispatch`
/// gives the rate-image frames' other options (forced refinement, ...).
pub fn settle(
    gpu: &Gpu,
    shader: &mut Shader,
    bindings: &Bindings,
    color: &wgpu::Texture,
    options: &RateOptions,
    dispatch: DispatchOptions,
) -> Result<Settled> {
    let target = bindings.shading_rate.context("the rate-image mode has no shading-rate image")?;
    let submit = |shader: &mut Shader, mode: Mode| -> Result<()> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let options = DispatchOptions { mode, rate_tile: options.tile, ..dispatch };
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, options)?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    };
    let mut source = RateSource::new(&gpu.device)?;
    let decide = |source: &mut RateSource| -> Result<f64> {
        // The frame before must be done, or its time would count as the source's.
        gpu.device.poll(wgpu::PollType::wait_indefinitely())?;
        let start = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        source.encode(&gpu.device, &mut encoder, &RateInputs::new(color), options, target)?;
        gpu.queue.submit([encoder.finish()]);
        gpu.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    };
    submit(shader, Mode::Reference)?;
    let mut previous: Option<Vec<ShadingRate>> = None;
    let (mut frames, mut stable, mut changed) = (0, false, 0);
    let mut times = vec![];
    while frames < MAX_FRAMES {
        times.push(decide(&mut source)?);
        let rates = read_rate_image(&gpu.device, &gpu.queue, target)?;
        if let Some(previous) = &previous {
            changed = previous.iter().zip(&rates).filter(|(a, b)| a != b).count();
            if changed as f64 <= SETTLED_FRACTION * rates.len() as f64 {
                stable = true;
                break;
            }
        }
        previous = Some(rates);
        submit(shader, Mode::RateImage)?;
        frames += 1;
    }
    let rates = previous.unwrap_or_default();
    let histogram = ShadingRate::ALL.iter().map(|&r| (r, rates.iter().filter(|x| **x == r).count())).collect();
    // The first decisions build pipelines and history; time the last ones.
    let warm: Vec<f64> = times.iter().rev().take(3).copied().collect();
    Ok(Settled { frames, stable, changed, histogram, source_ms: median(warm) })
}

/// Sets every tile of `target` (an `R32Uint` rate image) to `rate`. The
/// target is the rate image the shader is bound to
/// (`mrsl_runtime::rate_source::create_rate_image`), written in place: the
/// runtime's `upload_rate_image` makes a new `R8Uint` texture instead.
pub fn fill(gpu: &Gpu, target: &wgpu::Texture, rate: ShadingRate) {
    let (w, h) = (target.width(), target.height());
    let codes = vec![u32::from(rate.code()); (w * h) as usize];
    gpu.queue.write_texture(
        target.as_image_copy(),
        &codes.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>(),
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(w * 4), rows_per_image: Some(h) },
        target.size(),
    );
}
