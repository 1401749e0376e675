// A position is a coarse-sample index in the coarse kernel and a pixel elsewhere.
fn mrsl_grid() -> vec2<i32> {
    let size = vec2<i32>(mrsl_ctl.size);
    return {{GRID}};
}

fn mrsl_pixel(pos: vec2<i32>) -> vec2<i32> {
    return {{PIXEL}};
}

// The two positions of pos's quad along x (xy, zw), as hardware 2x2 quads pair them;
// at the last odd column the pair is taken to the left instead.
fn mrsl_pair_x(pos: vec2<i32>) -> vec4<i32> {
    let n = mrsl_grid();
    var a = pos.x & ~1;
    var b = a + 1;
    if (b >= n.x) { a = max(pos.x - 1, 0); b = pos.x; }
    return vec4<i32>(a, pos.y, b, pos.y);
}

fn mrsl_pair_y(pos: vec2<i32>) -> vec4<i32> {
    let n = mrsl_grid();
    var a = pos.y & ~1;
    var b = a + 1;
    if (b >= n.y) { a = max(pos.y - 1, 0); b = pos.y; }
    return vec4<i32>(pos.x, a, pos.x, b);
}

