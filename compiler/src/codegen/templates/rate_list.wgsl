// Samples a tile lists along one axis: origin + i * step inside the tile (up to `end`,
// exclusive), and the image's last pixel n - 1 when the tile reaches the edge and that
// pixel is off the lattice (the last cells clamp their far corner to it).
fn mrsl_axis_count(origin: i32, end: i32, step: i32, n: i32) -> i32 {
    let extra = select(0, 1, end == n && (n - 1 - origin) % step != 0);
    return (end - origin + step - 1) / step + extra;
}

fn mrsl_axis_at(origin: i32, step: i32, n: i32, i: i32) -> i32 {
    return min(origin + i * step, n - 1);
}

fn mrsl_list(at: u32, p: vec2<i32>) {
    mrsl_work[at] = u32(p.x) | (u32(p.y) << 16u);
}

// One invocation per tile: lists the coarse samples the tile owns. A tile at rate w x h
// owns its lattice (every w-th column and h-th row from its origin, plus the image's
// last column and row at the edge), except that along its first row it lists only every
// max(w, w above)-th column and along its first column every max(h, h left)-th row: both
// sides resample a shared border from those alone. The samples on its far borders belong
// to the tiles there. A full-rate (1x1) tile shades everything per pixel and owns only what its
// coarser neighbours' cells need: its first column at its left neighbour's height,
// its first row at its upper neighbour's width, and its origin when one of those or the
// tile diagonally above-left is coarser. So every listed sample is a distinct pixel, and the cells of every tile find all their corners listed.
@compute @workgroup_size({{TILES}}, {{TILES}}, 1)
fn {{LIST}}(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<i32>(mrsl_ctl.size);
    let tile = i32(mrsl_ctl.rate_tile);
    let t = vec2<i32>(gid.xy);
    if (any(t >= mrsl_tile_count())) { return; }
    let origin = t * tile;
    let end = min(origin + vec2<i32>(tile), size);
    let rate = mrsl_tile_rate(t);
    if (all(rate == vec2<i32>(1))) {
        var left = 0;
        var up = 0;
        if (t.x > 0) {
            let r = mrsl_tile_rate(t - vec2<i32>(1, 0));
            left = select(r.y, 0, all(r == vec2<i32>(1)));
        }
        if (t.y > 0) {
            let r = mrsl_tile_rate(t - vec2<i32>(0, 1));
            up = select(r.x, 0, all(r == vec2<i32>(1)));
        }
        let column = select(0, mrsl_axis_count(origin.y, end.y, left, size.y), left > 0);
        let row = select(0, mrsl_axis_count(origin.x, end.x, up, size.x), up > 0);
        if (column == 0 && row == 0) {
            // Only a coarser tile diagonally above-left can need the origin (its last cell's corner).
            if (all(t > vec2<i32>(0)) && any(mrsl_tile_rate(t - vec2<i32>(1)) != vec2<i32>(1))) {
                mrsl_list(atomicAdd(&mrsl_queue[0], 1u), origin);
            }
            return;
        }
        // The origin is the first sample of the column and of the row; listed once.
        let total = column + row - select(0, 1, column > 0 && row > 0);
        var at = atomicAdd(&mrsl_queue[0], u32(total));
        for (var i = 0; i < column; i += 1) {
            mrsl_list(at, vec2<i32>(origin.x, mrsl_axis_at(origin.y, left, size.y, i)));
            at += 1u;
        }
        for (var i = select(0, 1, column > 0); i < row; i += 1) {
            mrsl_list(at, vec2<i32>(mrsl_axis_at(origin.x, up, size.x, i), origin.y));
            at += 1u;
        }
        return;
    }
    // The steps along the first row and the first column: the coarser side's.
    var row_step = rate.x;
    var column_step = rate.y;
    if (t.y > 0) {
        row_step = max(row_step, mrsl_tile_rate(t - vec2<i32>(0, 1)).x);
    }
    if (t.x > 0) {
        column_step = max(column_step, mrsl_tile_rate(t - vec2<i32>(1, 0)).y);
    }
    let nx = mrsl_axis_count(origin.x, end.x, rate.x, size.x);
    let ny = mrsl_axis_count(origin.y, end.y, rate.y, size.y);
    let row = mrsl_axis_count(origin.x, end.x, row_step, size.x);
    let column = mrsl_axis_count(origin.y, end.y, column_step, size.y);
    var at = atomicAdd(&mrsl_queue[0], u32(row + column - 1 + (nx - 1) * (ny - 1)));
    for (var i = 0; i < row; i += 1) {
        mrsl_list(at, vec2<i32>(mrsl_axis_at(origin.x, row_step, size.x, i), origin.y));
        at += 1u;
    }
    for (var j = 1; j < column; j += 1) {
        mrsl_list(at, vec2<i32>(origin.x, mrsl_axis_at(origin.y, column_step, size.y, j)));
        at += 1u;
    }
    for (var j = 1; j < ny; j += 1) {
        for (var i = 1; i < nx; i += 1) {
            mrsl_list(at, vec2<i32>(mrsl_axis_at(origin.x, rate.x, size.x, i), mrsl_axis_at(origin.y, rate.y, size.y, j)));
            at += 1u;
        }
    }
}

// Workgroups of `{{COARSE}}` for the listed samples, in rows of at most {{MAX_X}}.
@compute @workgroup_size(1, 1, 1)
fn {{ARGS}}() {
    let groups = (atomicLoad(&mrsl_queue[0]) + {{WORK_GROUP_LESS_1}}u) / {{WORK_GROUP}}u;
    let x = min(groups, {{MAX_X}}u);
    mrsl_args[0] = x;
    mrsl_args[1] = select(0u, (groups + x - 1u) / max(x, 1u), groups > 0u);
    mrsl_args[2] = 1u;
}
