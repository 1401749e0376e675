fn mrsl_get{{SUFFIX}}_{{NAME}}(s: u32) -> {{TYPE}} {
    let base = s * {{STRIDE}}u + {{OFFSET}}u;
    return {{UNPACK}};
}
fn mrsl_resample{{SUFFIX}}_{{NAME}}(b: MrslBlock) -> {{TYPE}} {
{{#GUARD}}
{{#CORNERS}}
    // {{FILTER}}
    return {{VALUE}};
}
