// Evaluates the coarse effects `mrsl_pos`'s mask names (reading the others), stores
// their values and refine flags, and writes the pixel's outputs: its record is complete.
fn mrsl_shade(mrsl_pos: vec2<i32>) {
{{#FLAG_WORDS}}
    let mrsl_force = mrsl_ctl.force_refine != 0u;
{{#EFFECTS}}
    mrsl_finish(mrsl_pos);
}

