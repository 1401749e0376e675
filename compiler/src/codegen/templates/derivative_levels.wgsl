// derivative operand #{{SITE}} at a pixel whose values are known (its complete record, or
// at level 0 the values stored before it): its effects are read (`mrsl_stored_<effect>`).
fn mrsl_dr{{SITE}}({{PARAMS}}) -> {{TYPE}} {
    return {{STORED}};
}
// Its differences per pixel along x and y at hierarchical level `mrsl_level` (1 to 3, and 0
// where its neighbours' values are stored first), from four neighbours complete before the
// level is shaded, so no effect is evaluated at another position. Central differences
// over the opposite pairs (0, 1) and (2, 3), weighted by `mrsl_level_weights`; a
// neighbour outside the image is its opposite mirrored through the pixel (a one-sided
// difference, exact for a linear operand), and a pair with both outside differs by 0.
fn mrsl_dl{{SITE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> array<{{TYPE}}, 2> {
    let mrsl_near = mrsl_level_neighbours(mrsl_pos);
    var mrsl_inside: array<bool, 4>;
    var mrsl_loaded: array<{{TYPE}}, 4>;
    for (var k = 0; k < 4; k++) {
        mrsl_inside[k] = all(mrsl_near[k] >= vec2<i32>(0)) && all(mrsl_near[k] < vec2<i32>(mrsl_ctl.size));
        mrsl_loaded[k] = select(mrsl_here, mrsl_dr{{SITE}}(select(mrsl_pos, mrsl_near[k], mrsl_inside[k]){{ARGS}}), mrsl_inside[k]);
    }
    var mrsl_vals: array<{{TYPE}}, 4>;
    for (var k = 0; k < 4; k++) {
        mrsl_vals[k] = select(2.0 * mrsl_here - mrsl_loaded[k ^ 1], mrsl_loaded[k], mrsl_inside[k]);
    }
    let mrsl_along = mrsl_vals[1] - mrsl_vals[0];
    let mrsl_across = mrsl_vals[2] - mrsl_vals[3];
    let mrsl_weights = mrsl_level_weights();
    return array<{{TYPE}}, 2>(
        mrsl_along * mrsl_weights.x + mrsl_across * mrsl_weights.y,
        mrsl_along * mrsl_weights.z + mrsl_across * mrsl_weights.w);
}
