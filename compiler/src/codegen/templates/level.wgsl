// Level {{LEVEL}}: {{WHAT}}.
@compute @workgroup_size({{CLASSIFY_WORKGROUP}})
fn {{CLASSIFY}}({{PARAMS}}) {
{{#INVOCATION}}
    let p = {{PIXEL}};
    // One call of mrsl_finish per entry point: a device that runs every branch
    // with its lanes masked (llvmpipe) would run each call site.
    if ({{VALID}}all(p < vec2<i32>(mrsl_ctl.size))) {
        if (mrsl_classify(p, {{NEIGHBOURS}}, {{LEVEL}}u)) {
            mrsl_finish(p);
        }
    }
{{#FLUSH_CLASSIFY}}
}

@compute @workgroup_size(1, 1, 1)
fn {{ARGS}}() {
    let count = atomicLoad(&mrsl_queue[{{QUEUE}}u]);
    mrsl_args[{{ARGS_X}}u] = (count + {{WORK_GROUP_LESS_1}}u) / {{WORK_GROUP}}u;
    mrsl_args[{{ARGS_Y}}u] = 1u;
    mrsl_args[{{ARGS_Z}}u] = 1u;
}

// Shades the compacted work list of the level: every lane has a pixel to shade.
@compute @workgroup_size({{WORK_GROUP}}, 1, 1)
fn {{SHADE}}(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) mrsl_li: u32) {
    if (gid.x < atomicLoad(&mrsl_queue[{{QUEUE}}u])) {
        let index = mrsl_work[mrsl_work_offset({{LEVEL}}u) + gid.x];
        let listed = vec2<i32>(i32(index % mrsl_ctl.size.x), i32(index / mrsl_ctl.size.x));
        {{#SET_LEVEL}}
        {{SHADE_PIXEL}}(listed);
        mrsl_finish(listed);
    }
{{#FLUSH_SHADE}}
}

