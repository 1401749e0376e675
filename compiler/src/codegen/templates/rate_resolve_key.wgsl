    // discontinuity key `{{NAME}}`: the pixel against every sample it resamples from,
    // and the cell's corners against each other
    let k_{{NAME}} = mrsl_load_{{NAME}}(pos);
    let k0_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.corners.x));
    let k1_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.corners.y));
    let k2_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.corners.z));
    let k3_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.corners.w));
    let k4_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.others.x));
    let k5_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.others.y));
    let k6_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.others.z));
    let k7_{{NAME}} = mrsl_load_{{NAME}}(mrsl_sample_pixel(b.others.w));
    let disc_{{NAME}} = {{TESTS}};
