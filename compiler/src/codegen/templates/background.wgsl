// The background rule: whether nothing was drawn at `pos`. There every
// coarse effect reads as zero, is not evaluated and is not refined.
fn mrsl_background(pos: vec2<i32>) -> bool {
    return {{TESTS}};
}

