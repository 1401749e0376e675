// The kernels of `record_loads`: each lane reads the records of the four
// coarse samples around its 4x4 block (six words each, as sponza_lights' are) and
// writes two pixels, like the block fine kernel's corner loads; `none` only writes.

@group(0) @binding(0) var<storage, read> words: array<u32>;
@group(0) @binding(1) var records: texture_2d_array<u32>;
@group(0) @binding(3) var records_storage: texture_storage_2d_array<rgba32uint, read>;
@group(0) @binding(2) var out_image: texture_storage_2d<r32uint, write>;

const GRID_X: u32 = {{GRID_X}}u;
const STRIDE: u32 = 6u;

fn pixel(wg: vec3<u32>, li: u32) -> vec2<u32> {
    return vec2<u32>(wg.x * 8u + li % 8u, wg.y * 8u + li / 8u % 2u + li / 16u * 4u);
}

@compute @workgroup_size(32)
fn none_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let pos = pixel(wg, li);
    textureStore(out_image, pos, vec4<u32>(pos.x));
    textureStore(out_image, pos + vec2<u32>(0u, 2u), vec4<u32>(pos.y));
}

// Word k of the four samples from a storage buffer: 24 loads per lane.
@compute @workgroup_size(32)
fn buffer_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let pos = pixel(wg, li);
    let i0 = pos / 4u;
    let s = vec4<u32>(i0.y * GRID_X + i0.x, i0.y * GRID_X + i0.x + 1u, (i0.y + 1u) * GRID_X + i0.x, (i0.y + 1u) * GRID_X + i0.x + 1u) * STRIDE;
    var acc = 0u;
    for (var k = 0u; k < STRIDE; k++) {
        acc += words[s.x + k] ^ words[s.y + k] ^ words[s.z + k] ^ words[s.w + k];
    }
    textureStore(out_image, pos, vec4<u32>(acc));
    textureStore(out_image, pos + vec2<u32>(0u, 2u), vec4<u32>(acc));
}

// The same words as texels of an rgba32uint texture array: 8 loads per lane.
@compute @workgroup_size(32)
fn texture_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let pos = pixel(wg, li);
    let i0 = vec2<i32>(pos / 4u);
    var acc = vec4<u32>(0u);
    for (var layer = 0; layer < 2; layer++) {
        acc += textureLoad(records, i0, layer, 0) ^ textureLoad(records, i0 + vec2<i32>(1, 0), layer, 0)
            ^ textureLoad(records, i0 + vec2<i32>(0, 1), layer, 0) ^ textureLoad(records, i0 + vec2<i32>(1, 1), layer, 0);
    }
    let sum = acc.x + acc.y + acc.z + acc.w;
    textureStore(out_image, pos, vec4<u32>(sum));
    textureStore(out_image, pos + vec2<u32>(0u, 2u), vec4<u32>(sum));
}

// The same texels read as a read-only storage texture.
@compute @workgroup_size(32)
fn storage_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let pos = pixel(wg, li);
    let i0 = vec2<i32>(pos / 4u);
    var acc = vec4<u32>(0u);
    for (var layer = 0; layer < 2; layer++) {
        acc += textureLoad(records_storage, i0, layer) ^ textureLoad(records_storage, i0 + vec2<i32>(1, 0), layer)
            ^ textureLoad(records_storage, i0 + vec2<i32>(0, 1), layer) ^ textureLoad(records_storage, i0 + vec2<i32>(1, 1), layer);
    }
    let sum = acc.x + acc.y + acc.z + acc.w;
    textureStore(out_image, pos, vec4<u32>(sum));
    textureStore(out_image, pos + vec2<u32>(0u, 2u), vec4<u32>(sum));
}
