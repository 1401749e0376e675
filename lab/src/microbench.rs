//! What the lab's microbenchmarks share (`lab/examples/record_loads.rs`,
//! `record_access.rs`, `uniform_branch.rs`, `uniform_loads.rs`): the device
//! and the rounds from the command line, a kernel per entry point of one WGSL
//! source, kernels timed in interleaved rounds,
//! medians over the rounds and the report of each kernel's time above the
//! first's.

use crate::gpu::Gpu;

/// A microbenchmark's start: the rounds (the first command-line argument,
/// else 9) and the device, whose adapter it prints.
pub fn start() -> (Gpu, usize) {
    start_on(Gpu::new())
}

/// [`start`] on a device that grants read-write `Rgba32Uint` storage where
/// the adapter has it ([`Gpu::with_packed_records`]): what reading records
/// as the hierarchical kernel's packed records needs.
pub fn start_packing_records() -> (Gpu, usize) {
    start_on(Gpu::with_packed_records(wgpu::Limits::default().max_storage_textures_per_shader_stage))
}

fn start_on(gpu: Result<Gpu, crate::gpu::GpuError>) -> (Gpu, usize) {
    let rounds: usize = std::env::args().nth(1).map_or(9, |a| a.parse().expect("ROUNDS is a number"));
    let gpu = gpu.unwrap_or_else(|e| panic!("{e}"));
    println!("adapter: {} ({:?})", gpu.adapter_info.name, gpu.adapter_info.backend);
    (gpu, rounds)
}

/// A microbenchmark's kernel: its pipeline and bind group 0.
pub type Kernel = (wgpu::ComputePipeline, wgpu::BindGroup);

/// A kernel per name in `names`: the entry point `{name}_main` of the WGSL
/// `source`, with bind group 0 made of `entries(name)`.
pub fn kernels<'a>(
    gpu: &Gpu,
    label: &str,
    source: &str,
    names: &[&str],
    mut entries: impl FnMut(&str) -> Vec<wgpu::BindGroupEntry<'a>>,
) -> Vec<Kernel> {
    let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    names.iter().map(|name| gpu.entry_kernel(&module, &format!("{name}_main"), &entries(name))).collect()
}

/// Times `kernels` over `workgroups`, each `dispatches` times per timing, in
/// `rounds` interleaved rounds: the times per kernel.
pub fn time_kernels(
    gpu: &Gpu,
    kernels: &[Kernel],
    workgroups: (u32, u32),
    dispatches: u32,
    rounds: usize,
) -> Vec<Vec<f64>> {
    interleaved_rounds(kernels.len(), rounds, |k| {
        gpu.time_dispatches(&kernels[k].0, &kernels[k].1, workgroups, dispatches)
    })
}

/// Prints each kernel's median time and the median over rounds of its time
/// above the first kernel's (`above`: what that difference is).
pub fn report_above_first(names: &[&str], times: &[Vec<f64>], above: &str) {
    let width = names.iter().map(|n| n.len()).max().unwrap_or(0);
    for (k, name) in names.iter().enumerate() {
        let extra = median_above(&times[k], &times[0]);
        println!(
            "{name:>width$}: {:6.1} ms, {above} {extra:5.1} ms (median of {} rounds)",
            median(&times[k]),
            times[k].len()
        );
    }
}

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
