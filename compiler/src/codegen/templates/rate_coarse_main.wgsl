// One invocation per listed sample (indirect dispatch): the coarse effects at that pixel,
// stored in the record of the pixel.
@compute @workgroup_size({{WORK_GROUP}}, 1, 1)
fn {{ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    let mrsl_k = (mrsl_wg.y * {{MAX_X}}u + mrsl_wg.x) * {{WORK_GROUP}}u + mrsl_li;
    if (mrsl_k >= atomicLoad(&mrsl_queue[0])) { return; }
    let mrsl_packed = mrsl_work[mrsl_k];
    let mrsl_pos = vec2<i32>(i32(mrsl_packed & 0xffffu), i32(mrsl_packed >> 16u));
    let mrsl_rec = (u32(mrsl_pos.y) * mrsl_ctl.size.x + u32(mrsl_pos.x)) * MRSL_STRIDE;
{{#BODY}}
}
