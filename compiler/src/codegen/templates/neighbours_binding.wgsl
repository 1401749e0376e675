// Neighbour values: the coarse effects that derivatives read at other positions, stored
// by a first entry point (layout `neighbours`; at every coarse sample by
// `coarse_neighbours`, at every level-0 pixel by `hier_level0_values`), a layer per word.
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_neighbours: texture_storage_2d_array<r32uint, read_write>;
