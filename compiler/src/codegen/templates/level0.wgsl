// Level 0: every {{STEP}}th pixel in both directions is shaded.
@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = {{PIXEL}};
    if (any(p >= vec2<i32>(mrsl_ctl.size))) { return; }
{{#MASKS}}
    mrsl_shade(p);
}

