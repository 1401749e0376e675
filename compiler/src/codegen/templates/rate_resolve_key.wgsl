    // discontinuity key `{{NAME}}`: the pixel against every sample it resamples from,
    // and the cell's corners against each other
    let k_{{NAME}} = {{LOAD}}(pos);
    let k0_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.corners.x));
    let k1_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.corners.y));
    let k2_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.corners.z));
    let k3_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.corners.w));
    var k4_{{NAME}} = k0_{{NAME}};
    var k5_{{NAME}} = k1_{{NAME}};
    var k6_{{NAME}} = k2_{{NAME}};
    var k7_{{NAME}} = k3_{{NAME}};
    if (blended) {
        k4_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.others.x));
        k5_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.others.y));
        k6_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.others.z));
        k7_{{NAME}} = {{LOAD}}(mrsl_sample_pixel(b.others.w));
    }
    let disc_{{NAME}} = {{TESTS}};
