// derivative operand #{{SITE}} in `{{EFFECT}}`: {{TEXT}}
fn mrsl_d{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    return {{OPERAND}};
}
{{#DIFFERENCES}}
// The differences across the pixel's quad pair. The caller passes the operand at
// `mrsl_pos` itself (`mrsl_here`, the value it already has), so only the pair's other
// position is evaluated: for an effect, one evaluation at a neighbour instead of two.
// That position is chosen by `select`, not by a branch: lanes on both sides of their
// pairs would run both sides of a branch on a SIMD machine, evaluating it twice.
fn mrsl_ddx_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    {{#LEVELS_X}}
    let mrsl_q = mrsl_pair_x(mrsl_pos);
    let mrsl_second = all(mrsl_q.zw == mrsl_pos);
    let mrsl_there = mrsl_d{{SITE}}(select(mrsl_q.zw, mrsl_q.xy, mrsl_second){{ARGS}});
    let mrsl_difference = select(mrsl_there - mrsl_here, mrsl_here - mrsl_there, mrsl_second);
    return select(mrsl_difference, {{TYPE}}(), all(mrsl_q.xy == mrsl_q.zw));
}
fn mrsl_ddy_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    {{#LEVELS_Y}}
    let mrsl_q = mrsl_pair_y(mrsl_pos);
    let mrsl_second = all(mrsl_q.zw == mrsl_pos);
    let mrsl_there = mrsl_d{{SITE}}(select(mrsl_q.zw, mrsl_q.xy, mrsl_second){{ARGS}});
    let mrsl_difference = select(mrsl_there - mrsl_here, mrsl_here - mrsl_there, mrsl_second);
    return select(mrsl_difference, {{TYPE}}(), all(mrsl_q.xy == mrsl_q.zw));
}
