//! The playground's G-buffer endpoints: `POST /api/gbuffer` runs
//! [`crate::gbuffer::export`] on the server's one device (made on first
//! use, one export at a time, on the blocking pool) and keeps the files in
//! a bounded cache, from which `GET /api/gbuffer/KEY/FILE` serves them.

use super::diagnostics::{PROGRAM_NAME, diagnostics};
use super::reply::{ApiError, blocking, read_json};
use crate::gbuffer::{self, MANIFEST, ProgramRef};
use axum::Json;
use axum::body::{Body, Bytes};
use axum::extract::{Path, State as Shared};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use mrsl_lab::gpu::Gpu;
use mrsl_lab::scene::Scene;
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Mutex, PoisonError};

/// The largest export the playground makes (1920x1080 pixels).
pub const MAX_PIXELS: u64 = 1920 * 1080;

/// The exports kept: at most this many, and at most [`CACHE_BYTES`] in all
/// (the newest is kept whatever its size).
const CACHE_EXPORTS: usize = 8;
const CACHE_BYTES: usize = 512 << 20;

/// Programs compiled at once (each on a thread of its own).
const COMPILERS: usize = 2;

/// What the handlers share.
pub struct State {
    pub compiling: tokio::sync::Semaphore,
    /// The device, made by the first export; the lock makes exports take turns.
    gpu: Mutex<Option<Gpu>>,
    cache: Mutex<Cache>,
}

impl Default for State {
    fn default() -> State {
        State {
            compiling: tokio::sync::Semaphore::new(COMPILERS),
            gpu: Mutex::new(None),
            cache: Mutex::new(Cache::default()),
        }
    }
}

/// The latest exports' files by key, oldest first.
#[derive(Default)]
struct Cache {
    exports: VecDeque<(String, HashMap<String, Bytes>)>,
    made: u64,
}

impl Cache {
    /// Keeps `files` under a new key, dropping the oldest exports past the bounds.
    fn insert(&mut self, files: Vec<(String, Vec<u8>)>) -> String {
        self.made += 1;
        let key = format!("{}-{}", std::process::id(), self.made);
        self.exports.push_back((key.clone(), files.into_iter().map(|(n, b)| (n, Bytes::from(b))).collect()));
        let bytes = |e: &(String, HashMap<String, Bytes>)| e.1.values().map(Bytes::len).sum::<usize>();
        while self.exports.len() > CACHE_EXPORTS
            || (self.exports.len() > 1 && self.exports.iter().map(bytes).sum::<usize>() > CACHE_BYTES)
        {
            self.exports.pop_front();
        }
        key
    }

    fn get(&self, key: &str, file: &str) -> Option<Bytes> {
        self.exports.iter().find(|(k, _)| k == key).and_then(|(_, files)| files.get(file).cloned())
    }
}

#[derive(Deserialize)]
struct ExportRequest {
    scene: String,
    size: [u32; 2],
    /// The program whose bindings to export; the G-buffer alone without one.
    source: Option<String>,
}

/// `POST /api/gbuffer`.
pub async fn create(Shared(state): Shared<Arc<State>>, body: Body) -> Result<Json<Value>, ApiError> {
    let request: ExportRequest = read_json(body).await?;
    // Built-in scenes only: a scene file's path would read the server's files.
    if Scene::parse(&request.scene).is_none() {
        let names = Scene::NAMES.join(", ");
        return Err(ApiError::bad_request(format!("unknown scene `{}` (the scenes: {names})", request.scene)));
    }
    let size = (request.size[0], request.size[1]);
    gbuffer::check_size(size, MAX_PIXELS).map_err(|e| ApiError::bad_request(format!("the playground's limit: {e}")))?;
    let program = match &request.source {
        Some(source) => Some(compile(&state, source.clone()).await?),
        None => None,
    };
    let worker = state.clone();
    let export = blocking(move || {
        let mut gpu = worker.gpu.lock().unwrap_or_else(PoisonError::into_inner);
        if gpu.is_none() {
            *gpu = Some(Gpu::new().map_err(|e| ApiError::new(StatusCode::SERVICE_UNAVAILABLE, e.to_string()))?);
        }
        let gpu = gpu.as_ref().expect("made just above");
        let program = program.as_ref().map(|program| ProgramRef { name: PROGRAM_NAME, program });
        let export = gbuffer::export(gpu, &request.scene, Some(size), program, &[])
            .map_err(|e| ApiError::internal(format!("the export failed: {e}")))?;
        Ok(export)
    })
    .await?;
    let manifest = serde_json::to_value(&export.manifest).map_err(|e| ApiError::internal(e.to_string()))?;
    let files = export.into_files().map_err(|e| ApiError::internal(e.to_string()))?;
    let key = state.cache.lock().unwrap_or_else(PoisonError::into_inner).insert(files);
    Ok(Json(json!({ "key": key, "manifest": manifest, "base": format!("/api/gbuffer/{key}/") })))
}

/// Compiles the program for its layout alone (the export needs no kernel);
/// 400 with the diagnostics' text if it does not compile.
async fn compile(state: &State, source: String) -> Result<mrsl::Program, ApiError> {
    let _slot = state.compiling.acquire().await.map_err(|e| ApiError::internal(e.to_string()))?;
    blocking(move || {
        let options = mrsl::Options { file_name: PROGRAM_NAME.into(), ..mrsl::Options::for_modes(&[]) };
        mrsl::compile(&source, &options).map_err(|found| {
            let rendered: Vec<String> =
                diagnostics(&found, &source).iter().filter_map(|d| d["rendered"].as_str().map(String::from)).collect();
            ApiError::bad_request(format!("the program does not compile:\n{}", rendered.concat()))
        })
    })
    .await
}

/// `GET /api/gbuffer/KEY/FILE`.
pub async fn file(Shared(state): Shared<Arc<State>>, Path((key, file)): Path<(String, String)>) -> Response {
    let found = state.cache.lock().unwrap_or_else(PoisonError::into_inner).get(&key, &file);
    let Some(bytes) = found else {
        let message = format!(
            "no file `{file}` in export `{key}` (the server keeps the last {CACHE_EXPORTS} exports: export again)"
        );
        return ApiError::new(StatusCode::NOT_FOUND, message).into_response();
    };
    let content_type = if file == MANIFEST { "application/json" } else { "application/octet-stream" };
    ([(header::CONTENT_TYPE, content_type)], bytes).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_keeps_the_latest_exports_within_its_bounds() {
        let mut cache = Cache::default();
        let keys: Vec<String> = (0..10).map(|k| cache.insert(vec![("a.bin".into(), vec![k as u8])])).collect();
        assert_eq!(cache.exports.len(), CACHE_EXPORTS);
        assert_eq!(cache.get(&keys[0], "a.bin"), None, "the oldest went first");
        assert_eq!(cache.get(&keys[9], "a.bin").as_deref(), Some(&[9u8][..]));
        assert_eq!(cache.get(&keys[9], "b.bin"), None);
        // One export over the byte bound is kept alone.
        let big = cache.insert(vec![("big.bin".into(), vec![0; CACHE_BYTES + 1])]);
        assert_eq!(cache.exports.len(), 1);
        assert!(cache.get(&big, "big.bin").is_some());
    }
}
