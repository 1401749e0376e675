//! The playground's compiler endpoints: the examples (embedded), the
//! built-in scenes, and `POST /api/compile`: diagnostics with their spans
//! as UTF-8 byte offsets into the source, the kernels and the layout.

use super::export::State;
use super::reply::{ApiError, blocking, read_json};
use axum::Json;
use axum::body::Body;
use axum::extract::State as Shared;
use mrsl::{Diagnostic, Mode, Options, Severity};
use serde::Deserialize;
use serde_json::{Value, json};
use std::sync::Arc;

/// The name the playground's program goes by in kernel headers and diagnostics.
pub const PROGRAM_NAME: &str = "program.mrsl";

/// Every example with the scene it is made for (README.md's table of the examples).
const EXAMPLES: [(&str, &str, &str); 10] = [
    ("demo", "demo", include_str!("../../../examples/demo.mrsl")),
    ("sponza_lights", "sponza", include_str!("../../../examples/sponza_lights.mrsl")),
    ("pbr_deferred", "dungeon", include_str!("../../../examples/pbr_deferred.mrsl")),
    ("soft_shadows", "demo", include_str!("../../../examples/soft_shadows.mrsl")),
    ("many_lights", "sponza", include_str!("../../../examples/many_lights.mrsl")),
    ("diffuse_specular", "demo", include_str!("../../../examples/diffuse_specular.mrsl")),
    ("textured_materials", "demo", include_str!("../../../examples/textured_materials.mrsl")),
    ("derivatives", "demo", include_str!("../../../examples/derivatives.mrsl")),
    ("effect_chain", "demo", include_str!("../../../examples/effect_chain.mrsl")),
    ("three_rates", "demo", include_str!("../../../examples/three_rates.mrsl")),
];

/// `GET /api/examples`.
pub async fn examples() -> Json<Value> {
    let list: Vec<Value> = EXAMPLES
        .iter()
        .map(|(name, scene, source)| json!({ "name": name, "file": format!("{name}.mrsl"), "scene": scene, "source": source }))
        .collect();
    Json(Value::Array(list))
}

/// `GET /api/scenes`.
pub async fn scenes() -> Json<Value> {
    Json(json!(mrsl_lab::scene::Scene::NAMES))
}

#[derive(Deserialize)]
struct CompileRequest {
    source: String,
    /// Mode names; all of them when absent.
    modes: Option<Vec<String>>,
}

/// `POST /api/compile`: 200 whether or not the program compiles (`ok`).
pub async fn compile(Shared(state): Shared<Arc<State>>, body: Body) -> Result<Json<Value>, ApiError> {
    let request: CompileRequest = read_json(body).await?;
    let modes = match &request.modes {
        Some(names) => parse_modes(names)?,
        None => Mode::ALL.to_vec(),
    };
    let _slot = state.compiling.acquire().await.map_err(|e| ApiError::internal(e.to_string()))?;
    blocking(move || Ok(Json(compiled(&request.source, &modes)))).await
}

/// The modes named, or 400 naming the unknown ones and the known.
pub fn parse_modes(names: &[String]) -> Result<Vec<Mode>, ApiError> {
    let unknown: Vec<String> = names.iter().filter(|n| n.parse::<Mode>().is_err()).map(|n| format!("`{n}`")).collect();
    if !unknown.is_empty() {
        let known = Mode::ALL.map(Mode::name).join(", ");
        return Err(ApiError::bad_request(format!("unknown mode {} (known: {known})", unknown.join(", "))));
    }
    Ok(names.iter().filter_map(|n| n.parse().ok()).collect())
}

/// The compile response for `source`.
fn compiled(source: &str, modes: &[Mode]) -> Value {
    let options = Options { file_name: PROGRAM_NAME.into(), ..Options::for_modes(modes) };
    match mrsl::compile(source, &options) {
        Ok(program) => {
            let kernels: Vec<Value> = program
                .kernels
                .iter()
                .map(|k| {
                    json!({ "kind": k.kind.name(), "block": k.block_size, "file": k.file_name("program"), "wgsl": k.wgsl })
                })
                .collect();
            // As `compile -o` writes it.
            let layout: Value = serde_json::from_str(&program.layout.to_json()).unwrap_or(Value::Null);
            json!({ "ok": true, "diagnostics": diagnostics(&program.warnings, source), "kernels": kernels, "layout": layout })
        }
        Err(found) => json!({ "ok": false, "diagnostics": diagnostics(&found, source), "kernels": [], "layout": null }),
    }
}

/// Diagnostics as JSON: spans in UTF-8 bytes, with the 1-based line and
/// column (in characters) of their start, and the text `mrslc check` prints.
pub fn diagnostics(found: &[Diagnostic], source: &str) -> Vec<Value> {
    found
        .iter()
        .map(|d| {
            let labels: Vec<Value> = d
                .labels
                .iter()
                .map(|l| {
                    let start = floor_char_boundary(source, l.span.start as usize);
                    let end = floor_char_boundary(source, (l.span.end as usize).max(start));
                    let (line, column) = line_column(source, start);
                    json!({ "start": start, "end": end, "line": line, "column": column,
                            "message": l.message, "primary": l.primary })
                })
                .collect();
            // An internal error (E9000) is an error to the page.
            let severity = if d.severity == Severity::Warning { "warning" } else { "error" };
            json!({ "severity": severity, "code": d.code, "message": d.message, "labels": labels,
                    "notes": d.notes, "rendered": d.render(PROGRAM_NAME, source) })
        })
        .collect()
}

/// `offset` clamped to the source and moved back to a character's start.
fn floor_char_boundary(source: &str, offset: usize) -> usize {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// The 1-based line and column (in characters) of byte `offset`.
fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_are_byte_offsets_with_lines_and_columns_in_characters() {
        let source = "// é\nfine out float4 color = float4(nope, 1.0);\n";
        let found = diagnostics(&mrsl::check(source), source);
        let label = &found[0]["labels"][0];
        let start = source.find("nope").unwrap();
        assert_eq!((label["start"].as_u64(), label["end"].as_u64()), (Some(start as u64), Some(start as u64 + 4)));
        assert_eq!((label["line"].as_u64(), label["column"].as_u64()), (Some(2), Some(32)));
        assert_eq!(found[0]["severity"], "error");
        assert!(found[0]["rendered"].as_str().unwrap().contains("program.mrsl:2:32"), "{}", found[0]["rendered"]);
        assert_eq!(line_column("aé\nb", 3), (1, 3));
        assert_eq!(floor_char_boundary("aé", 2), 1);
        assert_eq!(floor_char_boundary("a", 9), 1);
    }

    #[test]
    fn unknown_modes_are_named_with_the_known_ones() {
        let e = parse_modes(&["coarse4x4".into(), "fast".into()]).unwrap_err();
        assert_eq!(e.status, axum::http::StatusCode::BAD_REQUEST);
        assert!(e.message.starts_with("unknown mode `fast` (known: reference, coarse2x2"), "{}", e.message);
        assert_eq!(parse_modes(&["rate-image".into()]).unwrap(), [Mode::RateImage]);
    }

    #[test]
    fn every_example_is_listed_and_compiles() {
        let files = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples")).unwrap();
        let mut on_disk: Vec<String> = files
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter_map(|n| n.strip_suffix(".mrsl").map(String::from))
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = EXAMPLES.iter().map(|e| e.0.to_string()).collect();
        listed.sort();
        assert_eq!(listed, on_disk);
        for (name, scene, source) in EXAMPLES {
            assert!(mrsl_lab::scene::Scene::parse(scene).is_some(), "{name}: {scene}");
            assert_eq!(compiled(source, &[Mode::Coarse4x4])["ok"], true, "{name}");
        }
    }
}
