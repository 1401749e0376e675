fn mrsl_get{{SUFFIX}}_{{NAME}}(s: u32) -> {{TYPE}} {
    let base = s * {{STRIDE}}u + {{OFFSET}}u;
    return {{UNPACK}};
}
fn mrsl_resample{{SUFFIX}}_{{NAME}}(b: MrslBlock) -> {{TYPE}} {
{{#GUARD}}
    let v0 = mrsl_get{{SUFFIX}}_{{NAME}}(b.corners.x);
    let v1 = mrsl_get{{SUFFIX}}_{{NAME}}(b.corners.y);
    let v2 = mrsl_get{{SUFFIX}}_{{NAME}}(b.corners.z);
    let v3 = mrsl_get{{SUFFIX}}_{{NAME}}(b.corners.w);
    // {{FILTER}}
    return {{VALUE}};
}

