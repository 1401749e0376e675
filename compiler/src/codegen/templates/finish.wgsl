// Pixel `mrsl_pos`'s outputs, written where its record is complete: from the coarse
// values its invocation just stored (`mrsl_pv_*`) and its fine effects.
fn mrsl_finish(mrsl_pos: vec2<i32>) {
{{#STATISTICS}}
{{#BODY}}
}

