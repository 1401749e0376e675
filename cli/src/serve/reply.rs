//! The server's refusals as JSON (`{"error": "..."}` with a status), and
//! request bodies read with a size limit and parsed with serde's messages.

use axum::Json;
use axum::body::Body;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use http_body_util::BodyExt;
use serde::de::DeserializeOwned;

/// The largest request body the server takes (a program of 1 MiB is far
/// past anything the compiler's size budget lets through).
pub const MAX_BODY: usize = 1 << 20;

/// How much of a larger body is read (and dropped) before the refusal is
/// sent: a client that writes its whole body before reading the reply then
/// gets the reply instead of a reset connection.
const MAX_DRAINED: usize = 64 << 20;

/// A refusal: its status and its message.
#[derive(Debug)]
pub struct ApiError {
    pub status: StatusCode,
    pub message: String,
}

impl ApiError {
    pub fn new(status: StatusCode, message: impl Into<String>) -> ApiError {
        ApiError { status, message: message.into() }
    }

    pub fn bad_request(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, message)
    }

    pub fn internal(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, message)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.status, Json(serde_json::json!({ "error": self.message }))).into_response()
    }
}

/// Reads a JSON body of at most [`MAX_BODY`] bytes: a larger one is 413,
/// one that is not the JSON `T` is 400 with serde's message.
pub async fn read_json<T: DeserializeOwned>(mut body: Body) -> Result<T, ApiError> {
    let mut bytes = Vec::new();
    let mut seen = 0usize;
    while let Some(frame) = body.frame().await {
        let frame = frame.map_err(|e| ApiError::bad_request(format!("cannot read the request body: {e}")))?;
        let Ok(data) = frame.into_data() else { continue };
        seen += data.len();
        if seen <= MAX_BODY {
            bytes.extend_from_slice(&data);
        } else if seen > MAX_DRAINED {
            break;
        }
    }
    if seen > MAX_BODY {
        let message = format!("the request body is over {MAX_BODY} bytes (1 MiB), the most the server takes");
        return Err(ApiError::new(StatusCode::PAYLOAD_TOO_LARGE, message));
    }
    serde_json::from_slice(&bytes).map_err(|e| ApiError::bad_request(format!("malformed request: {e}")))
}

/// Runs `work` on the blocking pool; a panic there is a 500, not a crash.
pub async fn blocking<T: Send + 'static>(
    work: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(work).await.map_err(|e| ApiError::internal(format!("the request failed: {e}")))?
}
