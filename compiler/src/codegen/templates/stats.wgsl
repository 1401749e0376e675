// Statistics: element k counts the pixels that re-evaluated coarse effect k (layout `stats`).
{{#BUFFER}}
var<workgroup> mrsl_wg_stats: array<atomic<u32>, {{COUNTERS}}>;
// Per pixel: .x bit k = coarse effect k evaluated per pixel, .y bit k = taken from the 2x2 level.
@group({{MASK_GROUP}}) @binding({{MASK_BINDING}}) var mrsl_refine_mask: texture_storage_2d<rg32uint, write>;
