var mrsl_b2 = mrsl_b;
if (mrsl_any_refined(mrsl_b)) { mrsl_b2 = mrsl_resolve2{{NAME}}(mrsl_pos, mrsl_b); }
