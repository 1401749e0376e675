fn mrsl_hget_{{NAME}}(r: MrslRecord) -> {{TYPE}} {
    return {{UNPACK}};
}
