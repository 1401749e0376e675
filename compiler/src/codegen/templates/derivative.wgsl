// derivative operand #{{SITE}} in `{{EFFECT}}`: {{TEXT}}
fn mrsl_d{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    return {{OPERAND}};
}
{{#DIFFERENCES}}
// The differences across the pixel's quad pair. The caller passes the operand at
// `mrsl_pos` itself (`mrsl_here`, the value it already has), so only the pair's other
// position is evaluated: for an effect, one evaluation at a neighbour instead of two.
fn mrsl_ddx_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    let mrsl_q = mrsl_pair_x(mrsl_pos);
    if (all(mrsl_q.xy == mrsl_q.zw)) { return {{TYPE}}(); }
    if (all(mrsl_q.zw == mrsl_pos)) { return mrsl_here - mrsl_d{{SITE}}(mrsl_q.xy{{ARGS}}); }
    return mrsl_d{{SITE}}(mrsl_q.zw{{ARGS}}) - mrsl_here;
}
fn mrsl_ddy_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    let mrsl_q = mrsl_pair_y(mrsl_pos);
    if (all(mrsl_q.xy == mrsl_q.zw)) { return {{TYPE}}(); }
    if (all(mrsl_q.zw == mrsl_pos)) { return mrsl_here - mrsl_d{{SITE}}(mrsl_q.xy{{ARGS}}); }
    return mrsl_d{{SITE}}(mrsl_q.zw{{ARGS}}) - mrsl_here;
}

