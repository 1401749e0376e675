// The coarse samples to shade, packed x | y << 16, and their count (word 0).
@group({{GROUP}}) @binding({{WORK_BINDING}}) var<storage, read_write> mrsl_work: array<u32>;
@group({{GROUP}}) @binding({{QUEUE_BINDING}}) var<storage, read_write> mrsl_queue: array<atomic<u32>>;
// Indirect dispatch arguments of `{{COARSE}}`, bound only for `{{ARGS}}`.
@group({{ARGS_GROUP}}) @binding({{ARGS_BINDING}}) var<storage, read_write> mrsl_args: array<u32>;
