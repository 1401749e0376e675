    // `{{NAME}}`
    {
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
