        let mrsl_r0 = mrsl_rec(mrsl_pos);
        if ({{STATISTICS_ON}}) {
            let mrsl_mask = mrsl_values[mrsl_r0 + {{FLAG_WORDS}}u];
            textureStore(mrsl_rate, mrsl_pos, vec4<u32>(mrsl_mask, 0u, 0u, 1u));
{{#COUNTS}}
        }
