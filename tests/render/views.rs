//! Several `encode`s of one `Shader` before one submit, as an engine's frame
//! loop records views, split screens or probes: each with its own size,
//! uniforms and mode gives, bit for bit, the image it gives alone.

use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use mrsl_runtime::{Bindings, DispatchOptions, Mode, Shader};

/// A coarse effect that refines and a uniform every view sets its own way.
const PROGRAM: &str = "in float3 normal;\nin float3 position;\nuniform float3 tint = float3(1.0);\n\
    coarse effect float3 lit {\n    lit = tint * saturate(normal.y * 0.5 + 0.5) * (0.5 + 0.5 * sin(position.x * 3.0));\n    \
    if (fwidth(lit.x) > 0.05) refine;\n}\nfine out float4 color = float4(lit, 1.0);\n";

/// One view: its size, its `tint` and its mode.
struct View {
    size: (u32, u32),
    tint: [f64; 3],
    mode: Mode,
}

/// The first and the last view share a size and differ in `tint` (before,
/// the second one's values reached both: a silently wrong image); the middle
/// one has a size and a mode of its own (before, its resources replaced the
/// first view's while that one's commands still used them).
pub fn views_in_one_submission_are_each_their_own_render(gpu: &Gpu) {
    let program = crate::compile(PROGRAM);
    let mut shader = Shader::new(&gpu.device, &program).unwrap();
    let views = [
        View { size: (40, 24), tint: [1.0, 0.5, 0.25], mode: Mode::Coarse4x4 },
        View { size: (56, 40), tint: [0.2, 0.9, 0.4], mode: Mode::Hierarchical },
        View { size: (40, 24), tint: [0.3, 0.3, 1.0], mode: Mode::Dynamic },
    ];
    let alone: Vec<Vec<[f32; 4]>> =
        views.iter().map(|v| render(gpu, &mut shader, std::slice::from_ref(v)).remove(0)).collect();
    let together = render(gpu, &mut shader, &views);
    for (k, (one, both)) in alone.iter().zip(&together).enumerate() {
        let differing = one.iter().zip(both).filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits)).count();
        assert_eq!(differing, 0, "view {k} ({:?}): {differing} pixels differ from its render alone", views[k].mode);
    }
    assert_ne!(alone[0], alone[2], "the two views of one size must differ for the test to mean anything");
}

/// Encodes every view into one encoder, submits once, reads each output.
fn render(gpu: &Gpu, shader: &mut Shader, views: &[View]) -> Vec<Vec<[f32; 4]>> {
    let gbuffers: Vec<Vec<(String, wgpu::Texture)>> =
        views.iter().map(|v| Scene::Demo.render(v.size.0, v.size.1).upload(gpu)).collect();
    let outputs: Vec<wgpu::Texture> =
        views.iter().map(|v| gpu.output_texture("color", v.size, wgpu::TextureFormat::Rgba32Float)).collect();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    for ((view, channels), output) in views.iter().zip(&gbuffers).zip(&outputs) {
        shader.set_uniform("tint", &view.tint).unwrap();
        let mut bindings = Bindings { size: view.size, ..Default::default() };
        for (name, texture) in channels {
            bindings.channels.insert(name.clone(), texture);
        }
        bindings.outputs.insert("color".into(), output);
        shader.encode(&gpu.device, &gpu.queue, &mut encoder, &bindings, DispatchOptions::new(view.mode)).unwrap();
    }
    gpu.queue.submit([encoder.finish()]);
    outputs.iter().map(|o| gpu.read_rgba32f(o).unwrap()).collect()
}
