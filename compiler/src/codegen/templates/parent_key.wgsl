        let k00_{{NAME}} = {{LOAD}}(min(i0 * {{BLOCK}}, size - vec2<i32>(1)));
        let k10_{{NAME}} = {{LOAD}}(min(vec2<i32>(i1.x, i0.y) * {{BLOCK}}, size - vec2<i32>(1)));
        let k01_{{NAME}} = {{LOAD}}(min(vec2<i32>(i0.x, i1.y) * {{BLOCK}}, size - vec2<i32>(1)));
        let k11_{{NAME}} = {{LOAD}}(min(i1 * {{BLOCK}}, size - vec2<i32>(1)));
        refined = refined || {{TESTS}};
