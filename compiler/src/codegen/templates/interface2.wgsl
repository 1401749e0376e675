// Second level (2x2) interface, each record followed by its validity tag.
@group({{GROUP}}) @binding({{BINDING}}) var<storage, read> mrsl_interface2: array<u32>;
