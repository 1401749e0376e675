fn mrsl_reconstruct_{{NAME}}(p: vec2<i32>, ok: array<bool, 4>) -> {{TYPE}} {
    let taps = {{TAPS}};
{{#BLEND}}
    var sum = {{TYPE}}();
    var n = 0.0;
    for (var k = 0; k < 4; k++) {
        if (ok[k]) { sum = sum + mrsl_hget_{{NAME}}(taps[k]); n += 1.0; }
    }
    return sum * (1.0 / n);
{{#FIRST_TAP}}
    // Not blendable: the first usable tap.
    for (var k = 0; k < 4; k++) {
        if (ok[k]) { return mrsl_hget_{{NAME}}(taps[k]); }
    }
    return mrsl_hget_{{NAME}}(p);
{{#END}}
}
