fn mrsl_resolve{{SUFFIX}}({{PARAMS}}) -> MrslBlock {
{{GEOMETRY}}
    let extent = p1 - p0;
    let t = select(vec2<f32>(0.0), vec2<f32>(pos - p0) / vec2<f32>(max(extent, vec2<i32>(1))), extent > vec2<i32>(0));
    var b: MrslBlock;
    b.corners = vec4<u32>(u32(i0.y * n.x + i0.x), u32(i0.y * n.x + i1.x), u32(i1.y * n.x + i0.x), u32(i1.y * n.x + i1.x));
    b.weights = vec4<f32>((1.0 - t.x) * (1.0 - t.y), t.x * (1.0 - t.y), (1.0 - t.x) * t.y, t.x * t.y);
    b.nearest = select(0u, 1u, t.x > 0.5) + select(0u, 2u, t.y > 0.5);
    var disc = mrsl_ctl.force_refine != 0u;
{{#CORNERS}}
    // Effective refinement, users before what they use: an effect is evaluated per pixel
    // when a corner flagged it, at a discontinuity, or when it is needed coarsely but a
    // corner's shared slot holds another effect (an interface miss).
{{#REFINED}}
    return b;
}

