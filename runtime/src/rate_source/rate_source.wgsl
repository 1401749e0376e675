// The content-adaptive rate source of the `rate-image` mode (see
// runtime/src/rate_source/ and docs/rate-image.md): VALAR's per-tile
// decision from the previous frame's luminance and motion (`decide`), then
// temporal damping, reprojection and the combiners (`resolve`).
//
// Codes are those of D3D12/Vulkan: (log2(width) << 2) | log2(height), width
// along x. Per-axis rates are carried as log2 values 0 (1x), 1 (2x), 2 (4x).

// `Params`, the FLAG_ and COMBINE_ constants, WEBER_FLOOR and the bindings
// are declared before this text by runtime/src/rate_source/interface.rs,
// from the same description the Rust side binds and fills them from.

// A history slot that holds no decision (before the first frame, or where the
// reprojected source left the screen): it takes no part in the damping.
const NONE: u32 = 0xffu;

// Rec.709 / sRGB primaries' luminance weights, as VALAR's RGBToLuminance.
const REC709 = vec3<f32>(0.212671, 0.715160, 0.072169);

// Larger than any velocity in pixels: the neutral element of the tile minimum.
const FAR: f32 = 3.0e38;

// Pixels per tile side: 8 or 16, set per pipeline.
override TILE: u32 = 8u;

fn has(flag: u32) -> bool {
    return (params.flags & flag) != 0u;
}

// The luminance of what the colour input holds: Rec.709 of an RGB(A)
// colour, the mean of a two-channel one, the value of a one-channel one.
fn luma(p: vec2<i32>) -> f32 {
    let c = textureLoad(color, p, 0);
    switch params.color_channels {
        case 1u: {
            return c.r;
        }
        case 2u: {
            return 0.5 * (c.r + c.g);
        }
        default: {
            return dot(c.rgb, REC709);
        }
    }
}

// The minimum luminance of the 3x3 neighbourhood, clamped to the image
// (the Weber–Fechner brightness sensitivity's input).
fn min_luma_3x3(p: vec2<i32>) -> f32 {
    let last = vec2<i32>(params.size) - 1;
    var m = FAR;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            m = min(m, luma(clamp(p + vec2<i32>(dx, dy), vec2<i32>(0), last)));
        }
    }
    return m;
}

// One neighbour difference: Eq. 2's |L - L'| / 2, or Weber's contrast with
// the brightness sensitivity `bs` added to the darker of the two.
fn difference(a: f32, b: f32, bs: f32) -> f32 {
    if has(FLAG_WEBER_FECHNER) {
        // The floor keeps a zero constant over black pixels finite.
        return abs(a - b) / max(min(a, b) + bs, WEBER_FLOOR);
    }
    return abs(a - b) / 2.0;
}

// x^y for x >= 0, with 0^y = 0 (WGSL leaves pow(0, y) to log2(0)).
fn pow0(x: f32, y: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    return pow(x, y);
}

// Eq. 16 / Eq. 14: full rate when the half-rate error reaches the JND
// threshold, quarter rate when even the quarter-rate error stays below it.
fn axis_rate(error: f32, tau: f32, half_rate: f32, quarter: f32) -> u32 {
    if half_rate * error >= tau {
        return 0u;
    }
    if quarter * error < tau {
        return 2u;
    }
    return 1u;
}

// The code of per-axis log2 rates, 4x1 and 1x4 made 2x1 and 1x2 (as
// `ShadingRate::clamp_size`: never coarser than asked on either axis).
fn encode(rate: vec2<u32>) -> u32 {
    var r = min(rate, vec2<u32>(2u));
    if r.x == 2u && r.y == 0u {
        r.x = 1u;
    }
    if r.x == 0u && r.y == 2u {
        r.y = 1u;
    }
    return (r.x << 2u) | r.y;
}

fn decode(code: u32) -> vec2<u32> {
    return min(vec2<u32>((code >> 2u) & 3u, code & 3u), vec2<u32>(2u));
}

// One invocation per tile, summing its pixels in a loop. VALAR runs a
// workgroup per tile and reduces in shared memory; on a CPU device
// (lavapipe) every workgroup barrier switches all the workgroup's
// invocations, which made that 1.6 s at 1920x1080 against tens of ms for
// this loop. On a GPU the loop leaves lanes idle only while the tile count
// is below the lane count. The order of the sums is fixed either way.
@compute @workgroup_size(8, 8)
fn decide(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(params.size);
    if any(id.xy >= params.rate_size) {
        return;
    }
    let origin = vec2<i32>(id.xy * TILE);
    let end = min(origin + vec2<i32>(i32(TILE)), size);
    // Sum of L, sum of x differences, sum of y differences, minimum speed.
    var total = vec4<f32>(0.0, 0.0, 0.0, FAR);
    for (var y = origin.y; y < end.y; y++) {
        for (var x = origin.x; x < end.x; x++) {
            let p = vec2<i32>(x, y);
            let l = luma(p);
            var bs = 0.0;
            if has(FLAG_WEBER_FECHNER) {
                bs = params.weber_fechner * (1.0 - saturate(min_luma_3x3(p) * 50.0 - 2.5));
            }
            total.x += l;
            // The left and upper neighbours, across tile borders as in VALAR;
            // the image's first column and row have none.
            if p.x > 0 {
                total.y += difference(l, luma(p - vec2<i32>(1, 0)), bs);
            }
            if p.y > 0 {
                total.z += difference(l, luma(p - vec2<i32>(0, 1)), bs);
            }
            if has(FLAG_MOTION) {
                total.w = min(total.w, length(textureLoad(velocity, p, 0).xy));
            }
        }
    }
    let tile = id;

    // Pixels of this tile inside the image, and how many of them have a left
    // (upper) neighbour: the means' denominators.
    let extent = min(vec2<i32>(i32(TILE)), size - origin);
    let pixels = f32(extent.x * extent.y);
    let with_left = f32(extent.y * (extent.x - select(0, 1, origin.x == 0)));
    let with_up = f32(extent.x * (extent.y - select(0, 1, origin.y == 0)));
    let mean_luma = total.x / pixels;
    let mean_x = select(0.0, total.y / with_left, with_left > 0.0);
    let mean_y = select(0.0, total.z / with_up, with_up > 0.0);
    // Eq. 15: the just-noticeable-difference threshold.
    let tau = params.sensitivity * (mean_luma + params.env_luma);
    let error = sqrt(vec2<f32>(mean_x, mean_y));
    var half_rate = 1.0;
    var quarter = params.k;
    if has(FLAG_MOTION) {
        let speed = total.w;
        // Eq. 20 and Eq. 21: motion hides the error of the coarser rates.
        half_rate = pow(1.0 / (1.0 + pow0(1.05 * speed, 3.10)), 0.35);
        quarter = params.k * pow(1.0 / (1.0 + pow0(0.55 * speed, 2.41)), 0.49);
    }
    let rate = vec2<u32>(axis_rate(error.x, tau, half_rate, quarter), axis_rate(error.y, tau, half_rate, quarter));
    textureStore(raw_out, tile.xy, vec4<u32>(encode(rate), 0u, 0u, 0u));
}

fn combine(a: vec2<u32>, b: vec2<u32>, combiner: u32) -> vec2<u32> {
    switch combiner {
        case COMBINE_MIN: {
            return min(a, b);
        }
        case COMBINE_MAX: {
            return max(a, b);
        }
        default: {
            return b;
        }
    }
}

// The foveation rate of the tile whose pixels are [lo, hi): from the point of
// the tile nearest to the gaze, 1x1 within the inner radius, 2x2 within the
// outer one, 4x4 beyond.
fn foveation(lo: vec2<f32>, hi: vec2<f32>) -> vec2<u32> {
    let nearest = clamp(params.gaze, lo, hi);
    let d = distance(nearest, params.gaze);
    if d <= params.fovea_inner {
        return vec2<u32>(0u);
    }
    if d <= params.fovea_outer {
        return vec2<u32>(1u);
    }
    return vec2<u32>(2u);
}

@compute @workgroup_size(8, 8)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= params.rate_size) {
        return;
    }
    let tile = vec2<i32>(id.xy);
    let size = vec2<i32>(params.size);
    // Reprojection: the rates are for the next frame, so each tile takes the
    // decision (and its history) from where its content is now, one frame of
    // motion back (constant velocity over one frame). Content from outside
    // the screen has no decision.
    var source = tile;
    var inside = true;
    if has(FLAG_REPROJECT) {
        let centre = min(tile * i32(params.tile) + i32(params.tile / 2u), size - 1);
        let back = vec2<f32>(centre) + 0.5 - textureLoad(velocity, centre, 0).xy;
        inside = all(back >= vec2<f32>(0.0)) && all(back < vec2<f32>(size));
        if inside {
            source = vec2<i32>(floor(back)) / i32(params.tile);
        }
    }
    var decision = NONE;
    var history = (NONE << 8u) | NONE;
    if inside {
        decision = textureLoad(raw_in, source, 0).r;
        if !has(FLAG_FIRST_FRAME) {
            history = textureLoad(history_in, source, 0).r;
        }
    }
    let previous = history & 0xffu;
    let before = (history >> 8u) & 0xffu;
    textureStore(history_out, tile, vec4<u32>(decision | (previous << 8u), 0u, 0u, 0u));
    // First frame, or content new on screen: full rate.
    var rate = vec2<u32>(0u);
    if decision != NONE && !has(FLAG_FIRST_FRAME) {
        rate = decode(decision);
        // Hysteresis: a tile is no coarser on an axis than any of the last
        // three decisions for its content; it refines at once and coarsens
        // only when three frames agree.
        if has(FLAG_HYSTERESIS) {
            if previous != NONE {
                rate = min(rate, decode(previous));
            }
            if before != NONE {
                rate = min(rate, decode(before));
            }
        }
    }
    if has(FLAG_FOVEATION) {
        let lo = vec2<f32>(tile * i32(params.tile));
        let hi = vec2<f32>(min((tile + 1) * i32(params.tile), size));
        rate = combine(rate, foveation(lo, hi), (params.combiners >> 4u) & 15u);
    }
    if has(FLAG_EXTERNAL) {
        rate = combine(rate, decode(textureLoad(external_rates, tile, 0).r), params.combiners & 15u);
    }
    textureStore(target_out, tile, vec4<u32>(encode(rate), 0u, 0u, 0u));
}
