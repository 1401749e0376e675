// Tile lists (`fine_tiles`): a word per tile, x | y << 16, the surface tiles
// (some pixel is not background) from the front, the background tiles from
// the back; their lengths; and their indirect dispatch arguments, bound only
// for `fine_tile_args`.
@group({{GROUP}}) @binding({{LIST_BINDING}}) var<storage, read_write> mrsl_tiles: array<u32>;
@group({{GROUP}}) @binding({{COUNTS_BINDING}}) var<storage, read_write> mrsl_tiles_n: array<atomic<u32>>;
@group({{ARGS_GROUP}}) @binding({{ARGS_BINDING}}) var<storage, read_write> mrsl_args: array<u32>;
var<workgroup> mrsl_wg_tile: u32;
var<workgroup> mrsl_wg_surface: atomic<u32>;

// The image's tiles along x and y.
fn mrsl_tile_grid() -> vec2<u32> {
    return (mrsl_ctl.size + vec2<u32>({{TILE}}u - 1u)) / {{TILE}}u;
}

// The tile workgroup `wg` of an indirect dispatch over list `list` (0: surface
// tiles, 1: background tiles) shades, the same for every lane; x = 0xffff past
// the list's end. The arguments lay the workgroups out in rows as wide as the
// image's tiles.
fn mrsl_listed_tile(wg: vec2<u32>, li: u32, list: u32) -> vec2<u32> {
    if (li == 0u) {
        let grid = mrsl_tile_grid();
        let entry = wg.y * grid.x + wg.x;
        var tile = 0xffffffffu;
        if (entry < atomicLoad(&mrsl_tiles_n[list])) {
            tile = mrsl_tiles[select(entry, grid.x * grid.y - 1u - entry, list == 1u)];
        }
        mrsl_wg_tile = tile;
    }
    let tile = workgroupUniformLoad(&mrsl_wg_tile);
    return vec2<u32>(tile & 0xffffu, tile >> 16u);
}

// Lists tile `wg` as a surface tile if a pixel of it is not background (or
// refinement is forced: then the background is refined like any pixel), else
// as a background tile.
@compute @workgroup_size({{LANES}}, 1, 1)
fn {{TILES_ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    var surface = mrsl_ctl.force_refine != 0u;
    for (var k = 0u; k < {{PER_LANE}}u; k += 1u) {
        let pixel = mrsl_li + k * {{LANES}}u;
        let pos = vec2<i32>(mrsl_wg.xy * {{TILE}}u + vec2<u32>(pixel % {{TILE}}u, pixel / {{TILE}}u));
        if (all(pos < mrsl_grid()) && !mrsl_background(pos)) { surface = true; }
    }
    if (surface) { atomicOr(&mrsl_wg_surface, 1u); }
    workgroupBarrier();
    if (mrsl_li == 0u) {
        let tile = mrsl_wg.x | (mrsl_wg.y << 16u);
        if (atomicLoad(&mrsl_wg_surface) != 0u) {
            mrsl_tiles[atomicAdd(&mrsl_tiles_n[0], 1u)] = tile;
        } else {
            let grid = mrsl_tile_grid();
            mrsl_tiles[grid.x * grid.y - 1u - atomicAdd(&mrsl_tiles_n[1], 1u)] = tile;
        }
    }
}

// The two lists' indirect arguments: rows as wide as the image's tiles.
@compute @workgroup_size(1, 1, 1)
fn {{ARGS_ENTRY}}() {
    let across = mrsl_tile_grid().x;
    for (var list = 0u; list < {{LISTS}}u; list += 1u) {
        let n = atomicLoad(&mrsl_tiles_n[list]);
        mrsl_args[{{ARG_WORDS}}u * list] = min(n, across);
        mrsl_args[{{ARG_WORDS}}u * list + 1u] = (n + across - 1u) / across;
        mrsl_args[{{ARG_WORDS}}u * list + 2u] = 1u;
    }
}

