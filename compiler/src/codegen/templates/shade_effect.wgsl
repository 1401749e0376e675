var {{VAR}}: {{TYPE}};
if ((mrsl_pmask{{MASK_WORD}} & {{MASK}}u) != 0u) {
{{#EVALUATE}}
{{#PUT}}
{{#FLAG}}
} else {
    {{VAR}} = mrsl_hget_{{NAME}}({{OWN}});
}
mrsl_pv_{{NAME}} = {{VAR}};
