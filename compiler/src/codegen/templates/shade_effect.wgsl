var {{VAR}}: {{TYPE}};
if ((mrsl_pmask{{MASK_WORD}} & {{MASK}}u) != 0u) {
{{#EVALUATE}}
    mrsl_hput_{{NAME}}(mrsl_pos, {{VAR}});
{{#FLAG}}
} else {
    {{VAR}} = mrsl_hget_{{NAME}}(mrsl_pos);
}
mrsl_pv_{{NAME}} = {{VAR}};
