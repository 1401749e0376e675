// Decides, per coarse effect, whether pixel `p` interpolates its four previous-level
// neighbours `n` (those inside the image and on its side of every key the effect
// reads) or is shaded; queues it for shading if any effect is. Returns whether its
// record is complete (nothing queued): then the caller writes its outputs.
fn mrsl_classify(p: vec2<i32>, n: array<vec2<i32>, 4>, level: u32) -> bool {
    let size = vec2<i32>(mrsl_ctl.size);
    var inside: array<bool, 4>;
    var q: array<vec2<i32>, 4>;
{{#BACKGROUND}}
    for (var k = 0; k < 4; k++) {
        inside[k] = all(n[k] >= vec2<i32>(0)) && all(n[k] < size);
        q[k] = select(p, n[k], inside[k]);
    }
    let force = mrsl_ctl.force_refine != 0u;
{{#KEYS}}
{{#EFFECTS}}
    if (({{ANY_MASK}}) != 0u) {
        let slot = atomicAdd(&mrsl_queue[level * {{QUEUE_WORDS}}u], 1u);
        mrsl_work[mrsl_work_offset(level) + slot] = u32(p.y) * mrsl_ctl.size.x + u32(p.x);
        return false;
    }
    return true;
}
