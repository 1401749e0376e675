// Decides, per coarse effect, whether pixel `p` interpolates its four previous-level
// neighbours `n` (those inside the image) or is shaded; queues it for shading if any.
fn mrsl_classify(p: vec2<i32>, n: array<vec2<i32>, 4>, level: u32) {
    let size = vec2<i32>(mrsl_ctl.size);
    var ok: array<bool, 4>;
    var q: array<vec2<i32>, 4>;
    var total = 0.0;
{{#IN_IMAGE}}
    // Neighbours come in opposite pairs (0, 1) and (2, 3); at a border only complete pairs
    // are used, so interpolation stays centred (exact for linear values). A pixel with no
    // complete pair is shaded.
{{#PAIRS}}
    ok = array<bool, 4>(pair_a, pair_a, pair_b, pair_b);
    for (var k = 0; k < 4; k++) {
        q[k] = select(p, n[k], ok[k]);
        total += select(0.0, 1.0, ok[k]);
    }
    var disc = mrsl_ctl.force_refine != 0u || total == 0.0;
{{#KEYS}}
{{#EFFECTS}}
    if (({{ANY_MASK}}) != 0u) {
        let slot = atomicAdd(&mrsl_queue[level * {{QUEUE_WORDS}}u], 1u);
        mrsl_work[mrsl_work_offset(level) + slot] = u32(p.y) * mrsl_ctl.size.x + u32(p.x);
    }
}

