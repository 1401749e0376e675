
// Whether sample `i` is one of those whose records the workgroup holds.
fn mrsl_is_record(i: vec2<i32>) -> bool {
    let r = i - mrsl_origin + vec2<i32>(MRSL_RING);
    return all(r >= vec2<i32>(0)) && all(r < vec2<i32>(MRSL_TILE + 1 + MRSL_RING));
}
