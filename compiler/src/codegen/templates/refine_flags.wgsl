    // Refine flags (all set when the runtime forces refinement).
    let mrsl_force = mrsl_ctl.force_refine != 0u;
