// Coarse sample `mrsl_pos` of the tile: its coarse effects, refine flags and record, into
// slot `mrsl_slot` of the workgroup's records. `mrsl_owned`: the sample counts towards the
// statistics here (it is evaluated by every workgroup whose pixels resample from it).
fn mrsl_tile_sample(mrsl_pos: vec2<i32>, mrsl_slot: u32, mrsl_owned: bool) {
{{#BODY}}
}

