// Where a pixel takes its coarse values from, and which coarse effects it re-evaluates.
// Each corner of the pixel's cell is a sample, or, on a tile border shared with a tile
// that is coarser along the border, a blend of the two border samples it lies between.
struct MrslBlock {
    corners: vec4<u32>, // samples of the cell's corners c00, c10, c01, c11 (the first of two on a border)
    others: vec4<u32>,  // the second border sample of each corner (the corner's own where it has one)
    lerps: vec4<f32>,   // the weight of `others` in each corner (0 where the corner is a sample)
    weights: vec4<f32>, // bilinear weights of the corners
    nearest: u32,       // index of the nearest corner
{{#REFINED_WORDS}}
}

fn mrsl_is_refined(b: MrslBlock, k: u32) -> bool {
    return (({{WORD}} >> (k % 32u)) & 1u) != 0u;
}

// A corner `c` of a cell of tile `t` (rate `rate`), as two samples and the second's weight.
// On a border between tiles, both sides resample the border from the samples the
// coarser side has (every `step`-th along it), so the image has no seam there.
fn mrsl_rate_corner(c: vec2<i32>, t: vec2<i32>, rate: vec2<i32>) -> vec3<u32> {
    let size = vec2<i32>(mrsl_ctl.size);
    let tile = i32(mrsl_ctl.rate_tile);
    let origin = t * tile;
    let tiles = mrsl_tile_count();
    var a = c;
    var b = c;
    let on_x = c.x == origin.x || c.x == origin.x + tile;
    let on_y = c.y == origin.y || c.y == origin.y + tile;
    if (on_x && !on_y && c.y != size.y - 1) {
        let n = select(t.x + 1, t.x - 1, c.x == origin.x);
        if (n >= 0 && n < tiles.x) {
            let step = max(rate.y, mrsl_tile_rate(vec2<i32>(n, t.y)).y);
            let off = (c.y - origin.y) % step;
            a.y = c.y - off;
            b.y = select(c.y, min(a.y + step, size.y - 1), off != 0);
        }
    } else if (on_y && !on_x && c.x != size.x - 1) {
        let n = select(t.y + 1, t.y - 1, c.y == origin.y);
        if (n >= 0 && n < tiles.y) {
            let step = max(rate.x, mrsl_tile_rate(vec2<i32>(t.x, n)).x);
            let off = (c.x - origin.x) % step;
            a.x = c.x - off;
            b.x = select(c.x, min(a.x + step, size.x - 1), off != 0);
        }
    }
    let f = select(0.0, f32(c.x - a.x + c.y - a.y) / f32(max(b.x - a.x + b.y - a.y, 1)), any(a != b));
    return vec3<u32>(u32(a.y * size.x + a.x), u32(b.y * size.x + b.x), bitcast<u32>(f));
}

// The pixel of sample `s`.
fn mrsl_sample_pixel(s: u32) -> vec2<i32> {
    return vec2<i32>(i32(s % mrsl_ctl.size.x), i32(s / mrsl_ctl.size.x));
}
