// One workgroup per tile of {{SIDE}}x{{SIDE}} pixels, in three phases with a barrier between
// them: the neighbour values of the samples around the tile; the tile's samples (their
// coarse effects, refine flags and records); its pixels, {{TILE}}x{{TILE}} at a time per
// group of {{GROUP}} lanes, written out one after the other (SwiftShader takes minutes
// to compile the fine pass's code inside a loop). Each sample is evaluated once per
// workgroup; a lane of the first two phases takes one sample (or a few, in turn), and
// a sample outside the image is skipped.
@compute @workgroup_size({{LANES}}, 1, 1)
fn {{ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    mrsl_origin = vec2<i32>(mrsl_wg.xy) * MRSL_TILE;
    let mrsl_n = {{GRID}}();
{{#NEIGHBOURS}}
    for (var k = mrsl_li; k < MRSL_NEIGHBOUR_SLOTS; k += {{LANES}}u) {
        let at = mrsl_origin - vec2<i32>(MRSL_RING + 1) + vec2<i32>(i32(k % {{NEIGHBOUR_SIDE}}u), i32(k / {{NEIGHBOUR_SIDE}}u));
        if (all(at >= vec2<i32>(0)) && all(at < mrsl_n)) { {{TILE_NEIGHBOURS}}(at, k); }
    }
    workgroupBarrier();
{{#SAMPLES}}
    // A sample counts towards the statistics in one tile: the one it lies in, the last
    // tile along an axis for the grid's last sample.
    let last = (vec2<i32>(mrsl_ctl.size) + vec2<i32>({{SIDE}} - 1)) / {{SIDE}} - vec2<i32>(1);
    for (var k = mrsl_li; k < MRSL_RECORD_SLOTS; k += {{LANES}}u) {
        let at = mrsl_origin - vec2<i32>(MRSL_RING) + vec2<i32>(i32(k % {{RECORD_SIDE}}u), i32(k / {{RECORD_SIDE}}u));
        if (all(at >= vec2<i32>(0)) && all(at < mrsl_n)) {
            let owned = all(min(at / MRSL_TILE, last) == vec2<i32>(mrsl_wg.xy));
            {{TILE_SAMPLE}}(at, k, owned);
        }
    }
{{#SURFACE}}
    workgroupBarrier();
{{#PIXELS}}
