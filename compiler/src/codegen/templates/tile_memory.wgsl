// The tile: {{SAMPLES}}x{{SAMPLES}} blocks per workgroup (layout `tile`). The workgroup holds the
// records of the samples `mrsl_origin - MRSL_RING` to `mrsl_origin + MRSL_TILE` along each
// axis (the tile's own, the next tile's first row and column, and MRSL_RING before it):
// word w of slot s at `w * MRSL_RECORD_SLOTS + s`. It holds the neighbour values (layout
// `neighbours`) of one sample more on every side, which the samples' derivatives read.
const MRSL_TILE: i32 = {{SAMPLES}};
const MRSL_RING: i32 = {{RING}};
const MRSL_RECORD_SLOTS: u32 = {{RECORD_SLOTS}}u;
const MRSL_NEIGHBOUR_SLOTS: u32 = {{NEIGHBOUR_SLOTS}}u;
// The tile's first coarse sample, set by the entry point.
var<private> mrsl_origin: vec2<i32>;
var<workgroup> mrsl_wg_records: array<u32, {{RECORD_WORDS}}>;
{{#NEIGHBOURS}}

// Where sample `i` sits among the workgroup's records.
fn mrsl_record_slot(i: vec2<i32>) -> u32 {
    let r = i - mrsl_origin + vec2<i32>(MRSL_RING);
    return u32(r.y * (MRSL_TILE + 1 + MRSL_RING) + r.x);
}

// Where sample `i` sits among the workgroup's neighbour values.
fn mrsl_neighbour_slot(i: vec2<i32>) -> u32 {
    let r = i - mrsl_origin + vec2<i32>(MRSL_RING + 1);
    return u32(r.y * (MRSL_TILE + 3 + MRSL_RING) + r.x);
}

