// Interface: per coarse sample, refine flag words then value slots (see layout).
@group({{GROUP}}) @binding({{BINDING}}) var<storage, {{ACCESS}}> mrsl_interface: array<u32>;
