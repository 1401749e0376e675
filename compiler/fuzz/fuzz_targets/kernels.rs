//! Which kernels one execution of the `compile` and `wellformed` targets
//! builds. naga validation dominates the cost of a compile, so validating
//! all the kernels of `Options::default()` (fifteen) on every execution made these
//! targets many times slower; each execution builds the kernels of one mode
//! instead, chosen by the input, so that every kind is still covered across
//! executions (and a finding replays with the same kernels). The proptest
//! smoke of generated programs (compiler/tests/it/fuzz.rs) builds its
//! programs the same way, with this file.

use mrsl::{Mode, Options};

/// The number of choices [`options`] takes.
pub const CHOICES: usize = Mode::ALL.len();

/// The options of choice `k` (`k < CHOICES`): the kernels of one mode.
pub fn options(k: usize) -> Options {
    Options::for_modes(&[Mode::ALL[k % CHOICES]])
}
