// Word k of pixel p's record: layer k of the record texture (a texel per pixel).
fn mrsl_word(p: vec2<i32>, k: u32) -> u32 {
    return textureLoad(mrsl_values, p, i32(k)).x;
}

fn mrsl_set_word(p: vec2<i32>, k: u32, v: u32) {
    textureStore(mrsl_values, p, i32(k), vec4<u32>(v, 0u, 0u, 0u));
}

