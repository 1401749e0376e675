//! Generates the parser from the top-level `grammar/` folder with lalrpop.

fn main() {
    let manifest_dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let grammar_dir = std::path::Path::new(&manifest_dir).join("../grammar");
    let out_dir = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    // Without this, a newly added .lalrpop file would not be noticed.
    println!("cargo:rerun-if-changed={}", grammar_dir.display());
    lalrpop::Configuration::new()
        .set_in_dir(&grammar_dir)
        .set_out_dir(&out_dir)
        .emit_rerun_directives(true)
        .process()
        .expect("the grammar in grammar/ must be valid lalrpop");
}
