// `{{NAME}}`'s part of `mrsl_classify`.
fn mrsl_classify_{{NAME}}({{PARAMS}}) {
    // The neighbours it interpolates: its complete opposite pairs (0, 1) and (2, 3)
    // of neighbours on p's side of every key it reads, so that interpolation stays
    // centred (exact for linear values). With no complete pair, p is shaded.
    var on_side: array<bool, 4>;
    for (var k = 0; k < 4; k++) {
        on_side[k] = inside[k]{{ON_SIDE}};
    }
    let pair_a = on_side[0] && on_side[1];
    let pair_b = on_side[2] && on_side[3];
    var ok = array<bool, 4>(pair_a, pair_a, pair_b, pair_b);
    var total = 0.0;
    for (var k = 0; k < 4; k++) {
        total += select(0.0, 1.0, ok[k]);
    }
    let disc = force || !(pair_a || pair_b);
    let v0 = mrsl_hget_{{NAME}}({{FROM}}[0]);
    let v1 = mrsl_hget_{{NAME}}({{FROM}}[1]);
    let v2 = mrsl_hget_{{NAME}}({{FROM}}[2]);
    let v3 = mrsl_hget_{{NAME}}({{FROM}}[3]);
{{#TESTS}}
    if ({{NEED}}) {
        *mask{{WORD}} |= {{MASK}}u;
    } else {
{{#PUT}}
        mrsl_pv_{{NAME}} = {{VALUE}};
    }
}
