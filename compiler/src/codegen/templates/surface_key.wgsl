// Surface key `{{NAME}}`: a position and its normal.
struct {{TYPE}} {
    p: vec3<f32>,
    n: vec3<f32>,
}

fn {{KEY}}(pos: vec2<i32>) -> {{TYPE}} {
    return {{TYPE}}({{LOAD_POSITION}}(pos), {{LOAD_NORMAL}}(pos));
}

// Whether `a` and `b` lie on different surfaces: the offset between them
// leaves either one's tangent plane by more than {{THRESHOLD}} of its length
// (a ratio, the same at any scale). A zero normal tests nothing.
fn {{EDGE}}(a: {{TYPE}}, b: {{TYPE}}) -> bool {
    let d = b.p - a.p;
    let bound = {{THRESHOLD}} * length(d);
    let na = a.n * inverseSqrt(max(dot(a.n, a.n), 1e-30));
    let nb = b.n * inverseSqrt(max(dot(b.n, b.n), 1e-30));
    return abs(dot(d, na)) > bound || abs(dot(d, nb)) > bound;
}

