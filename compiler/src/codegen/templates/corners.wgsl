// The four coarse samples around a block as the fine kernel reads them: each
// discontinuity key at their pixels (`k00_<key>`, `k10_`, `k01_`, `k11_`) and word w
// of their records (`w<w>`: c00, c10, c01, c11). A lane loads them once for the
// pixels it shades in the block; the shader compiler drops the loads a caller never
// reads.
struct MrslCorners {
{{#FIELDS}}
}

fn mrsl_corners(pos: vec2<i32>) -> MrslCorners {
{{GEOMETRY}}
    var c: MrslCorners;
{{#LOADS}}
    return c;
}

