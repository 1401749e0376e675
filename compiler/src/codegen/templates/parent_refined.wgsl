fn mrsl_parent_refined(p: vec2<i32>) -> bool {
    let size = vec2<i32>(mrsl_ctl.size);
    let n = {{GRID}};
    var refined = mrsl_ctl.force_refine != 0u;
    for (var k = 0; k < 4; k++) {
        let q = clamp(p + vec2<i32>(select(-2, 1, (k & 1) != 0), select(-2, 1, (k & 2) != 0)), vec2<i32>(0), size - vec2<i32>(1));
        let i0 = q / {{BLOCK}};
        let i1 = min(i0 + vec2<i32>(1), n - vec2<i32>(1));
        let corners = array<vec2<i32>, 4>(i0, vec2<i32>(i1.x, i0.y), vec2<i32>(i0.x, i1.y), i1);
        for (var j = 0; j < 4; j++) {
{{#FLAGS}}
        }
{{#KEYS}}
    }
    return refined;
}

