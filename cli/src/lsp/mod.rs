//! `mrslc lsp`: the language server, over standard input and output.
//!
//! One thread reads messages in order (rust-analyzer's `lsp-server`, whose
//! reader and writer threads do the framing) and answers each before the
//! next: every document is analysed when it is opened or changed
//! (`mrsl::analyze`: the front end and the layout, no kernels), its
//! diagnostics are published then, and every request reads that analysis.
//! A request about a document the server does not have answers an empty
//! result, and one whose parameters do not parse answers an error: nothing
//! a client sends stops the server.
//!
//! The features live beside this file: `text` converts positions,
//! `document` holds a document and its analysis, `features` answers hovers,
//! definitions, references, symbols, inlay hints, code actions, formatting
//! (`mrsl::format`, as `mrslc fmt`) and diagnostics, and `completion` completes.

use anyhow::{Context, Result};
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, RequestId, Response};
use lsp_types::notification::{
    DidChangeTextDocument, DidCloseTextDocument, DidOpenTextDocument, Notification as _, PublishDiagnostics,
};
use lsp_types::request::{
    CodeActionRequest, Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest, InlayHintRequest,
    References, Request as _,
};
use lsp_types::{
    CodeActionProviderCapability, CompletionOptions, InitializeParams, OneOf, PositionEncodingKind,
    PublishDiagnosticsParams, ServerCapabilities, ServerInfo, TextDocumentSyncCapability, TextDocumentSyncKind, Uri,
};
use std::collections::HashMap;
pub(crate) use text::Encoding;

// `completion` and `features` also answer the playground (serve::assist).
pub(crate) mod completion;
mod document;
pub(crate) mod features;
mod text;

pub use document::Document;

/// Runs the server until the client says `exit` (or closes the stream).
pub fn serve() -> Result<()> {
    let (connection, io_threads) = Connection::stdio();
    let (id, params) = connection.initialize_start().context("the client's initialize request")?;
    let params: InitializeParams = serde_json::from_value(params).context("the initialize request's parameters")?;
    let encoding = negotiate(&params);
    let result = serde_json::json!({
        "capabilities": capabilities(encoding),
        "serverInfo": ServerInfo { name: "mrslc".into(), version: Some(env!("CARGO_PKG_VERSION").into()) },
    });
    connection.initialize_finish(id, result).context("finishing the initialization")?;
    Server { connection: &connection, documents: HashMap::new(), encoding }.run()?;
    drop(connection);
    io_threads.join().context("the server's input and output threads")?;
    Ok(())
}

/// UTF-8 columns when the client offers them (no conversion), else the
/// protocol's default, UTF-16.
fn negotiate(params: &InitializeParams) -> Encoding {
    let offered = params.capabilities.general.as_ref().and_then(|g| g.position_encodings.as_ref());
    match offered {
        Some(kinds) if kinds.contains(&PositionEncodingKind::UTF8) => Encoding::Utf8,
        _ => Encoding::Utf16,
    }
}

fn capabilities(encoding: Encoding) -> ServerCapabilities {
    ServerCapabilities {
        position_encoding: Some(match encoding {
            Encoding::Utf8 => PositionEncodingKind::UTF8,
            Encoding::Utf16 => PositionEncodingKind::UTF16,
        }),
        text_document_sync: Some(TextDocumentSyncCapability::Kind(TextDocumentSyncKind::FULL)),
        hover_provider: Some(true.into()),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        document_symbol_provider: Some(OneOf::Left(true)),
        inlay_hint_provider: Some(OneOf::Left(true)),
        code_action_provider: Some(CodeActionProviderCapability::Simple(true)),
        document_formatting_provider: Some(OneOf::Left(true)),
        completion_provider: Some(CompletionOptions {
            trigger_characters: Some(vec!["@".into(), ".".into()]),
            ..CompletionOptions::default()
        }),
        ..ServerCapabilities::default()
    }
}

/// The server's state: the open documents, by URI.
struct Server<'c> {
    connection: &'c Connection,
    documents: HashMap<Uri, Document>,
    encoding: Encoding,
}

impl Server<'_> {
    fn run(&mut self) -> Result<()> {
        for message in &self.connection.receiver {
            match message {
                Message::Request(request) => {
                    if self.connection.handle_shutdown(&request)? {
                        return Ok(());
                    }
                    let id = request.id.clone();
                    // A panic answering one request (a bug) answers it with an error, not the session.
                    let response = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.request(request)))
                        .unwrap_or_else(|_| {
                            error(id, ErrorCode::InternalError, "mrslc lsp panicked (see its log)".into())
                        });
                    self.connection.sender.send(Message::Response(response))?;
                }
                Message::Notification(notification) => self.notification(notification)?,
                Message::Response(_) => {}
            }
        }
        Ok(())
    }

    /// The answer to a request: its result, or an error for a method the
    /// server does not answer or parameters that do not parse.
    fn request(&self, request: Request) -> Response {
        let id = request.id.clone();
        let answer = match request.method.as_str() {
            HoverRequest::METHOD => self.answer(request, features::hover),
            GotoDefinition::METHOD => self.answer(request, features::definition),
            References::METHOD => self.answer(request, features::references),
            DocumentSymbolRequest::METHOD => self.answer(request, features::symbols),
            InlayHintRequest::METHOD => self.answer(request, features::inlay_hints),
            CodeActionRequest::METHOD => self.answer(request, features::code_actions),
            Completion::METHOD => self.answer(request, completion::complete),
            Formatting::METHOD => self.answer(request, features::format),
            method => return error(id, ErrorCode::MethodNotFound, format!("mrslc lsp does not answer `{method}`")),
        };
        match answer {
            Ok(value) => Response::new_ok(id, value),
            Err(message) => error(id, ErrorCode::InvalidParams, message),
        }
    }

    /// Parses a request's parameters, finds its document and answers with
    /// `handler` (`null` for a document the server does not have).
    fn answer<P, R>(
        &self,
        request: Request,
        handler: impl Fn(&Document, P) -> R,
    ) -> std::result::Result<serde_json::Value, String>
    where
        P: serde::de::DeserializeOwned + features::Addressed,
        R: serde::Serialize,
    {
        let params: P = serde_json::from_value(request.params).map_err(|e| format!("{}: {e}", request.method))?;
        let value = match self.documents.get(params.uri()) {
            Some(document) => serde_json::to_value(handler(document, params)),
            None => Ok(serde_json::Value::Null),
        };
        value.map_err(|e| e.to_string())
    }

    fn notification(&mut self, notification: Notification) -> Result<()> {
        let (uri, text) = match notification.method.as_str() {
            DidOpenTextDocument::METHOD => {
                let Ok(params) =
                    notification.extract::<lsp_types::DidOpenTextDocumentParams>(DidOpenTextDocument::METHOD)
                else {
                    return Ok(());
                };
                (params.text_document.uri, params.text_document.text)
            }
            DidChangeTextDocument::METHOD => {
                let Ok(mut params) =
                    notification.extract::<lsp_types::DidChangeTextDocumentParams>(DidChangeTextDocument::METHOD)
                else {
                    return Ok(());
                };
                // Full synchronisation: the last change is the whole text.
                let Some(change) = params.content_changes.pop() else { return Ok(()) };
                (params.text_document.uri, change.text)
            }
            DidCloseTextDocument::METHOD => {
                if let Ok(params) =
                    notification.extract::<lsp_types::DidCloseTextDocumentParams>(DidCloseTextDocument::METHOD)
                {
                    self.documents.remove(&params.text_document.uri);
                    self.publish(params.text_document.uri, vec![])?;
                }
                return Ok(());
            }
            _ => return Ok(()),
        };
        let previous = self.documents.remove(&uri);
        let document = Document::new(text, self.encoding, previous);
        let diagnostics = features::diagnostics(&document, &uri);
        self.documents.insert(uri.clone(), document);
        self.publish(uri, diagnostics)
    }

    fn publish(&self, uri: Uri, diagnostics: Vec<lsp_types::Diagnostic>) -> Result<()> {
        let params = PublishDiagnosticsParams { uri, diagnostics, version: None };
        let notification = Notification::new(PublishDiagnostics::METHOD.into(), params);
        self.connection.sender.send(Message::Notification(notification))?;
        Ok(())
    }
}

fn error(id: RequestId, code: ErrorCode, message: String) -> Response {
    Response::new_err(id, code as i32, message)
}
