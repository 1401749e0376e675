// The G-buffer rasteriser's shaders (lab/src/raster.rs): a mesh pass and a
// full-screen background pass for each of the three passes the channels are
// split into (see the module documentation there for why three).

struct Globals {
    view_proj: mat4x4<f32>,
    previous_view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    size: vec4<f32>,
};
@group(0) @binding(0) var<uniform> g: Globals;

struct Material {
    base_color: vec4<f32>,
    // x: roughness, y: metallic, z: normal scale, w: alpha cutoff (negative: none)
    params: vec4<f32>,
    // x: 1 where the normal map applies; y: 1 to sample at (u, 1 - v) (OBJ)
    flags: vec4<u32>,
};
@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var base_color_map: texture_2d<f32>;
@group(1) @binding(2) var metallic_roughness_map: texture_2d<f32>;
@group(1) @binding(3) var normal_map: texture_2d<f32>;
@group(1) @binding(4) var material_sampler: sampler;

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
    @location(4) tangent: vec4<f32>,
    @location(5) color: vec4<f32>,
};

struct Pass1 {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
};

struct Pass2 {
    @location(0) uv: vec2<f32>,
    @location(1) material: u32,
    @location(2) depth: f32,
    @location(3) velocity: vec2<f32>,
};

struct Pass3 {
    @location(0) albedo: vec4<f32>,
    @location(1) roughness: f32,
    @location(2) metallic: f32,
};

@vertex
fn vs_mesh(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @location(2) uv: vec2<f32>,
           @location(3) material_id: u32, @location(4) tangent: vec4<f32>, @location(5) color: vec4<f32>) -> VsOut {
    var out: VsOut;
    out.clip = g.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.normal = n;
    out.uv = uv;
    out.material = material_id;
    out.tangent = tangent;
    out.color = color;
    return out;
}

// Every pass samples the base colour first (in uniform control flow, so
// that the quad's uv derivatives pick the mip level) and discards the same
// masked fragments.
fn texture_uv(v: VsOut) -> vec2<f32> {
    return select(v.uv, vec2<f32>(v.uv.x, 1.0 - v.uv.y), material.flags.y != 0u);
}

fn base_color(v: VsOut) -> vec4<f32> {
    return material.base_color * v.color * textureSample(base_color_map, material_sampler, texture_uv(v));
}

fn alpha_test(alpha: f32) {
    if (material.params.w >= 0.0 && alpha < material.params.w) {
        discard;
    }
}

@fragment
fn fs_mesh1(v: VsOut, @builtin(front_facing) front: bool) -> Pass1 {
    let albedo = base_color(v);
    let mapped = textureSample(normal_map, material_sampler, texture_uv(v)).xyz * 2.0 - 1.0;
    alpha_test(albedo.a);
    var n = v.normal;
    if (dot(n, n) > 0.0) {
        n = normalize(n);
        // The tangent frame: the tangent made orthogonal to the normal, the
        // bitangent's handedness from w. A vertex without a tangent (zero)
        // keeps the interpolated normal.
        let t = v.tangent.xyz - n * dot(n, v.tangent.xyz);
        if (material.flags.x != 0u && dot(t, t) > 1e-12) {
            let tu = normalize(t);
            let b = cross(n, tu) * select(-1.0, 1.0, v.tangent.w >= 0.0);
            let p = (mapped.x * material.params.z) * tu + (mapped.y * material.params.z) * b + mapped.z * n;
            if (dot(p, p) > 0.0) {
                n = normalize(p);
            }
        }
    }
    if (!front) {
        n = -n;
    }
    return Pass1(vec4<f32>(v.world, 0.0), vec4<f32>(n, 0.0));
}

// A world point's position in pixels under a view-projection matrix, or
// nothing when it lies behind that camera.
fn project(m: mat4x4<f32>, p: vec3<f32>) -> vec3<f32> {
    let clip = m * vec4<f32>(p, 1.0);
    if (clip.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    let ndc = clip.xy / clip.w;
    return vec3<f32>((ndc.x * 0.5 + 0.5) * g.size.x, (0.5 - ndc.y * 0.5) * g.size.y, 1.0);
}

@fragment
fn fs_mesh2(v: VsOut) -> Pass2 {
    alpha_test(base_color(v).a);
    let now = project(g.view_proj, v.world);
    let before = project(g.previous_view_proj, v.world);
    let velocity = select(vec2<f32>(0.0), now.xy - before.xy, now.z > 0.0 && before.z > 0.0);
    return Pass2(v.uv, v.material, distance(v.world, g.eye.xyz), velocity);
}

@fragment
fn fs_mesh3(v: VsOut) -> Pass3 {
    let albedo = base_color(v);
    let mr = textureSample(metallic_roughness_map, material_sampler, texture_uv(v));
    alpha_test(albedo.a);
    return Pass3(albedo, clamp(material.params.x * mr.g, 0.0, 1.0), clamp(material.params.y * mr.b, 0.0, 1.0));
}

// A full-screen triangle at depth 0 (infinitely far with reversed depth).
@vertex
fn vs_background(@builtin(vertex_index) i: u32) -> @builtin(position) @invariant vec4<f32> {
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

fn view_ray(frag: vec2<f32>) -> vec3<f32> {
    let sx = (2.0 * frag.x / g.size.x - 1.0) * g.right.w;
    let sy = (1.0 - 2.0 * frag.y / g.size.y) * g.up.w;
    return normalize(g.forward.xyz + sx * g.right.xyz + sy * g.up.xyz);
}

@fragment
fn fs_background1(@builtin(position) frag: vec4<f32>) -> Pass1 {
    let d = view_ray(frag.xy);
    return Pass1(vec4<f32>(g.eye.xyz + g.eye.w * d, 0.0), vec4<f32>(-d, 0.0));
}

@fragment
fn fs_background2(@builtin(position) frag: vec4<f32>) -> Pass2 {
    return Pass2(vec2<f32>(0.0, 0.0), BACKGROUND_ID, g.eye.w, vec2<f32>(0.0));
}

@fragment
fn fs_background3() -> Pass3 {
    return Pass3(vec4<f32>(0.0), 1.0, 0.0);
}
