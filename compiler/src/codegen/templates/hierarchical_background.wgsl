// The background tiles, a pixel per lane: its record cleared, its coarse effects
// zero (the background rule), its outputs written.
@compute @workgroup_size({{WORK_GROUP}}, 1, 1)
fn {{ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    let lane = vec2<u32>(mrsl_li % {{LANES}}u, mrsl_li / {{LANES}}u);
    let gid = mrsl_tile_invocation(mrsl_wg.xy, lane, vec2<u32>({{PER_X}}u, {{PER_Y}}u), {{LIST}}u);
    let p = vec2<i32>(gid);
    if (gid.x != 0xffffffffu && all(p < vec2<i32>(mrsl_ctl.size))) {
{{#CLEAR}}
        mrsl_finish(p);
    }
{{#FLUSH}}
}

