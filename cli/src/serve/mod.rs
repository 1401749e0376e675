//! `mrslc serve`: the playground's local HTTP server (axum on a
//! single-threaded tokio runtime). It serves the page (web/playground/dist,
//! embedded at compile time) and a JSON API: the examples and scenes,
//! compiling a program ([`api`]), and exporting a scene's G-buffer for the
//! page's WebGPU runtime ([`export`]). Every refusal is JSON,
//! `{"error": "..."}`, with a fitting status ([`reply`]); a bad request
//! never takes the server down. docs/serve.md describes the endpoints.

mod api;
mod assist;
mod diagnostics;
mod export;
mod reply;

use anyhow::{Context, Result, anyhow};
use axum::Router;
use axum::extract::Request;
use axum::http::{StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use reply::ApiError;
use std::io::Write;
use std::sync::Arc;

/// The page and its two files, as the web build writes them.
const INDEX_HTML: &str = include_str!("../../../web/playground/dist/index.html");
const PLAYGROUND_JS: &str = include_str!("../../../web/playground/dist/playground.js");
const PLAYGROUND_CSS: &str = include_str!("../../../web/playground/dist/playground.css");

/// Listens on `host:port` (port 0: a free one), prints the address, and
/// serves until the process is stopped.
pub fn serve(host: &str, port: u16) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .build()
        .context("cannot start the server's runtime")?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind((host, port))
            .await
            .map_err(|e| anyhow!("cannot listen on {host}:{port}: {e}"))?;
        let address = listener.local_addr()?;
        if !address.ip().is_loopback() {
            eprintln!("warning: serving on {address}, beyond this machine; the server has no authentication");
        }
        // Tests and users read the address from this line.
        println!("playground: http://{address}/");
        std::io::stdout().flush()?;
        axum::serve(listener, router(Arc::new(export::State::default()))).await.context("the server stopped")
    })
}

/// Every route, behind the guard against paths outside the served directory.
fn router(state: Arc<export::State>) -> Router {
    Router::new()
        .route("/", get(|| async { file("text/html; charset=utf-8", INDEX_HTML) }))
        .route("/index.html", get(|| async { file("text/html; charset=utf-8", INDEX_HTML) }))
        .route("/playground.js", get(|| async { file("text/javascript; charset=utf-8", PLAYGROUND_JS) }))
        .route("/playground.css", get(|| async { file("text/css; charset=utf-8", PLAYGROUND_CSS) }))
        .route("/api/examples", get(api::examples))
        .route("/api/scenes", get(api::scenes))
        .route("/api/compile", post(api::compile))
        .route("/api/hover", post(assist::hover))
        .route("/api/complete", post(assist::complete))
        .route("/api/gbuffer", post(export::create))
        .route("/api/gbuffer/{key}/{file}", get(export::file))
        .fallback(not_found)
        .method_not_allowed_fallback(|| async {
            ApiError::new(StatusCode::METHOD_NOT_ALLOWED, "method not allowed on this path")
        })
        .layer(axum::middleware::from_fn(refuse_outside))
        .with_state(state)
}

fn file(content_type: &'static str, body: &'static str) -> Response {
    ([(header::CONTENT_TYPE, content_type), (header::CACHE_CONTROL, "no-cache")], body).into_response()
}

async fn not_found(request: Request) -> ApiError {
    ApiError::new(StatusCode::NOT_FOUND, format!("nothing at {}", request.uri().path()))
}

/// Refuses a path with a `..` segment, written out or percent-encoded,
/// before any route sees it.
async fn refuse_outside(request: Request, next: Next) -> Response {
    if outside(request.uri().path()) {
        return ApiError::new(StatusCode::BAD_REQUEST, "path outside the served directory").into_response();
    }
    next.run(request).await
}

/// Whether `path`, percent-decoded, has a `..` segment (between `/` or `\`).
fn outside(path: &str) -> bool {
    let decoded = percent_decode(path);
    decoded.split(['/', '\\']).any(|segment| segment == "..")
}

/// `%XX` escapes decoded once; a `%` not followed by two hex digits stays.
fn percent_decode(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        match (bytes[i], bytes.get(i + 1).copied().and_then(hex), bytes.get(i + 2).copied().and_then(hex)) {
            (b'%', Some(hi), Some(lo)) => {
                out.push((hi * 16 + lo) as u8);
                i += 3;
            }
            (b, ..) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_dot_segments_are_outside_however_written() {
        for path in ["/../Cargo.toml", "/%2e%2e/Cargo.toml", "/%2E%2e/x", "/a/.%2e/b", "/api/gbuffer/k/..", "/a\\..\\b"]
        {
            assert!(outside(path), "{path}");
        }
        for path in ["/", "/playground.js", "/a..b", "/.../x", "/api/gbuffer/k/channel.normal.bin", "/%zz", "/%2"] {
            assert!(!outside(path), "{path}");
        }
    }
}
