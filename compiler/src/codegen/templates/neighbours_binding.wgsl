// Neighbour values: the coarse effects that derivatives read at neighbouring samples,
// stored at every sample by `coarse_neighbours` (layout `neighbours`), a layer per word.
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_neighbours: texture_storage_2d_array<r32uint, read_write>;
