// The 4x4 level (the record texture), read to find refined blocks; the 2x2 level, written
// with validity tags.
@group({{PARENT_GROUP}}) @binding({{PARENT_BINDING}}) var mrsl_parent: texture_2d_array<u32>;
@group({{GROUP}}) @binding({{BINDING}}) var<storage, read_write> mrsl_interface: array<u32>;
