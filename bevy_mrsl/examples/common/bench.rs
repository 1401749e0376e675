//! Times the mrsl pass inside the example's Bevy app: blocks of frames
//! without bevy_mrsl, in the reference and in an adaptive mode, interleaved
//! (off, reference, adaptive, off, ...), statistics off. The pass's cost in a
//! mode is its block's frame time less the neighbouring block without it;
//! each round gives one ratio of the reference's cost to the mode's, and the
//! median of those ratios is the speedup (as `mrslc bench` pairs runs).

use super::{Scene, SceneSetup, app};
use bevy::app::AppExit;
use bevy::prelude::*;
use bevy_mrsl::{Mode, MrslCamera};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Frames at the start of a block left out: the switch itself.
const SETTLE: u32 = 3;
/// Frames before the first block: pipelines compile, caches warm.
const WARM_UP: u32 = 60;

/// Mean frame times in milliseconds, one per block, by configuration.
#[derive(Debug, Default, Clone)]
pub struct BenchTimes {
    pub off: Vec<f64>,
    pub reference: Vec<f64>,
    pub adaptive: Vec<f64>,
}

impl BenchTimes {
    /// The median over rounds of (reference - off) / (adaptive - off).
    pub fn pass_speedup(&self) -> f64 {
        let ratios =
            (0..self.rounds()).map(|i| (self.reference[i] - self.off[i]) / (self.adaptive[i] - self.off[i]).max(1e-6));
        median(ratios.collect())
    }

    /// The median over rounds of the reference frame's time over the adaptive frame's.
    pub fn frame_speedup(&self) -> f64 {
        median((0..self.rounds()).map(|i| self.reference[i] / self.adaptive[i]).collect())
    }

    pub fn rounds(&self) -> usize {
        self.off.len().min(self.reference.len()).min(self.adaptive.len())
    }
}

pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Block {
    Off,
    Reference,
    Adaptive,
}

#[derive(Resource)]
struct Bench {
    mode: Mode,
    rounds: usize,
    frames: u32,
    warm: bool,
    block: usize,
    frame: u32,
    started: Option<Instant>,
    times: BenchTimes,
    removed: Option<MrslCamera>,
    result: Arc<Mutex<Option<BenchTimes>>>,
}

/// Runs `rounds` rounds of three blocks of `frames` frames each at `size`.
pub fn bench(size: (u32, u32), scene: &Scene, mode: Mode, rounds: usize, frames: u32) -> Result<BenchTimes, String> {
    let result = Arc::new(Mutex::new(None));
    let state = Bench {
        mode,
        rounds,
        frames: frames.max(SETTLE + 1),
        warm: false,
        block: 0,
        frame: 0,
        started: None,
        times: BenchTimes::default(),
        removed: None,
        result: Arc::clone(&result),
    };
    app(size, scene)?.insert_resource(state).add_systems(Update, step).run();
    let times = result.lock().unwrap().take();
    times.ok_or_else(|| "the app stopped before the benchmark ended".into())
}

fn step(
    mut commands: Commands,
    mut bench: ResMut<Bench>,
    setup: Res<SceneSetup>,
    mut cameras: Query<(Entity, Option<&mut MrslCamera>), With<Camera>>,
    mut exit: MessageWriter<AppExit>,
) {
    let Ok((entity, camera)) = cameras.single_mut() else { return };
    bench.frame += 1;
    if !bench.warm {
        if bench.frame < WARM_UP {
            if let Some(mut camera) = camera {
                camera.statistics = false;
            }
            return;
        }
        bench.warm = true;
        bench.frame = 1;
    }
    let kind = [Block::Off, Block::Reference, Block::Adaptive][bench.block % 3];
    // 0 on the first frame of a block.
    let in_block = bench.frame - 1;
    if in_block == 0 {
        // The first frame of the block: switch.
        match (kind, camera) {
            (Block::Off, Some(camera)) => {
                bench.removed = Some(camera.clone());
                commands.entity(entity).remove::<MrslCamera>();
            }
            (Block::Reference | Block::Adaptive, _) => {
                let mut settings =
                    bench.removed.take().unwrap_or_else(|| MrslCamera::new(setup.program.clone(), bench.mode));
                settings.mode = if kind == Block::Reference { Mode::Reference } else { bench.mode };
                settings.statistics = false;
                commands.entity(entity).insert(settings);
            }
            _ => {}
        }
    } else if in_block == SETTLE {
        bench.started = Some(Instant::now());
    } else if in_block == bench.frames {
        let elapsed = bench.started.take().map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
        let mean = elapsed / f64::from(bench.frames - SETTLE);
        match kind {
            Block::Off => bench.times.off.push(mean),
            Block::Reference => bench.times.reference.push(mean),
            Block::Adaptive => bench.times.adaptive.push(mean),
        }
        bench.block += 1;
        bench.frame = 0;
        if bench.block == 3 * bench.rounds {
            *bench.result.lock().unwrap() = Some(bench.times.clone());
            exit.write(AppExit::Success);
        }
    }
}
