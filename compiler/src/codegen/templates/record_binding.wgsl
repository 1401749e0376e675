// {{WHAT}}
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_values: texture_storage_2d_array<{{FORMAT}}, read_write>;
