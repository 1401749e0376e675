    let k_{{NAME}} = mrsl_load_{{NAME}}(p);
    var disc_{{NAME}} = false;
    for (var k = 0; k < 4; k++) {
        disc_{{NAME}} = disc_{{NAME}} || (ok[k] && {{DIFFERS}});
    }
