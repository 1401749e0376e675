//! Micro-benchmark: which untaken branches llvmpipe skips. The same
//! straight-line work per pixel at 1920x1080 (8x8 workgroups) runs always,
//! and under conditions no pixel meets: an `if` on a texel each lane loads;
//! an `if` and a `loop` on a value the workgroup's lanes agreed on through
//! workgroup memory (`workgroupUniformLoad`); an `if` on a word indexed by
//! the workgroup, of a read-only storage buffer and of a uniform buffer;
//! and an `if` on a uniform-buffer word at a fixed place. `barrier_only`
//! is the agreement without the work. docs/eval/evaluation.md ("What llvmpipe
//! charges for") holds a run.
//!
//! `cargo run --release -p mrsl-lab --example uniform_branch [ROUNDS]`
//!
//! The kernels run interleaved (the order rotates every round), each timed
//! over 4 dispatches; it prints each kernel's median time and the median
//! over rounds of its time above the kernel without the work.

use mrsl_lab::microbench;

const SIZE: (u32, u32) = (1920, 1080);
const DISPATCHES: u32 = 4;
const KERNELS: [&str; 9] = [
    "none",
    "always",
    "lane_if",
    "uniform_if",
    "uniform_loop",
    "barrier_only",
    "buffer_if",
    "uniform_buffer_if",
    "dispatch_if",
];

fn main() {
    let (gpu, rounds) = microbench::start();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let texture = |label, format, texel: u32, fill: fn(u32) -> u32| {
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: SIZE.0 + 8, height: SIZE.1 + 8, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let data: Vec<u32> = (0..(SIZE.0 + 8) * (SIZE.1 + 8) * texel / 4).map(fill).collect();
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some((SIZE.0 + 8) * texel),
            rows_per_image: Some(SIZE.1 + 8),
        };
        queue.write_texture(t.as_image_copy(), bytemuck::cast_slice(&data), layout, t.size());
        t
    };
    let floats = texture("floats", wgpu::TextureFormat::Rgba32Float, 16, |i| ((i % 97) as f32 / 97.0).to_bits());
    let flags = texture("flags", wgpu::TextureFormat::R32Uint, 4, |_| 0);
    let (floats_view, flags_view) = (floats.create_view(&Default::default()), flags.create_view(&Default::default()));
    let zeros = |usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile flags"),
            size: 65536,
            usage,
            mapped_at_creation: false,
        })
    };
    let tile_flags = zeros(wgpu::BufferUsages::STORAGE);
    let tile_flags_uniform = zeros(wgpu::BufferUsages::UNIFORM);
    let out = gpu.output_texture("out", SIZE, wgpu::TextureFormat::R32Uint);
    let out_view = out.create_view(&Default::default());
    let kernels = microbench::kernels(&gpu, "uniform_branch", include_str!("uniform_branch.wgsl"), &KERNELS, |name| {
        let view = |v| wgpu::BindingResource::TextureView(v);
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 1, resource: view(&flags_view) },
            wgpu::BindGroupEntry { binding: 3, resource: view(&out_view) },
        ];
        if name != "none" && name != "barrier_only" {
            entries.push(wgpu::BindGroupEntry { binding: 0, resource: view(&floats_view) });
        }
        match name {
            "buffer_if" => entries.push(wgpu::BindGroupEntry { binding: 4, resource: tile_flags.as_entire_binding() }),
            "uniform_buffer_if" | "dispatch_if" => {
                entries.push(wgpu::BindGroupEntry { binding: 5, resource: tile_flags_uniform.as_entire_binding() })
            }
            _ => {}
        }
        entries
    });
    let times = microbench::time_kernels(&gpu, &kernels, (SIZE.0 / 8, SIZE.1 / 8), DISPATCHES, rounds);
    microbench::report_above_first(&KERNELS, &times, "above none");
}
