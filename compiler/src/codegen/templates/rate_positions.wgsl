// A position is a pixel. Derivatives pair the samples of the tile's lattice, as hardware
// shading at a coarse rate pairs coarse pixels: along x, (2k, 2k+1) cells from the tile's
// origin, one cell width apart (one pixel in a full-rate tile); at the image's last column
// the pair is taken to the left.
fn mrsl_grid() -> vec2<i32> {
    return vec2<i32>(mrsl_ctl.size);
}

fn mrsl_pixel(pos: vec2<i32>) -> vec2<i32> {
    return pos;
}

fn mrsl_cell(pos: vec2<i32>) -> vec2<i32> {
    let t = pos / i32(mrsl_ctl.rate_tile);
    let code = textureLoad(mrsl_shading_rate, t, 0).x;
    return min(vec2<i32>(1 << ((code >> 2u) & 3u), 1 << (code & 3u)), vec2<i32>(4));
}

fn mrsl_pair_x(pos: vec2<i32>) -> vec4<i32> {
    let n = i32(mrsl_ctl.size.x);
    let s = mrsl_cell(pos).x;
    let origin = pos.x / i32(mrsl_ctl.rate_tile) * i32(mrsl_ctl.rate_tile);
    var a = origin + (pos.x - origin) / (2 * s) * (2 * s);
    var b = min(a + s, n - 1);
    if (b == a) { a = max(b - s, 0); }
    return vec4<i32>(a, pos.y, b, pos.y);
}

fn mrsl_pair_y(pos: vec2<i32>) -> vec4<i32> {
    let n = i32(mrsl_ctl.size.y);
    let s = mrsl_cell(pos).y;
    let origin = pos.y / i32(mrsl_ctl.rate_tile) * i32(mrsl_ctl.rate_tile);
    var a = origin + (pos.y - origin) / (2 * s) * (2 * s);
    var b = min(a + s, n - 1);
    if (b == a) { a = max(b - s, 0); }
    return vec4<i32>(pos.x, a, pos.x, b);
}
