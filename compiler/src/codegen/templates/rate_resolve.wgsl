fn mrsl_resolve{{SUFFIX}}(pos: vec2<i32>) -> MrslBlock {
    let size = vec2<i32>(mrsl_ctl.size);
    let t = pos / i32(mrsl_ctl.rate_tile);
    let rate = mrsl_tile_rate(t);
    let origin = t * i32(mrsl_ctl.rate_tile);
    let p0 = origin + (pos - origin) / rate * rate;
    let p1 = min(p0 + rate, size - vec2<i32>(1));
    let extent = p1 - p0;
    let t01 = select(vec2<f32>(0.0), vec2<f32>(pos - p0) / vec2<f32>(max(extent, vec2<i32>(1))), extent > vec2<i32>(0));
    var b: MrslBlock;
    let c00 = mrsl_rate_corner(p0, t, rate);
    let c10 = mrsl_rate_corner(vec2<i32>(p1.x, p0.y), t, rate);
    let c01 = mrsl_rate_corner(vec2<i32>(p0.x, p1.y), t, rate);
    let c11 = mrsl_rate_corner(p1, t, rate);
    b.corners = vec4<u32>(c00.x, c10.x, c01.x, c11.x);
    b.others = vec4<u32>(c00.y, c10.y, c01.y, c11.y);
    b.lerps = bitcast<vec4<f32>>(vec4<u32>(c00.z, c10.z, c01.z, c11.z));
    // Whether a corner blends two border samples (else `others` repeats `corners`, and
    // their keys and flags are not read again).
    let blended = any(b.lerps != vec4<f32>(0.0));
    b.weights = vec4<f32>((1.0 - t01.x) * (1.0 - t01.y), t01.x * (1.0 - t01.y), (1.0 - t01.x) * t01.y, t01.x * t01.y);
    b.nearest = select(0u, 1u, t01.x > 0.5) + select(0u, 2u, t01.y > 0.5);
    // A full-rate tile evaluates every coarse effect per pixel.
    var disc = mrsl_ctl.force_refine != 0u || all(rate == vec2<i32>(1));
{{#CORNERS}}
    // Effective refinement, users before what they use: an effect is evaluated per pixel
    // when a sample it is resampled from flagged it, at a discontinuity, or when it is
    // needed coarsely but a sample's shared slot holds another effect (an interface miss).
{{#REFINED}}
    return b;
}
