// Word k of pixel p's record: component k % 4 of layer k / 4 of the record
// texture (four words per texel).
fn mrsl_word(p: vec2<i32>, k: u32) -> u32 {
    return textureLoad(mrsl_values, p, i32(k / 4u))[k % 4u];
}

// A pixel's record, a texel per four words: loaded whole, so that reading
// several of its words costs a load per texel, not per word.
alias MrslRecord = array<vec4<u32>, {{TEXELS}}>;

fn mrsl_record(p: vec2<i32>) -> MrslRecord {
    return MrslRecord({{LOADS}});
}

