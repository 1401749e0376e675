let mrsl_last = {{LAST}};
textureStore(mrsl_refine_mask, mrsl_pos, vec4<u32>({{MASK_X}}, {{FROM_INNER}}, 0u, 1u));
