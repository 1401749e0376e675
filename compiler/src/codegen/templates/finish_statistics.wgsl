    if ({{STATISTICS_ON}}) {
{{#MASKS}}
        textureStore(mrsl_refine_mask, mrsl_pos, vec4<u32>({{MASK_X}}, {{MASK_Y}}, 0u, 1u));
{{#COUNTS}}
    }
