fn mrsl_ddx_{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    let mrsl_q = mrsl_pair_x(mrsl_pos);
    return mrsl_d{{SITE}}(mrsl_q.zw{{ARGS}}) - mrsl_d{{SITE}}(mrsl_q.xy{{ARGS}});
}
fn mrsl_ddy_{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    let mrsl_q = mrsl_pair_y(mrsl_pos);
    return mrsl_d{{SITE}}(mrsl_q.zw{{ARGS}}) - mrsl_d{{SITE}}(mrsl_q.xy{{ARGS}});
}

