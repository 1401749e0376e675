fn mrsl_hget_{{NAME}}(p: vec2<i32>) -> {{TYPE}} {
    return {{UNPACK}};
}
fn mrsl_hput_{{NAME}}(p: vec2<i32>, v: {{TYPE}}) {
{{#STORES}}
}
