// Pixels of a lattice starting at `start` with step `step` along one axis of length `n`.
fn mrsl_count(start: u32, step: u32, n: u32) -> u32 {
    return select(0u, (n - start - 1u) / step + 1u, n > start);
}

// Start of each level's work list: levels 1..4 take at most their dispatch grid's size.
fn mrsl_work_offset(level: u32) -> u32 {
    let w = mrsl_ctl.size.x;
    let h = mrsl_ctl.size.y;
{{#LEVEL_SIZES}}
    return {{OFFSET}};
}

