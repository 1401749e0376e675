        let mrsl_shaded = mrsl_shaded_quad(mrsl_pos) || mrsl_ctl.force_refine != 0u;
        let mrsl_ok = mrsl_taps(mrsl_pos);
        // No usable tap (isolated by discontinuities): shaded here instead.
        let mrsl_alone = !mrsl_shaded && !(mrsl_ok[0] || mrsl_ok[1] || mrsl_ok[2] || mrsl_ok[3]);{{BACKGROUND}}
{{#STATS}}
        if ({{STATISTICS_ON}}) {
            textureStore(mrsl_refine_mask, mrsl_pos, vec4<u32>(select(0u, {{ALL}}u, {{EVALUATED}}), {{MASK_Y}}, 0u, 1u));
            if ({{EVALUATED}}) {
{{#COUNTS}}
            }{{BACKGROUND_COUNT}}
        }
