// Its differences at every level that evaluates predicates, level 0 included (whose
// neighbours' values `hier_level0_values` stored): from the level's neighbours.
fn mrsl_ddx_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    return mrsl_dl{{SITE}}(mrsl_pos{{ARGS}}, mrsl_here)[0];
}
fn mrsl_ddy_{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    return mrsl_dl{{SITE}}(mrsl_pos{{ARGS}}, mrsl_here)[1];
}
