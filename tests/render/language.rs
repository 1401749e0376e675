//! Language forms that compile to what they mean, in every mode: uniform
//! arrays with defaults and loops bounded by a constant beside a dynamic
//! limit force to the reference bit for bit, and a dynamic limit in the
//! condition renders exactly as the same limit tested by a `break`.

use crate::{run, worst_ulps};
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use mrsl_runtime::Mode;

const DEFAULTS: &str = include_str!("../../compiler/tests/data/ok/0089_uniform_array_default.mrsl");
const LIMITS: &str = include_str!("../../compiler/tests/data/ok/0090_loops_with_a_dynamic_limit.mrsl");

/// 0090's loops with the constant bound alone in the condition and the
/// dynamic limit tested first in the body: the form E0401 asked for before.
const BREAKS: &str = "in float3 normal;\nin float2 uv;\nuniform int count = 5;\nuniform float4 weights[16];\n\
    coarse effect float sum {\n    sum = 0.0;\n\
    for (int i = 0; i < 16; i++) {\n        if (!(i < count)) break;\n        sum += weights[i].x * normal.y;\n    }\n\
    for (int i = 0; 16 > i; i++) {\n        if (!(count > i)) break;\n        sum += weights[i].y * uv.x;\n    }\n\
    for (int i = 0; i < 16; i++) {\n        if (!(i < min(count, 16))) break;\n        sum += weights[i].z;\n    }\n\
    for (int j = 15; j > -1; j--) {\n        if (!(j > max(15 - count, -1))) break;\n        sum += weights[j].w * uv.y;\n    }\n\
    if (fwidth(sum) > 0.1) refine;\n}\nfine out float4 color = float4(float3(sum), 1.0);\n";

/// Forced refinement evaluates every effect per pixel with the reference's code.
pub fn new_forms_force_to_the_reference(gpu: &Gpu) {
    crate::assert_forced_equals_reference(gpu, &[("0089", DEFAULTS), ("0090", LIMITS)]);
}

/// The same sums in the same order, whichever way the limit is written:
/// the reference and coarse 4x4 images are bit-identical.
pub fn dynamic_limits_render_as_breaks(gpu: &Gpu) {
    let gbuffer = Scene::Demo.render(75, 43);
    let (limits, breaks) = (crate::compile(LIMITS), crate::compile(BREAKS));
    for mode in [Mode::Reference, Mode::Coarse4x4] {
        let a = run(gpu, &limits, &gbuffer, mode, false).unwrap();
        let b = run(gpu, &breaks, &gbuffer, mode, false).unwrap();
        assert_eq!(worst_ulps(&a.pixels, &b.pixels), 0, "{mode}");
        assert!(a.pixels.iter().any(|p| p[0] != 0.0), "{mode}: the loops add something");
    }
}
