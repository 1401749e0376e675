// Reconstruction of a pixel in an unshaded quad from the pixels at the same place in the
// edge-adjacent quads, (x +- 2, y) and (x, y +- 2), which are all shaded. Taps across a
// discontinuity key are rejected, and only complete opposite pairs are used (a centred
// mean, exact for linear values). `ok` is all false when no pair is usable: the pixel is
// then shaded in place.
fn mrsl_taps(p: vec2<i32>) -> array<bool, 4> {
    let size = vec2<i32>(mrsl_ctl.size);
    let taps = {{TAPS}};
    var ok: array<bool, 4>;
{{#IN_IMAGE}}
{{#PAIRS}}
    // Without a complete pair the pixel is shaded in place: one-sided means would extrapolate.
    return array<bool, 4>(pair_x, pair_x, pair_y, pair_y);
}

