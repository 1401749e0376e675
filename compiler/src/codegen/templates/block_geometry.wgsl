    let size = vec2<i32>(mrsl_ctl.size);
    let n = {{GRID}};
    let i0 = pos / {{BLOCK}};
    let i1 = min(i0 + vec2<i32>(1), n - vec2<i32>(1));
    let p0 = min(i0 * {{BLOCK}}, size - vec2<i32>(1));
    let p1 = min(i1 * {{BLOCK}}, size - vec2<i32>(1));
