@group({{GROUP}}) @binding({{WORK_BINDING}}) var<storage, read_write> mrsl_work: array<u32>;
@group({{GROUP}}) @binding({{QUEUE_BINDING}}) var<storage, read_write> mrsl_queue: array<atomic<u32>>;
// Indirect dispatch arguments, bound only for the `hier_args_*` entry points.
@group({{ARGS_GROUP}}) @binding({{ARGS_BINDING}}) var<storage, read_write> mrsl_args: array<u32>;
