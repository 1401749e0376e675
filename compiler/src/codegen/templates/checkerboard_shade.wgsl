// Quad (qx, qy) of 2x2 pixels is shaded when qx + qy is even (a checkerboard of quads).
fn mrsl_shaded_quad(p: vec2<i32>) -> bool {
    return ((p.x / 2 + p.y / 2) & 1) == 0;
}

// One lane per pixel of the shaded quads only: {{QUADS}} quads of 4 lanes per workgroup, along
// one row of quads (workgroup y), every other quad (shifted on odd rows).
@compute @workgroup_size({{WORKGROUP}}, 1, 1)
fn {{ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    let mrsl_qy = i32(mrsl_wg.y);
    // Forced refinement shades every quad (the runtime dispatches twice as many).
    let mrsl_k = i32(mrsl_wg.x) * {{QUADS}} + i32(mrsl_li / 4u);
    let mrsl_qx = select(2 * mrsl_k + (mrsl_qy & 1), mrsl_k, mrsl_ctl.force_refine != 0u);
    let mrsl_pos = vec2<i32>(mrsl_qx * 2 + i32(mrsl_li % 2u), mrsl_qy * 2 + i32((mrsl_li / 2u) % 2u));
    if (any(mrsl_pos >= mrsl_grid())) { return; }
{{#EFFECTS}}
}

