    // The neighbours across key `{{NAME}}`.
    let k_{{NAME}} = {{LOAD}}(p);
    var across_{{NAME}}: array<bool, 4>;
    for (var k = 0; k < 4; k++) {
        across_{{NAME}}[k] = inside[k] && {{DIFFERS}};
    }
