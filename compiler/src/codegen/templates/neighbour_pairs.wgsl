    for (var k = 0; k < 4; k++) {
        ok[k] = all({{POINTS}}[k] >= vec2<i32>(0)) && all({{POINTS}}[k] < size);
{{#TAP_TESTS}}
    }
{{#NOTE}}
    let {{A}} = ok[0] && ok[1];
    let {{B}} = ok[2] && ok[3];
