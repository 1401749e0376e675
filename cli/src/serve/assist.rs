//! The playground's editor help from the language server's own functions
//! (`mrslc lsp`): `POST /api/hover` and `POST /api/complete` take the
//! program and a position (a 0-based line and a UTF-16 column, as the
//! browser counts them) and answer with the server's `Hover` or completion
//! items, as the language server protocol writes them.

use super::reply::{ApiError, read_json};
use crate::lsp::{Document, Encoding, completion, features};
use axum::Json;
use axum::body::Body;
use lsp_types::{CompletionParams, HoverParams, Position, TextDocumentIdentifier, TextDocumentPositionParams, Uri};
use serde::Deserialize;
use serde_json::Value;

#[derive(Deserialize)]
struct At {
    source: String,
    line: u32,
    character: u32,
}

impl At {
    /// The document and where in it, as a language client would name them.
    fn position(self) -> Result<(Document, TextDocumentPositionParams), ApiError> {
        let uri: Uri = "file:///playground.mrsl".parse().map_err(|_| ApiError::internal("a document name"))?;
        let document = Document::new(self.source, Encoding::Utf16, None);
        let at = Position { line: self.line, character: self.character };
        Ok((document, TextDocumentPositionParams { text_document: TextDocumentIdentifier { uri }, position: at }))
    }
}

/// `POST /api/hover {source, line, character}`: the hover there, or null.
pub async fn hover(body: Body) -> Result<Json<Value>, ApiError> {
    let (document, at) = read_json::<At>(body).await?.position()?;
    let params = HoverParams { text_document_position_params: at, work_done_progress_params: Default::default() };
    Ok(Json(serde_json::to_value(features::hover(&document, params)).unwrap_or(Value::Null)))
}

/// `POST /api/complete {source, line, character}`: the completion items there.
pub async fn complete(body: Body) -> Result<Json<Value>, ApiError> {
    let (document, at) = read_json::<At>(body).await?.position()?;
    let params = CompletionParams {
        text_document_position: at,
        work_done_progress_params: Default::default(),
        partial_result_params: Default::default(),
        context: None,
    };
    Ok(Json(serde_json::to_value(completion::complete(&document, params)).unwrap_or(Value::Null)))
}
