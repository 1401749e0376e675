// Where a pixel takes its coarse values from, and which coarse effects it re-evaluates.
struct MrslBlock {
    corners: vec4<u32>, // coarse samples c00, c10, c01, c11
    weights: vec4<f32>, // bilinear weights of the corners
    nearest: u32,       // index of the nearest corner
{{#REFINED_WORDS}}
}

fn mrsl_is_refined(b: MrslBlock, k: u32) -> bool {
    return (({{WORD}} >> (k % 32u)) & 1u) != 0u;
}

