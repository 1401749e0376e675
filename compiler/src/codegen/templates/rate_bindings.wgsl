// Rate-image mode: the shading-rate image, one texel per tile, code (log2 width << 2) | log2 height.
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_shading_rate: texture_2d<u32>;
