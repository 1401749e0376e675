    let k_{{NAME}} = mrsl_load_{{NAME}}(p);
    for (var k = 0; k < 4; k++) {
        disc = disc || (ok[k] && {{DIFFERS}});
    }
