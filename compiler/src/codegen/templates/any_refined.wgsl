fn mrsl_any_refined(b: MrslBlock) -> bool {
    return ({{WORDS}}) != 0u;
}

