// derivative operand #{{SITE}} at a pixel whose record is complete: the effects it
// reads are taken from the record (`mrsl_stored_<effect>`), not evaluated.
fn mrsl_dr{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    return {{STORED}};
}
// Its differences per pixel along x and y at hierarchical level `mrsl_level` (1 to 3),
// from the four neighbours the level interpolates from: those are complete before the
// level is shaded, so no effect is evaluated at another position. Central differences
// over the opposite pairs (0, 1) and (2, 3), weighted by `mrsl_level_weights`; a
// neighbour outside the image counts as the pixel itself.
fn mrsl_dl{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> array<{{TYPE}}, 2> {
    let mrsl_near = mrsl_level_neighbours(mrsl_pos);
    var mrsl_vals: array<{{TYPE}}, 4>;
    for (var k = 0; k < 4; k++) {
        let mrsl_inside = all(mrsl_near[k] >= vec2<i32>(0)) && all(mrsl_near[k] < vec2<i32>(mrsl_ctl.size));
        mrsl_vals[k] = select(mrsl_here, mrsl_dr{{SITE}}(select(mrsl_pos, mrsl_near[k], mrsl_inside){{ARGS}}), mrsl_inside);
    }
    let mrsl_along = mrsl_vals[1] - mrsl_vals[0];
    let mrsl_across = mrsl_vals[2] - mrsl_vals[3];
    let mrsl_weights = mrsl_level_weights();
    return array<{{TYPE}}, 2>(
        mrsl_along * mrsl_weights.x + mrsl_across * mrsl_weights.y,
        mrsl_along * mrsl_weights.z + mrsl_across * mrsl_weights.w);
}
