    // discontinuity key `{{NAME}}`
    let k_{{NAME}} = {{LOAD}}(pos);
    let k00_{{NAME}} = {{K00}};
    let k10_{{NAME}} = {{K10}};
    let k01_{{NAME}} = {{K01}};
    let k11_{{NAME}} = {{K11}};
    let side_{{NAME}} = vec4<bool>({{SIDE}}); // the corners on the pixel's side of the key
