//! Micro-benchmark behind the block modes' record texture: what reading the
//! four coarse samples' records around a block costs each fine-kernel lane
//! as storage-buffer words, as texels of a sampled `rgba32uint` texture
//! array (what the block modes bind) and as the same texels through a
//! read-only storage binding, at 1920x1080 with two pixels per lane and six
//! words per record (the sponza_lights workload's figures).
//!
//! `cargo run --release -p mrsl-lab --example record_loads [ROUNDS]`
//!
//! The four kernels run interleaved (the order rotates every round), each
//! timed over 4 dispatches; it prints the median time of each and the
//! median over rounds of each load kernel's time above the store-only
//! kernel's, so that a slow moment of a shared machine weighs on all four.

use mrsl_lab::microbench;

const SIZE: (u32, u32) = (1920, 1080);
const BLOCK: u32 = 4;
const STRIDE: u32 = 6;
const LAYERS: u32 = STRIDE.div_ceil(4);
const DISPATCHES: u32 = 4;
const KERNELS: [&str; 4] = ["none", "buffer", "texture", "storage"];

fn main() {
    let (gpu, rounds) = microbench::start();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let grid = (SIZE.0 / BLOCK + 2, SIZE.1 / BLOCK + 2);
    let texels = (grid.0 * grid.1 * LAYERS) as usize;
    let words: Vec<u32> = (0..4 * texels as u32).map(|i| i.wrapping_mul(2_654_435_761)).collect();
    let bytes: &[u8] = bytemuck::cast_slice(&words);

    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("records as words"),
        size: bytes.len() as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytes);
    let extent = wgpu::Extent3d { width: grid.0, height: grid.1, depth_or_array_layers: LAYERS };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("records as texels"),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let layout =
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(grid.0 * 16), rows_per_image: Some(grid.1) };
    queue.write_texture(texture.as_image_copy(), bytes, layout, extent);
    let out = gpu.output_texture("out", SIZE, wgpu::TextureFormat::R32Uint);

    let source = include_str!("record_loads.wgsl").replace("{{GRID_X}}", &grid.0.to_string());
    let records = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let out_view = out.create_view(&Default::default());
    let kernels = microbench::kernels(&gpu, "record_loads", &source, &KERNELS, |name| {
        let mut entries =
            vec![wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&out_view) }];
        match name {
            "buffer" => entries.push(wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }),
            "texture" => entries
                .push(wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&records) }),
            "storage" => entries
                .push(wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&records) }),
            _ => {}
        }
        entries
    });
    let times = microbench::time_kernels(&gpu, &kernels, (SIZE.0 / 8, SIZE.1 / 8), DISPATCHES, rounds);
    for (k, name) in KERNELS.iter().enumerate() {
        println!("{name:>8}: {:6.1} ms median of {rounds} rounds", microbench::median(&times[k]));
    }
    let extra = |k: usize| microbench::median_above(&times[k], &times[0]);
    let (buffer_ms, texture_ms) = (extra(1), extra(2));
    println!(
        "loads: {:.1} ms as buffer words (24 per lane), {:.1} ms as texels (8 per lane): {:.1}x",
        buffer_ms,
        texture_ms,
        buffer_ms / texture_ms
    );
}
