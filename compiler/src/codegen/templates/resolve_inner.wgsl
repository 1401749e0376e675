var {{INNER}} = {{OUTER}};
if (mrsl_any_refined({{OUTER}})) { {{INNER}} = mrsl_resolve2{{NAME}}({{POS}}, {{OUTER}}); }
