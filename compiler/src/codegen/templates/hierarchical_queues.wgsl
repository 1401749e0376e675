@group({{GROUP}}) @binding({{WORK_BINDING}}) var<storage, read_write> mrsl_work: array<u32>;
@group({{GROUP}}) @binding({{QUEUE_BINDING}}) var<storage, read_write> mrsl_queue: array<atomic<u32>>;
// Indirect dispatch arguments, bound only for the `hier_args_*` entry points (the
// levels' arguments) and `fine_tile_args` (the tile lists').
@group({{ARGS_GROUP}}) @binding({{ARGS_BINDING}}) var<storage, read_write> mrsl_args: array<u32>;
