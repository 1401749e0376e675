fn mrsl_resample{{SUFFIX}}_{{NAME}}(b: MrslBlock, c: MrslCorners) -> {{TYPE}} {
{{#GUARD}}
    let v0 = {{V0}};
    let v1 = {{V1}};
    let v2 = {{V2}};
    let v3 = {{V3}};
    // {{FILTER}}
    return {{VALUE}};
}

