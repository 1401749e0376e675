fn mrsl_hget_{{NAME}}(p: vec2<i32>) -> {{TYPE}} {
    let base = mrsl_rec(p) + {{OFFSET}}u;
    return {{UNPACK}};
}
fn mrsl_hput_{{NAME}}(p: vec2<i32>, v: {{TYPE}}) {
    let base = mrsl_rec(p) + {{OFFSET}}u;
{{#STORES}}
}
