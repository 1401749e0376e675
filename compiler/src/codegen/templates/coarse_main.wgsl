@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}(@builtin(global_invocation_id) mrsl_gid: vec3<u32>) {
    let mrsl_n = mrsl_grid();
    if (mrsl_gid.x >= u32(mrsl_n.x) || mrsl_gid.y >= u32(mrsl_n.y)) { return; }
    let mrsl_pos = vec2<i32>(mrsl_gid.xy);{{RECORD}}
{{#BODY}}
}
