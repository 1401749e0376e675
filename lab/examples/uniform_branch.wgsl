// Kernels of the uniform_branch microbenchmark (lab/examples/uniform_branch.rs):
// the same straight-line work (16 texel loads and the arithmetic over them)
// per lane, always, and under conditions that are all false, each kernel
// deciding them another way.

@group(0) @binding(0) var floats: texture_2d<f32>;
@group(0) @binding(1) var flags: texture_2d<u32>;
@group(0) @binding(3) var out: texture_storage_2d<r32uint, write>;

var<workgroup> any_set: atomic<u32>;
var<workgroup> any_set_plain: u32;

fn work(p: vec2<i32>) -> u32 {
    var acc = vec4<f32>(0.0);
    acc += textureLoad(floats, p + vec2<i32>(0, 0), 0);
    acc += textureLoad(floats, p + vec2<i32>(1, 0), 0) * acc.x;
    acc += textureLoad(floats, p + vec2<i32>(2, 0), 0) * acc.y;
    acc += textureLoad(floats, p + vec2<i32>(3, 0), 0) * acc.z;
    acc += textureLoad(floats, p + vec2<i32>(0, 1), 0) * acc.w;
    acc += textureLoad(floats, p + vec2<i32>(1, 1), 0) * acc.x;
    acc += textureLoad(floats, p + vec2<i32>(2, 1), 0) * acc.y;
    acc += textureLoad(floats, p + vec2<i32>(3, 1), 0) * acc.z;
    acc += textureLoad(floats, p + vec2<i32>(0, 2), 0) * acc.w;
    acc += textureLoad(floats, p + vec2<i32>(1, 2), 0) * acc.x;
    acc += textureLoad(floats, p + vec2<i32>(2, 2), 0) * acc.y;
    acc += textureLoad(floats, p + vec2<i32>(3, 2), 0) * acc.z;
    acc = normalize(acc + vec4<f32>(1.0)) * inverseSqrt(dot(acc, acc) + 1.0);
    acc += textureLoad(floats, p + vec2<i32>(0, 3), 0) * acc.w;
    acc += textureLoad(floats, p + vec2<i32>(1, 3), 0) * acc.x;
    acc += textureLoad(floats, p + vec2<i32>(2, 3), 0) * acc.y;
    acc += textureLoad(floats, p + vec2<i32>(3, 3), 0) * acc.z;
    acc = normalize(acc + vec4<f32>(1.0)) * inverseSqrt(dot(acc, acc) + 1.0);
    return bitcast<u32>(acc.x + acc.y + acc.z + acc.w);
}

fn pixel(wg: vec3<u32>, li: vec3<u32>) -> vec2<i32> {
    return vec2<i32>(wg.xy * 8u + li.xy);
}

@compute @workgroup_size(8, 8, 1)
fn none_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    textureStore(out, p, vec4<u32>(f));
}

@compute @workgroup_size(8, 8, 1)
fn always_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    textureStore(out, p, vec4<u32>(f + work(p)));
}

@compute @workgroup_size(8, 8, 1)
fn lane_if_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    var v = f;
    if (f != 0u) { v += work(p); }
    textureStore(out, p, vec4<u32>(v));
}

@compute @workgroup_size(8, 8, 1)
fn uniform_if_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    if (f != 0u) { atomicOr(&any_set, 1u); }
    workgroupBarrier();
    if (li.x == 0u && li.y == 0u) { any_set_plain = atomicLoad(&any_set); }
    let any = workgroupUniformLoad(&any_set_plain);
    var v = f;
    if (any != 0u) { v += work(p); }
    textureStore(out, p, vec4<u32>(v));
}

@compute @workgroup_size(8, 8, 1)
fn uniform_loop_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    if (f != 0u) { atomicOr(&any_set, 1u); }
    workgroupBarrier();
    if (li.x == 0u && li.y == 0u) { any_set_plain = atomicLoad(&any_set); }
    let any = workgroupUniformLoad(&any_set_plain);
    var v = f;
    var todo = any;
    loop {
        if (todo == 0u) { break; }
        todo = 0u;
        v += work(p);
    }
    textureStore(out, p, vec4<u32>(v));
}

@compute @workgroup_size(8, 8, 1)
fn barrier_only_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    if (f != 0u) { atomicOr(&any_set, 1u); }
    workgroupBarrier();
    if (li.x == 0u && li.y == 0u) { any_set_plain = atomicLoad(&any_set); }
    let any = workgroupUniformLoad(&any_set_plain);
    textureStore(out, p, vec4<u32>(f + any));
}

// A class per workgroup in a read-only storage buffer, indexed by the
// workgroup's id: the same for every lane of the workgroup.
@group(0) @binding(4) var<storage, read> tile_flags: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn buffer_if_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    var v = f;
    if (tile_flags[wg.y * n.x + wg.x] != 0u) { v += work(p); }
    textureStore(out, p, vec4<u32>(v));
}

// The same class in a uniform buffer (4096 vec4s, 64 KiB: indexed modulo its length).
@group(0) @binding(5) var<uniform> tile_flags_uniform: array<vec4<u32>, 4096>;

@compute @workgroup_size(8, 8, 1)
fn uniform_buffer_if_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    var v = f;
    let t = (wg.y * n.x + wg.x) % 16384u;
    if (tile_flags_uniform[t / 4u][t % 4u] != 0u) { v += work(p); }
    textureStore(out, p, vec4<u32>(v));
}

// One flag for the whole dispatch, at a fixed place in the uniform buffer.
@compute @workgroup_size(8, 8, 1)
fn dispatch_if_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) li: vec3<u32>) {
    let p = pixel(wg, li);
    let f = textureLoad(flags, p, 0).x;
    var v = f;
    if (tile_flags_uniform[0].x != 0u) { v += work(p); }
    textureStore(out, p, vec4<u32>(v));
}
