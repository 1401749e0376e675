// The hierarchical tiles ({{TILE}}x{{TILE}} pixels, what a workgroup of level 0 covers) along x and y.
fn mrsl_htile_grid() -> vec2<u32> {
    return (mrsl_ctl.size + vec2<u32>({{TILE}}u - 1u)) / {{TILE}}u;
}

// Where the tile list starts in the work lists: the back of level {{LAST_LEVEL}}'s list,
// which never reaches it (it lists at most half its lattice). A word per tile,
// x | y << 16: the surface tiles from the front, the background tiles from the back.
fn mrsl_tile_list() -> u32 {
    let grid = mrsl_htile_grid();
    let w = mrsl_ctl.size.x;
    let h = mrsl_ctl.size.y;
    return mrsl_work_offset({{LAST_LEVEL}}u) + {{LAST_POINTS}} - grid.x * grid.y;
}

// The invocation, as a point of the grid of {{LANES}}x{{LANES}}-lane workgroups over a
// lattice, of lane `lid` of workgroup `wg` of a dispatch over tile list `list`
// (0: surface tiles, 1: background tiles) with `per` workgroups per tile along x
// and y; x = 0xffffffff past the list's end. The arguments lay the workgroups
// out in rows of as many tiles as the image has across.
fn mrsl_tile_invocation(wg: vec2<u32>, lid: vec2<u32>, per: vec2<u32>, list: u32) -> vec2<u32> {
    let grid = mrsl_htile_grid();
    let entry = wg.y * grid.x + wg.x / (per.x * per.y);
    if (entry >= atomicLoad(&mrsl_queue[list])) {
        return vec2<u32>(0xffffffffu);
    }
    let sub = wg.x % (per.x * per.y);
    let tile = mrsl_work[mrsl_tile_list() + select(entry, grid.x * grid.y - 1u - entry, list == 1u)];
    return (vec2<u32>(tile & 0xffffu, tile >> 16u) * per + vec2<u32>(sub % per.x, sub / per.x)) * {{LANES}}u + lid;
}

var<workgroup> mrsl_wg_surface: atomic<u32>;

// Lists tile `mrsl_wg` as a surface tile if a pixel of it is not background (or
// refinement is forced: then the background is shaded like any pixel), else as a
// background tile; each lane tests {{STEP}}x{{STEP}} pixels.
@compute @workgroup_size({{LANES}}, {{LANES}}, 1)
fn {{TILES_ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_id) mrsl_lid: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    var surface = mrsl_ctl.force_refine != 0u;
    for (var k = 0u; k < {{STEP}}u * {{STEP}}u; k += 1u) {
        let pos = vec2<i32>(mrsl_wg.xy * {{TILE}}u + mrsl_lid.xy * {{STEP}}u + vec2<u32>(k % {{STEP}}u, k / {{STEP}}u));
        if (all(pos < vec2<i32>(mrsl_ctl.size)) && !mrsl_background(pos)) { surface = true; }
    }
    if (surface) { atomicOr(&mrsl_wg_surface, 1u); }
    workgroupBarrier();
    if (mrsl_li == 0u) {
        let tile = mrsl_wg.x | (mrsl_wg.y << 16u);
        let grid = mrsl_htile_grid();
        if (atomicLoad(&mrsl_wg_surface) != 0u) {
            mrsl_work[mrsl_tile_list() + atomicAdd(&mrsl_queue[{{SURFACE}}u], 1u)] = tile;
        } else {
            mrsl_work[mrsl_tile_list() + grid.x * grid.y - 1u - atomicAdd(&mrsl_queue[{{BACKGROUND}}u], 1u)] = tile;
        }
    }
}

// The arguments at word `word` of a dispatch over `tiles` listed tiles with
// `per_tile` workgroups each: rows of as many tiles as the image has across.
fn mrsl_tile_args(word: u32, tiles: u32, per_tile: u32) {
    let across = mrsl_htile_grid().x;
    mrsl_args[word] = min(tiles, across) * per_tile;
    mrsl_args[word + 1u] = (tiles + across - 1u) / across;
    mrsl_args[word + 2u] = 1u;
}

// The arguments of level 0's and every classification's dispatch over the surface
// tiles, and of the background tiles' pass.
@compute @workgroup_size(1, 1, 1)
fn {{ARGS_ENTRY}}() {
    let surface = atomicLoad(&mrsl_queue[{{SURFACE}}u]);
    let background = atomicLoad(&mrsl_queue[{{BACKGROUND}}u]);
{{#DISPATCHES}}
}

