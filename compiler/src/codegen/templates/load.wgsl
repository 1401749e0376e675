fn mrsl_load_{{NAME}}(pos: vec2<i32>) -> {{TYPE}} {
    {{#KNOWN}}
    return textureLoad(mrsl_gb_{{NAME}}, mrsl_pixel(pos){{LEVEL}}){{SWIZZLE}};
}

