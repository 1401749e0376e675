@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}(@builtin(workgroup_id) mrsl_wg: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    {{#LISTED}}
    let {{FIRST}} = mrsl_tile_pixel({{TILE}}, mrsl_li);
