//! The timing the lab's microbenchmarks share (`lab/examples/record_loads.rs`,
//! `record_access.rs`, `uniform_branch.rs`, `uniform_loads.rs`): kernels timed in interleaved
//! rounds, and medians over the rounds.

/// Times each of `kernels` once to warm up, then `rounds` times in
/// interleaved rounds whose order rotates every round, so that a shared
/// machine's slow moments weigh on every kernel; the times per kernel.
pub fn interleaved_rounds(kernels: usize, rounds: usize, mut time: impl FnMut(usize) -> f64) -> Vec<Vec<f64>> {
    (0..kernels).for_each(|k| {
        time(k);
    });
    let mut times = vec![vec![]; kernels];
    for round in 0..rounds {
        for k in 0..kernels {
            let k = (k + round) % kernels;
            times[k].push(time(k));
        }
    }
    times
}

/// The median of `values` (the upper one of an even count); NaN when empty.
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The median over rounds of kernel `times`' time above `baseline`'s in
/// the same round.
pub fn median_above(times: &[f64], baseline: &[f64]) -> f64 {
    median(&times.iter().zip(baseline).map(|(t, b)| t - b).collect::<Vec<_>>())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_rotate_and_medians_take_the_middle() {
        let mut order = vec![];
        let times = interleaved_rounds(3, 2, |k| {
            order.push(k);
            k as f64
        });
        // Warm-up 0 1 2, then 0 1 2, then 1 2 0.
        assert_eq!(order, [0, 1, 2, 0, 1, 2, 1, 2, 0]);
        assert_eq!(times, [vec![0.0, 0.0], vec![1.0, 1.0], vec![2.0, 2.0]]);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median_above(&[5.0, 9.0, 4.0], &[1.0, 2.0, 3.0]), 4.0);
        assert!(median(&[]).is_nan());
    }
}
