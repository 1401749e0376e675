// The cell size (width, height) of rate tile `t`. Each axis is read on its own and
// clamped to 4, so the codes of 4x1 and 1x4 (which hardware VRS lacks) work as well.
fn mrsl_tile_rate(t: vec2<i32>) -> vec2<i32> {
    let code = textureLoad(mrsl_shading_rate, t, 0).x;
    return min(vec2<i32>(1 << ((code >> 2u) & 3u), 1 << (code & 3u)), vec2<i32>(4));
}

fn mrsl_tile_count() -> vec2<i32> {
    let tile = i32(mrsl_ctl.rate_tile);
    return (vec2<i32>(mrsl_ctl.size) + vec2<i32>(tile - 1)) / tile;
}
