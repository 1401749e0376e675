// Level 0's pixel `p`: every coarse effect is shaded (none at a background pixel).
fn mrsl_level0(p: vec2<i32>) {
{{#MASKS}}
    mrsl_shade(p);
}

// Level 0: every {{STEP}}th pixel in both directions is shaded.
@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    let p = {{PIXEL}};
    if (all(p < vec2<i32>(mrsl_ctl.size))) {
        mrsl_level0(p);
        mrsl_finish(p);
    }
{{#FLUSH}}
}

