//! Micro-benchmark: what a load costs a lane on llvmpipe when its address is
//! the same for many lanes. 16 four-word loads per pixel at 1920x1080 (8x8
//! workgroups), at addresses that differ per lane, that a row of eight lanes
//! shares (one llvmpipe SIMD vector: how the block fine kernel's lanes share
//! a block's corners), or that depend on the workgroup id alone, from a
//! read-only `rgba32uint` storage texture, a read-only storage buffer and (the
//! last) a uniform buffer; `arithmetic` is the same sum over values made
//! without a load. docs/eval/evaluation.md ("What llvmpipe charges for")
//! holds a run.
//!
//! `cargo run --release -p mrsl-lab --example uniform_loads [ROUNDS]`
//!
//! The kernels run interleaved (the order rotates every round), each timed
//! over 4 dispatches; it prints each kernel's median time and the median
//! over rounds of its time above the store-only kernel's.

use mrsl_lab::microbench;

const SIZE: (u32, u32) = (1920, 1080);
/// Texels per row of the texture and words per row of the buffer (`ROW` in
/// the kernels): the image's width and the 16 loads past it.
const ROW: u32 = 2048;
const DISPATCHES: u32 = 4;
const KERNELS: [&str; 9] = [
    "none",
    "arithmetic",
    "lane_texel",
    "row_texel",
    "group_texel",
    "lane_buffer",
    "row_buffer",
    "group_buffer",
    "group_uniform",
];

fn main() {
    let (gpu, rounds) = microbench::start();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let data: Vec<u32> = (0..ROW * SIZE.1 * 4).map(|i| i.wrapping_mul(2_654_435_761)).collect();
    let texels = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("texels"),
        size: wgpu::Extent3d { width: ROW, height: SIZE.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Uint,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let layout = wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(ROW * 16), rows_per_image: Some(SIZE.1) };
    queue.write_texture(texels.as_image_copy(), bytemuck::cast_slice(&data), layout, texels.size());
    let buffer = |usage, words: &[u32]| {
        let b = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("words"),
            size: (words.len() * 4) as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&b, 0, bytemuck::cast_slice(words));
        b
    };
    let words = buffer(wgpu::BufferUsages::STORAGE, &data);
    let constants = buffer(wgpu::BufferUsages::UNIFORM, &data[..4096 * 4]);
    let texels_view = texels.create_view(&Default::default());
    let out = gpu.output_texture("out", SIZE, wgpu::TextureFormat::R32Uint);
    let out_view = out.create_view(&Default::default());
    let kernels = microbench::kernels(&gpu, "uniform_loads", include_str!("uniform_loads.wgsl"), &KERNELS, |name| {
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&out_view) }];
        if name.ends_with("texel") {
            entries
                .push(wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&texels_view) });
        } else if name.ends_with("buffer") {
            entries.push(wgpu::BindGroupEntry { binding: 1, resource: words.as_entire_binding() });
        } else if name.ends_with("uniform") {
            entries.push(wgpu::BindGroupEntry { binding: 2, resource: constants.as_entire_binding() });
        }
        entries
    });
    let times = microbench::time_kernels(&gpu, &kernels, (SIZE.0 / 8, SIZE.1 / 8), DISPATCHES, rounds);
    microbench::report_above_first(&KERNELS, &times, "loads");
}
