//! The playground's compiler endpoints: the examples (embedded), the
//! built-in scenes, and `POST /api/compile`: diagnostics with their spans
//! as UTF-8 byte offsets into the source, the kernels and the layout.

use super::diagnostics::{PROGRAM_NAME, diagnostics};
use super::export::State;
use super::reply::{ApiError, blocking, read_json};
use axum::Json;
use axum::body::Body;
use axum::extract::State as Shared;
use mrsl::{Mode, Options};
use serde::Deserialize;
use serde_json::{Value, json};
use std::sync::Arc;

/// Every example with the scene it is made for (the table of the examples in docs/eval/examples.md).
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

#[cfg(test)]
mod tests {
    use super::*;

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
