    if ({{STATISTICS_ON}}) {
        let mrsl_mask = mrsl_word(mrsl_pos, {{FLAG_WORDS}}u);
        textureStore(mrsl_refine_mask, mrsl_pos, vec4<u32>(mrsl_mask, {{MASK_Y}}, 0u, 1u));
{{#COUNTS}}
    }
