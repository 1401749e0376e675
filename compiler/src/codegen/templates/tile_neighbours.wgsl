// Wave {{WAVE}} of the neighbour values at sample `mrsl_pos`, into slot `mrsl_slot` of the workgroup's.
fn {{NAME}}(mrsl_pos: vec2<i32>, mrsl_slot: u32) {
{{#BODY}}
}

