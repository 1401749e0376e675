// {{WHAT}}
@group({{GROUP}}) @binding({{BINDING}}) var<storage, read_write> mrsl_values: array<u32>;
