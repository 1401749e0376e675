//! Time measurement shared by `render --compare`, `render --frames`,
//! `bench` and the ablation: one warm run timed (on a GPU by its
//! timestamps, on a CPU device from encoding to idle), runs paired with
//! reference runs, and the median.
//!
//! A shared machine has slow moments; pairing each run of a mode with a
//! reference run beside it, alternately after and before it, makes a slow
//! moment weigh on both members of a pair, so the median of the per-pair
//! ratios says how fast the mode is relative to the reference even where
//! the absolute times drift.

use anyhow::Result;
use mrsl_lab::gpu::Gpu;
use mrsl_runtime::{Bindings, DispatchOptions, Shader};
use std::time::Instant;

/// Runs of each mode paired with reference runs for the timing of
/// `render --compare` and `render --frames`.
pub const PAIRS: usize = 3;

/// One run of `options`, in ms: on a GPU with timestamp queries the span
/// of its passes' timestamps (the first pass's beginning to the last one's
/// end: the shading work, without the encoding, submission and wait that a
/// wall clock adds to a frame of a millisecond or two); elsewhere, and on a
/// CPU device such as lavapipe, whose timestamps do not measure the shader
/// work (docs/runtime.md, section 9), its wall time from encoding to idle.
/// [`clock`] says which.
pub fn time_run(gpu: &Gpu, shader: &mut Shader, bindings: &Bindings, options: DispatchOptions) -> Result<f64> {
    let start = Instant::now();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    shader.encode(&gpu.device, &gpu.queue, &mut encoder, bindings, options)?;
    gpu.queue.submit([encoder.finish()]);
    gpu.device.poll(wgpu::PollType::wait_indefinitely())?;
    let wall = start.elapsed().as_secs_f64() * 1e3;
    if clock(gpu) == Clock::GpuTimestamps {
        // The period is the queue's: set here so that no caller can forget it.
        shader.set_timestamp_period(&gpu.queue);
        if let Some(timings) = shader.read_timings(&gpu.device)? {
            return Ok(timings.total_ms);
        }
    }
    Ok(wall)
}

/// What [`time_run`] measures on a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// The span of the passes' timestamps (a GPU with timestamp queries).
    GpuTimestamps,
    /// Wall time from encoding to idle.
    Wall,
}

impl Clock {
    /// How the reports name it.
    pub fn describe(self) -> &'static str {
        match self {
            Clock::GpuTimestamps => "GPU time (the span of the passes' timestamps)",
            Clock::Wall => "wall time from encoding to idle",
        }
    }

    /// The short name a line of progress gives a time.
    pub fn short(self) -> &'static str {
        match self {
            Clock::GpuTimestamps => "GPU time",
            Clock::Wall => "warm wall time",
        }
    }
}

/// The clock [`time_run`] uses on `gpu`.
pub fn clock(gpu: &Gpu) -> Clock {
    let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    if timestamps && gpu.adapter_info.device_type != wgpu::DeviceType::Cpu { Clock::GpuTimestamps } else { Clock::Wall }
}

/// Runs `time` until the device is warm: at least [`WARM_UP_MIN`] runs,
/// then until two consecutive runs agree within 10%, at most
/// [`WARM_UP_MAX`]. The first runs after a scene is loaded can be slow
/// (once measured on lavapipe: the reference at 960x540 took 340 ms for
/// six runs, then 175-180 ms), which one warm-up run does not cover and
/// which would weigh on the first mode measured.
///
/// It also runs for at least [`WARM_UP_WALL`] of wall time: a GPU raises
/// its clock only under load sustained for some milliseconds, and runs of
/// a millisecond at its idle clock agree with each other too.
pub fn warm_up(mut time: impl FnMut() -> Result<f64>) -> Result<()> {
    let start = Instant::now();
    let mut last = time()?;
    for run in 1..WARM_UP_MAX {
        let now = time()?;
        let settled = run + 1 >= WARM_UP_MIN && (now - last).abs() <= 0.1 * last.min(now);
        if settled && start.elapsed() >= WARM_UP_WALL {
            break;
        }
        last = now;
    }
    while start.elapsed() < WARM_UP_WALL {
        time()?;
    }
    Ok(())
}

/// The least wall time [`warm_up`] runs for.
pub const WARM_UP_WALL: std::time::Duration = std::time::Duration::from_millis(300);

/// The fewest warm-up runs of [`warm_up`].
pub const WARM_UP_MIN: usize = 3;

/// The most warm-up runs of [`warm_up`].
pub const WARM_UP_MAX: usize = 20;

/// The wall times of `pairs` runs of `options` and each run's ratio to the
/// reference run paired with it.
pub struct Paired {
    pub walls: Vec<f64>,
    pub ratios: Vec<f64>,
    /// The wall times of the reference runs, pair by pair.
    pub reference_walls: Vec<f64>,
}

/// Times `pairs` runs of `options` with `time`, each paired with a run of
/// `reference`: the reference first in even pairs, second in odd ones.
pub fn paired(
    pairs: usize,
    options: DispatchOptions,
    reference: DispatchOptions,
    mut time: impl FnMut(DispatchOptions) -> Result<f64>,
) -> Result<Paired> {
    let (mut walls, mut ratios, mut reference_walls) = (vec![], vec![], vec![]);
    for pair in 0..pairs {
        let (wall, reference_wall) = if pair % 2 == 0 {
            let r = time(reference)?;
            (time(options)?, r)
        } else {
            let w = time(options)?;
            (w, time(reference)?)
        };
        walls.push(wall);
        ratios.push(wall / reference_wall);
        reference_walls.push(reference_wall);
    }
    Ok(Paired { walls, ratios, reference_walls })
}

/// The median (the mean of the middle two for an even count); NaN for none.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrsl_runtime::Mode;

    #[test]
    fn the_median_of_odd_even_and_no_values() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(vec![]).is_nan());
    }

    #[test]
    fn pairs_alternate_which_run_goes_first() {
        let mut order = vec![];
        let mode = DispatchOptions::new(Mode::Coarse4x4);
        let reference = DispatchOptions::new(Mode::Reference);
        let p = paired(3, mode, reference, |o| {
            order.push(o.mode);
            Ok(if o.mode == Mode::Reference { 4.0 } else { 1.0 })
        })
        .unwrap();
        use Mode::{Coarse4x4 as M, Reference as R};
        assert_eq!(order, [R, M, M, R, R, M]);
        assert_eq!((p.walls, p.ratios), (vec![1.0; 3], vec![0.25; 3]));
    }
}
