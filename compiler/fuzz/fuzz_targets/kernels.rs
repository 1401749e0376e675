//! Which kernels one execution of the `compile` and `wellformed` targets
//! builds. naga validation dominates the cost of a compile, so validating
//! all the kernels of `Options::default()` (nine then) on every execution made these
//! targets nine times slower; each execution builds the kernels of one mode
//! instead, chosen by the input, so that every kind is still covered across
//! executions (and a finding replays with the same kernels). The proptest
//! smoke of generated programs (compiler/tests/it/fuzz.rs) builds its
//! programs the same way, with this file.

use mrsl::Options;

/// The number of choices [`options`] takes.
pub const CHOICES: usize = 9;

/// The options of choice `k` (`k < CHOICES`): one kernel (the coarse or fine
/// kernel of either block size, the reference, hierarchical or checkerboard
/// kernel), or the dynamic mode's three, or the rate-image mode's two, which
/// `Options` makes together.
pub fn options(k: usize) -> Options {
    let mut o = Options::none();
    match k % CHOICES {
        0 => (o.coarse, o.block_sizes) = (true, vec![2]),
        1 => (o.coarse, o.block_sizes) = (true, vec![4]),
        2 => (o.fine, o.block_sizes) = (true, vec![2]),
        3 => (o.fine, o.block_sizes) = (true, vec![4]),
        4 => o.reference = true,
        5 => o.dynamic = true,
        6 => o.hierarchical = true,
        7 => o.checkerboard = true,
        _ => o.rate_image = true,
    }
    o
}
