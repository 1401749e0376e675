//! Micro-benchmark behind the record modes' final pass: what reading one
//! pixel's record (ten 32-bit words, about what sponza_lights keeps per
//! pixel in the hierarchical mode) costs a lane at 1920x1080, as texels of
//! the `r32uint` read-write storage array the classification writes (and
//! the same array read-only), as the same texels through a sampled view,
//! and packed four words to a texel of an `rgba32uint` array (sampled,
//! read-only storage, and read-write storage as the hierarchical kernel's
//! packed records are); and a float G-buffer texel and its neighbours,
//! sampled and as storage.
//!
//! `cargo run --release -p mrsl-lab --example record_access [ROUNDS]`
//!
//! The kernels run interleaved (the order rotates every round), each timed
//! over 4 dispatches; it prints each kernel's median time and the median
//! over rounds of each load kernel's time above the store-only kernel's.

use mrsl_lab::microbench;

const SIZE: (u32, u32) = (1920, 1080);
const WORDS: u32 = 10;
const DISPATCHES: u32 = 4;
const KERNELS: [&str; 9] = [
    "none",
    "storage",
    "storage_read",
    "sampled",
    "packed",
    "packed_storage",
    "packed_read_write",
    "float_sampled",
    "float_storage",
];

fn main() {
    let (gpu, rounds) = microbench::start_packing_records();
    // Read-write `Rgba32Uint` storage is an adapter feature: without it that kernel is left out.
    let names: Vec<&str> = KERNELS.into_iter().filter(|&k| gpu.packs_records || k != "packed_read_write").collect();
    if !gpu.packs_records {
        println!("packed_read_write: left out (the adapter grants no read-write Rgba32Uint storage)");
    }
    let (device, queue) = (&gpu.device, &gpu.queue);
    let texture = |label, format, layers, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: SIZE.0, height: SIZE.1, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: usage | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    };
    let words = texture("words", wgpu::TextureFormat::R32Uint, WORDS, wgpu::TextureUsages::STORAGE_BINDING);
    let packed =
        texture("packed", wgpu::TextureFormat::Rgba32Uint, WORDS.div_ceil(4), wgpu::TextureUsages::STORAGE_BINDING);
    let floats = texture("floats", wgpu::TextureFormat::Rgba32Float, 1, wgpu::TextureUsages::STORAGE_BINDING);
    for (t, texel) in [(&words, 4u32), (&packed, 16), (&floats, 16)] {
        let layers = t.size().depth_or_array_layers;
        let data: Vec<u32> = (0..SIZE.0 * SIZE.1 * layers * texel / 4).map(|i| i.wrapping_mul(2_654_435_761)).collect();
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(SIZE.0 * texel),
            rows_per_image: Some(SIZE.1),
        };
        queue.write_texture(t.as_image_copy(), bytemuck::cast_slice(&data), layout, t.size());
    }
    let array = |t: &wgpu::Texture| {
        t.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        })
    };
    let (words_view, packed_view) = (array(&words), array(&packed));
    let floats_view = floats.create_view(&Default::default());
    let out = gpu.output_texture("out", SIZE, wgpu::TextureFormat::R32Uint);
    let out_view = out.create_view(&Default::default());
    let source = include_str!("record_access.wgsl").replace("{{WORDS}}", &WORDS.to_string());
    let kernels = microbench::kernels(&gpu, "record_access", &source, &names, |name| {
        let view = |v| wgpu::BindingResource::TextureView(v);
        let mut entries = vec![wgpu::BindGroupEntry { binding: 3, resource: view(&out_view) }];
        match name {
            "storage" => entries.push(wgpu::BindGroupEntry { binding: 0, resource: view(&words_view) }),
            "sampled" => entries.push(wgpu::BindGroupEntry { binding: 1, resource: view(&words_view) }),
            "packed" => entries.push(wgpu::BindGroupEntry { binding: 2, resource: view(&packed_view) }),
            "packed_storage" => entries.push(wgpu::BindGroupEntry { binding: 4, resource: view(&packed_view) }),
            "storage_read" => entries.push(wgpu::BindGroupEntry { binding: 7, resource: view(&words_view) }),
            "packed_read_write" => entries.push(wgpu::BindGroupEntry { binding: 8, resource: view(&packed_view) }),
            "float_sampled" => entries.push(wgpu::BindGroupEntry { binding: 5, resource: view(&floats_view) }),
            "float_storage" => entries.push(wgpu::BindGroupEntry { binding: 6, resource: view(&floats_view) }),
            _ => {}
        }
        entries
    });
    let times = microbench::time_kernels(&gpu, &kernels, (SIZE.0 / 8, SIZE.1 / 8), DISPATCHES, rounds);
    microbench::report_above_first(&names, &times, "loads");
}
