// Channel `{{NAME}}`: `{{FIELD}}` of Bevy's deferred G-buffer texel.
fn mrsl_load_{{NAME}}(pos: vec2<i32>) -> {{TYPE}} {
    {{#KNOWN}}
    let g = textureLoad(mrsl_gb_{{NAME}}, mrsl_pixel(pos){{LEVEL}});
    return {{VALUE}};
}

