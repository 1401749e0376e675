var {{VAR}}: {{TYPE}};
{{ZERO}}if (mrsl_shaded) { {{VAR}} = mrsl_hget_{{NAME}}(mrsl_pos); }
else if (!mrsl_alone) { {{VAR}} = mrsl_reconstruct_{{NAME}}(mrsl_pos, mrsl_ok); }
else {
{{#EVALUATE}}
}
