// Interface: per coarse sample, refine flag words then value slots (see layout), four
// words per texel: word w of sample (i, j) is component w % 4 of texel (i, j), layer w / 4.
@group({{GROUP}}) @binding({{BINDING}}) var mrsl_interface: texture_storage_2d_array<rgba32uint, write>;
