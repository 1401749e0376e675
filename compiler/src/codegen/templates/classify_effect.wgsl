    // `{{NAME}}`
    {
        // The neighbours it interpolates: its complete opposite pairs (0, 1) and (2, 3)
        // (centred: exact for linear values); where a key leaves no pair complete, the
        // two on p's side. With fewer, or none complete at the image border, p is shaded.
        var ok: array<bool, 4>;
        for (var k = 0; k < 4; k++) {
            ok[k] = inside[k]{{ON_SIDE}};
        }
        let pair_a = ok[0] && ok[1];
        let pair_b = ok[2] && ok[3];
        if (pair_a || pair_b) {
            ok = array<bool, 4>(pair_a, pair_a, pair_b, pair_b);
        }
        var total = 0.0;
        for (var k = 0; k < 4; k++) {
            total += select(0.0, 1.0, ok[k]);
        }
        let disc = force || total < 2.0 || !(pair_a || pair_b || all_inside);
        let v0 = mrsl_hget_{{NAME}}(q[0]);
        let v1 = mrsl_hget_{{NAME}}(q[1]);
        let v2 = mrsl_hget_{{NAME}}(q[2]);
        let v3 = mrsl_hget_{{NAME}}(q[3]);
{{#TESTS}}
        if ({{NEED}}) {
            mask{{WORD}} |= {{MASK}}u;
        } else {
            mrsl_hput_{{NAME}}(p, {{VALUE}});
        }
    }
