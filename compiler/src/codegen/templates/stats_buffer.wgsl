@group({{GROUP}}) @binding({{BINDING}}) var<storage, read_write> mrsl_stats: array<atomic<u32>>;
