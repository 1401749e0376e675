// The neighbour values at sample `mrsl_pos`, into slot `mrsl_slot` of the workgroup's.
fn mrsl_tile_neighbours(mrsl_pos: vec2<i32>, mrsl_slot: u32) {
{{#BODY}}
}

