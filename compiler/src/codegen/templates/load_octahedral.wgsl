// Channel `{{NAME}}`: a unit vector stored as two octahedral components.
fn mrsl_load_{{NAME}}(pos: vec2<i32>) -> vec3<f32> {
    return mrsl_octahedral(textureLoad(mrsl_gb_{{NAME}}, mrsl_pixel(pos){{LEVEL}}).xy{{UNORM}});
}

