// {{WHAT}}
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_values: texture_storage_2d_array<r32uint, read_write>;
