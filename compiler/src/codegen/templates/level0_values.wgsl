// Before level 0: the neighbour values (layout `neighbours`: the coarse effects that
// derivatives read elsewhere) at every level-0 pixel, for their values alone, a texel
// per point of level 0's lattice. Level 0 reads its own instead of evaluating them, and
// its predicates take their derivatives from its neighbours' (docs/language.md, section 9).
@compute @workgroup_size({{WORKGROUP}})
fn {{ENTRY}}({{PARAMS}}) {
{{#INVOCATION}}
    let p = {{PIXEL}};
    if ({{VALID}}all(p < vec2<i32>(mrsl_ctl.size))) {
        let mrsl_pos = p;
{{#VALUES}}
    }
}

