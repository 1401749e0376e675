//! Derivatives of locals built by a loop, a branch or several assignments,
//! taken by running the statements before the derivative again at the
//! neighbouring position (`DerivSite::prefix`, docs/language.md section 9).

use crate::dispatch_in_turn;
use mrsl_abi::Device;
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use mrsl_runtime::{DispatchOptions, Mode};

/// The corpus programs whose derivative operands read such locals: in a
/// refine predicate (0084, 0086) and in a value (0085, whose loop breaks
/// per pixel), and reading effects at the neighbour (0087: a coarse
/// predicate over a coarse effect, a fine value over a coarse effect).
const PROGRAMS: [(&str, &str); 4] = [
    ("0084", include_str!("../../compiler/tests/data/ok/0084_derivative_of_reassigned_local.mrsl")),
    ("0085", include_str!("../../compiler/tests/data/ok/0085_derivative_after_varying_break.mrsl")),
    ("0086", include_str!("../../compiler/tests/data/ok/0086_derivative_of_loop_built_effect.mrsl")),
    ("0087", include_str!("../../compiler/tests/data/ok/0087_loop_built_derivatives_that_read_effects.mrsl")),
];

/// Forced refinement evaluates every effect per pixel with the reference's
/// code, derivative prefixes included: bit-identical in every mode.
pub fn loop_built_derivatives_force_to_the_reference(gpu: &Gpu) {
    crate::assert_forced_equals_reference(gpu, &PROGRAMS);
}

/// A loop-built sum differentiated in its effect's own predicate (0086)
/// refines exactly where the same sum built in an effect of its own and
/// differentiated there does (the program E0503 once asked for): the value
/// at the neighbouring sample is the loop run there, in both. Compared in
/// the block modes, on both plans (tile kernel and coarse and fine kernels),
/// by the pixels that evaluated `x` themselves.
pub fn loop_built_predicates_refine_as_an_effect_of_their_own(gpu: &Gpu) {
    let lifted = PROGRAMS[2].1;
    let own_effect = "in float3 normal;\nuniform float threshold = 0.1;\n\
        coarse effect float sum {\n    sum = 0.0;\n    for (int i = 0; i < 4; i++) {\n        sum += normal.x * float(i);\n    }\n}\n\
        coarse effect float x {\n    x = sum;\n    if (fwidth(x) > threshold) refine;\n}\n\
        fine out float4 color = float4(float3(x), 1.0);\n";
    let gbuffer = Scene::Demo.render(75, 43);
    let rates = mrsl_lab::shading_rate::pattern(mrsl_abi::shading_rate::rate_image_size((75, 43), 8));
    for mode in [Mode::Coarse2x2, Mode::Coarse4x4] {
        for device in [Device::Gpu, Device::Cpu] {
            let refined = |source: &str| {
                let program = crate::compile(source);
                let options = DispatchOptions { device: Some(device), ..DispatchOptions::new(mode) };
                let [out] = dispatch_in_turn(gpu, &program, &gbuffer, &rates, [options]).unwrap();
                let stats = out.stats.unwrap();
                stats.effects.iter().find(|e| e.name == "x").expect("`x` is counted").pixel_evaluations
            };
            let (a, b) = (refined(lifted), refined(own_effect));
            assert!(a > 0, "{mode} {device:?}: the predicate refines somewhere over the demo scene");
            assert_eq!(a, b, "{mode} {device:?}: pixels refined for `x`, lifted against an effect of its own");
        }
    }
}
