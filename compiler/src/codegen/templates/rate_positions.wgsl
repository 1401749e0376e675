// A position is a pixel. Derivatives pair the samples of the tile's lattice, as hardware
// shading at a coarse rate pairs coarse pixels: along x, (2k, 2k+1) cells from the tile's
// origin, one cell width apart; at the image's last column the pair is taken to the left.
// Along a tile's first row (column), which its upper (left) neighbour's cells share and
// which both resample every max(both cell widths (heights)) pixels, the pairs are that far
// apart, so that a predicate sees the change across the cells that blend these samples.
// In a full-rate tile, elsewhere, they are one pixel apart.
fn mrsl_grid() -> vec2<i32> {
    return vec2<i32>(mrsl_ctl.size);
}

fn mrsl_pixel(pos: vec2<i32>) -> vec2<i32> {
    return pos;
}

fn mrsl_cell_of(t: vec2<i32>) -> vec2<i32> {
    let code = textureLoad(mrsl_shading_rate, t, 0).x;
    return min(vec2<i32>(1 << ((code >> 2u) & 3u), 1 << (code & 3u)), vec2<i32>(4));
}

// The spacing of derivative pairs at `pos` along x (`axis` 0) or y (1).
fn mrsl_cell(pos: vec2<i32>, axis: i32) -> i32 {
    let tile = i32(mrsl_ctl.rate_tile);
    let t = pos / tile;
    var s = mrsl_cell_of(t)[axis];
    // Along x, the first row is shared with the tile above; along y, the first column with the tile to the left.
    let across = 1 - axis;
    if (pos[across] == t[across] * tile && t[across] > 0) {
        var n = t;
        n[across] -= 1;
        s = max(s, mrsl_cell_of(n)[axis]);
    }
    return s;
}

fn mrsl_pair_x(pos: vec2<i32>) -> vec4<i32> {
    let n = i32(mrsl_ctl.size.x);
    let s = mrsl_cell(pos, 0);
    let origin = pos.x / i32(mrsl_ctl.rate_tile) * i32(mrsl_ctl.rate_tile);
    var a = origin + (pos.x - origin) / (2 * s) * (2 * s);
    var b = min(a + s, n - 1);
    if (b == a) { a = max(b - s, 0); }
    return vec4<i32>(a, pos.y, b, pos.y);
}

fn mrsl_pair_y(pos: vec2<i32>) -> vec4<i32> {
    let n = i32(mrsl_ctl.size.y);
    let s = mrsl_cell(pos, 1);
    let origin = pos.y / i32(mrsl_ctl.rate_tile) * i32(mrsl_ctl.rate_tile);
    var a = origin + (pos.y - origin) / (2 * s) * (2 * s);
    var b = min(a + s, n - 1);
    if (b == a) { a = max(b - s, 0); }
    return vec4<i32>(pos.x, a, pos.x, b);
}
