// The differences across the sample's quad pair, on the effect's own surface: where
// the pair's other sample lies across one of the effect's keys, the difference is
// taken with the sample on the other side instead (a one-sided difference), unless
// that one lies across a key too or outside the grid (a sliver: then the pair's).
// The keys already keep the resampling from blending across such an edge; a
// predicate that measured the step there would refine what the keys handle.
{{#AXIS}}
fn {{DIFFERENCE}}({{PARAMS}}, mrsl_here: {{TYPE}}) -> {{TYPE}} {
    let mrsl_q = {{PAIR}}(mrsl_pos);
    let mrsl_other = select(mrsl_q.zw, mrsl_q.xy, all(mrsl_q.zw == mrsl_pos));
    let mrsl_mirror = clamp(2 * mrsl_pos - mrsl_other, vec2<i32>(0), mrsl_grid() - vec2<i32>(1));
    let mrsl_flip = {{APART}}(mrsl_pos, mrsl_other) && any(mrsl_mirror != mrsl_pos) && !{{APART}}(mrsl_pos, mrsl_mirror);
    let mrsl_taken = select(mrsl_other, mrsl_mirror, mrsl_flip);
    let mrsl_there = mrsl_d{{SITE}}(mrsl_taken{{ARGS}});
    let mrsl_difference = select(mrsl_here - mrsl_there, mrsl_there - mrsl_here, mrsl_taken.{{AXIS}} > mrsl_pos.{{AXIS}});
    return select(mrsl_difference, {{TYPE}}(), all(mrsl_taken == mrsl_pos));
}
