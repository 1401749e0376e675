// A colour stored as rgb9e5: three 9-bit mantissas and a shared 5-bit exponent (bias 15).
fn mrsl_rgb9e5(v: u32) -> vec3<f32> {
    let scale = exp2(f32(i32(extractBits(v, 27u, 5u)) - 15 - 9));
    return vec3<f32>(f32(extractBits(v, 0u, 9u)), f32(extractBits(v, 9u, 9u)), f32(extractBits(v, 18u, 9u))) * scale;
}

