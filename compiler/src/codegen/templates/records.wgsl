const MRSL_RECORD: u32 = {{RECORD}}u;

fn mrsl_rec(p: vec2<i32>) -> u32 {
    return (u32(p.y) * mrsl_ctl.size.x + u32(p.x)) * MRSL_RECORD;
}

