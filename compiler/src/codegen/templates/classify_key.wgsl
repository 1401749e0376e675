    let k_{{NAME}} = {{LOAD}}(p);
    var disc_{{NAME}} = false;
    for (var k = 0; k < 4; k++) {
        disc_{{NAME}} = disc_{{NAME}} || (ok[k] && {{DIFFERS}});
    }
