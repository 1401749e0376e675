// Channel `{{NAME}}` from depth: the world position of the pixel's centre at
// its depth (WebGPU's clip space: depth 0 to 1, y up), through the inverse
// view-projection `{{MATRIX}}`.
fn mrsl_load_{{NAME}}(pos: vec2<i32>) -> vec3<f32> {
    let p = mrsl_pixel(pos);
    let depth = textureLoad(mrsl_gb_{{NAME}}, p, 0);
    let uv = (vec2<f32>(p) + vec2<f32>(0.5)) / vec2<f32>(mrsl_ctl.size);
    let world = mrsl_u.{{MATRIX}} * vec4<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y, depth, 1.0);
    return world.xyz / world.w;
}

