// Kernels of the uniform_loads microbenchmark (lab/examples/uniform_loads.rs):
// 16 four-word loads per lane and a sum over them, at addresses that differ
// per lane, that one row of eight lanes shares (one llvmpipe SIMD vector,
// like the block fine kernel's corners), or that the whole workgroup shares
// (a function of the workgroup id alone), from a read-only storage texture,
// a storage buffer and a uniform buffer.

@group(0) @binding(0) var texels: texture_storage_2d<rgba32uint, read>;
@group(0) @binding(1) var<storage, read> words: array<vec4<u32>>;
@group(0) @binding(2) var<uniform> constants: array<vec4<u32>, 4096>;
@group(0) @binding(3) var out: texture_storage_2d<r32uint, write>;

const LOADS: u32 = 16u;
const ROW: u32 = 2048u; // texels per row of `texels`, words per row of `words`

fn pixel(wg: vec3<u32>, li: vec3<u32>) -> vec2<u32> {
    return wg.xy * 8u + li.xy;
}

fn fold(acc: vec4<u32>, v: vec4<u32>) -> vec4<u32> {
    return (acc ^ v) * 2654435761u + v.yzwx;
}

fn from_texels(at: vec2<u32>) -> u32 {
    var acc = vec4<u32>(0u);
    for (var k = 0u; k < LOADS; k++) {
        acc = fold(acc, textureLoad(texels, vec2<u32>(at.x + k, at.y)));
    }
    return acc.x + acc.y + acc.z + acc.w;
}

fn from_words(at: vec2<u32>) -> u32 {
    var acc = vec4<u32>(0u);
    for (var k = 0u; k < LOADS; k++) {
        acc = fold(acc, words[at.y * ROW + at.x + k]);
    }
    return acc.x + acc.y + acc.z + acc.w;
}

fn from_arithmetic(at: vec2<u32>) -> u32 {
    var acc = vec4<u32>(0u);
    for (var k = 0u; k < LOADS; k++) {
        acc = fold(acc, vec4<u32>(at.x + k, at.y, k, at.x ^ k));
    }
    return acc.x + acc.y + acc.z + acc.w;
}

fn from_constants(at: vec2<u32>) -> u32 {
    var acc = vec4<u32>(0u);
    for (var k = 0u; k < LOADS; k++) {
        acc = fold(acc, constants[(at.y * 64u + at.x + k) % 4096u]);
    }
    return acc.x + acc.y + acc.z + acc.w;
}

// Addresses per lane, per row of eight lanes (li.y), per workgroup.
fn lane_at(wg: vec3<u32>, li: vec3<u32>) -> vec2<u32> { return pixel(wg, li); }
fn row_at(wg: vec3<u32>, li: vec3<u32>) -> vec2<u32> { return vec2<u32>(wg.x * 8u, wg.y * 8u + li.y); }
fn group_at(wg: vec3<u32>) -> vec2<u32> { return vec2<u32>(wg.x * 8u, wg.y * 8u); }

@compute @workgroup_size(8, 8, 1)
fn none_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(li.x));
}

// The sum over values made without a load: what the loads' kernels spend besides loading.
@compute @workgroup_size(8, 8, 1)
fn arithmetic_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_arithmetic(lane_at(wg, li))));
}

@compute @workgroup_size(8, 8, 1)
fn lane_texel_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_texels(lane_at(wg, li))));
}

@compute @workgroup_size(8, 8, 1)
fn row_texel_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_texels(row_at(wg, li)) + li.x));
}

@compute @workgroup_size(8, 8, 1)
fn group_texel_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_texels(group_at(wg)) + li.x));
}

@compute @workgroup_size(8, 8, 1)
fn lane_buffer_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_words(lane_at(wg, li))));
}

@compute @workgroup_size(8, 8, 1)
fn row_buffer_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_words(row_at(wg, li)) + li.x));
}

@compute @workgroup_size(8, 8, 1)
fn group_buffer_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_words(group_at(wg)) + li.x));
}

@compute @workgroup_size(8, 8, 1)
fn group_uniform_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    textureStore(out, pixel(wg, li), vec4<u32>(from_constants(group_at(wg) / 8u) + li.x));
}
