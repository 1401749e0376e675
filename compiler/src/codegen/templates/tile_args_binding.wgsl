@group({{ARGS_GROUP}}) @binding({{ARGS_BINDING}}) var<storage, read_write> mrsl_args: array<u32>;
