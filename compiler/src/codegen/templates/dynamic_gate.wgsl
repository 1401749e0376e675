    // Shade this {{INNER}}x{{INNER}} sample only where a {{OUTER}}x{{OUTER}} block around it was refined; the fine
    // kernel treats an untagged (skipped) corner as a reason to shade per pixel.
    if (!mrsl_parent_refined(mrsl_pixel(mrsl_pos))) { return; }
    if ({{STATISTICS_ON}}) { atomicAdd(&mrsl_stats[{{SAMPLES}}], 1u); }
    mrsl_interface[mrsl_rec + MRSL_STRIDE - 1u] = mrsl_ctl.frame + 1u;
