// Pixel of a {{TILE}}x{{TILE}} tile for lane `li`: {{BLOCK}}x{{BLOCK}} blocks are laid out so that
// consecutive lanes (a SIMD group) cover whole blocks and share their refine decisions.
{{#LANES}}
fn mrsl_tile_pixel(wg: vec2<u32>, li: u32) -> vec2<i32> {
    let per_block = {{PER_BLOCK}}u;
    let blocks_x = {{BLOCKS_X}}u;
    let blk = li / per_block;
    let within = li % per_block;
    let x = (blk % blocks_x) * {{BLOCK}}u + within % {{BLOCK}}u;
    let y = (blk / blocks_x) * {{BLOCK}}u + within / {{BLOCK}}u;
    return vec2<i32>(wg * {{TILE}}u + vec2<u32>(x, y));
}

