fn mrsl_tile_pixel(wg: vec2<u32>, li: u32) -> vec2<i32> {
    return vec2<i32>(wg * {{TILE}}u + vec2<u32>(li % {{TILE}}u, li / {{TILE}}u));
}

