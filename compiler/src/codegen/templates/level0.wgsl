// Level 0's pixel `p`: every coarse effect is shaded (none at a background pixel).
fn mrsl_level0(p: vec2<i32>) {
{{#MASKS}}
    mrsl_shade(p);
}

// Level 0: every {{STEP}}th pixel in both directions is shaded.
@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}({{PARAMS}}) {
{{#INVOCATION}}
    let p = {{PIXEL}};
    if ({{VALID}}all(p < vec2<i32>(mrsl_ctl.size))) {
        mrsl_level0(p);
        mrsl_finish(p);
    }
{{#FLUSH}}
}

