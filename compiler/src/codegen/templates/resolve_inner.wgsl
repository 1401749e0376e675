var {{INNER}} = {{OUTER}};
if (mrsl_any_refined({{OUTER}})) { {{INNER}} = mrsl_resolve{{LEVEL}}{{NAME}}({{POS}}, {{OUTER}}); }
