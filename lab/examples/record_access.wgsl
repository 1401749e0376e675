// Kernels of `record_access`: each lane reads one pixel's record of WORDS words
// and writes one pixel. `none` only writes; `storage` reads a texel per word of
// an r32uint read-write storage array; `sampled` the same texels through a
// sampled view; `packed` four words per texel of an rgba32uint sampled array.

@group(0) @binding(0) var storage_words: texture_storage_2d_array<r32uint, read_write>;
@group(0) @binding(1) var sampled_words: texture_2d_array<u32>;
@group(0) @binding(2) var packed_words: texture_2d_array<u32>;
@group(0) @binding(4) var packed_storage: texture_storage_2d_array<rgba32uint, read>;
@group(0) @binding(5) var float_sampled: texture_2d<f32>;
@group(0) @binding(6) var float_storage: texture_storage_2d<rgba32float, read>;
@group(0) @binding(7) var storage_words_read: texture_storage_2d_array<r32uint, read>;
@group(0) @binding(8) var packed_read_write: texture_storage_2d_array<rgba32uint, read_write>;
@group(0) @binding(3) var out_image: texture_storage_2d<r32uint, write>;

const WORDS: i32 = {{WORDS}};

fn pixel(wg: vec3<u32>, li: u32) -> vec2<i32> {
    return vec2<i32>(wg.xy * 8u + vec2<u32>(li % 8u, li / 8u));
}

@compute @workgroup_size(64)
fn none_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    textureStore(out_image, p, vec4<u32>(u32(p.x)));
}

@compute @workgroup_size(64)
fn storage_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < WORDS; k++) { acc ^= textureLoad(storage_words, p, k).x * u32(k + 1); }
    textureStore(out_image, p, vec4<u32>(acc));
}

@compute @workgroup_size(64)
fn sampled_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < WORDS; k++) { acc ^= textureLoad(sampled_words, p, k, 0).x * u32(k + 1); }
    textureStore(out_image, p, vec4<u32>(acc));
}

@compute @workgroup_size(64)
fn packed_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < (WORDS + 3) / 4; k++) {
        let t = textureLoad(packed_words, p, k, 0);
        acc ^= t.x ^ (t.y * 3u) ^ (t.z * 5u) ^ (t.w * 7u);
    }
    textureStore(out_image, p, vec4<u32>(acc));
}

@compute @workgroup_size(64)
fn packed_storage_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < (WORDS + 3) / 4; k++) {
        let t = textureLoad(packed_storage, p, k);
        acc ^= t.x ^ (t.y * 3u) ^ (t.z * 5u) ^ (t.w * 7u);
    }
    textureStore(out_image, p, vec4<u32>(acc));
}

// The same texels through the other storage access: `storage_read` the
// r32uint words read-only, `packed_read_write` the rgba32uint texels read-write
// (what the hierarchical kernel's packed records are).
@compute @workgroup_size(64)
fn storage_read_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < WORDS; k++) { acc ^= textureLoad(storage_words_read, p, k).x * u32(k + 1); }
    textureStore(out_image, p, vec4<u32>(acc));
}

@compute @workgroup_size(64)
fn packed_read_write_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    var acc = 0u;
    for (var k = 0; k < (WORDS + 3) / 4; k++) {
        let t = textureLoad(packed_read_write, p, k);
        acc ^= t.x ^ (t.y * 3u) ^ (t.z * 5u) ^ (t.w * 7u);
    }
    textureStore(out_image, p, vec4<u32>(acc));
}

// A float G-buffer texel at the pixel and its four axis neighbours, sampled or as storage.
@compute @workgroup_size(64)
fn float_sampled_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    let m = vec2<i32>(textureDimensions(float_sampled)) - 1;
    var acc = vec4<f32>(0.0);
    for (var k = 0; k < 5; k++) { acc += textureLoad(float_sampled, clamp(p + vec2<i32>(k - 2, k % 2), vec2<i32>(0), m), 0); }
    textureStore(out_image, p, vec4<u32>(bitcast<u32>(acc.x + acc.y + acc.z + acc.w)));
}

@compute @workgroup_size(64)
fn float_storage_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let p = pixel(wg, li);
    let m = vec2<i32>(textureDimensions(float_storage)) - 1;
    var acc = vec4<f32>(0.0);
    for (var k = 0; k < 5; k++) { acc += textureLoad(float_storage, clamp(p + vec2<i32>(k - 2, k % 2), vec2<i32>(0), m)); }
    textureStore(out_image, p, vec4<u32>(bitcast<u32>(acc.x + acc.y + acc.z + acc.w)));
}
