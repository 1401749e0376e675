// Evaluates the coarse effects `mrsl_pos`'s mask names (reading the others) and stores
// their values{{WHAT}}: the pixel's record is then complete.
fn {{NAME}}(mrsl_pos: vec2<i32>) {
{{#FLAG_WORDS}}
    let mrsl_force = mrsl_ctl.force_refine != 0u;
{{#EFFECTS}}
}

