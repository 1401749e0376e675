    // discontinuity key `{{NAME}}`
    let k_{{NAME}} = mrsl_load_{{NAME}}(pos);
    let k00_{{NAME}} = mrsl_load_{{NAME}}(p0);
    let k10_{{NAME}} = mrsl_load_{{NAME}}(vec2<i32>(p1.x, p0.y));
    let k01_{{NAME}} = mrsl_load_{{NAME}}(vec2<i32>(p0.x, p1.y));
    let k11_{{NAME}} = mrsl_load_{{NAME}}(p1);
    let disc_{{NAME}} = {{TESTS}};
