//! Completion: after `@`, the attributes; where an `in` declaration names
//! its channel, the channels the evaluation kit's scenes provide; anywhere
//! else the names in scope (from the last version of the document that
//! parsed: a program being typed rarely parses), the builtins, the types
//! and the keywords. The client filters by what was typed.

use super::document::Document;
use lsp_types::{
    CompletionItem, CompletionItemKind, CompletionParams, CompletionResponse, Documentation, MarkupContent, MarkupKind,
};
use mrsl::{DeclarationKind, vocabulary};

pub fn complete(document: &Document, params: CompletionParams) -> CompletionResponse {
    let offset = document.text.offset(params.text_document_position.position);
    let text = &document.text.text;
    let word_start = text[..offset].trim_end_matches(|c: char| c.is_alphanumeric() || c == '_').len();
    let before = &text[..word_start];
    let items = if before.ends_with('@') {
        attributes()
    } else if declares_channel(before) {
        channels()
    } else if before.ends_with('.') {
        // A field or swizzle: nothing the server knows better than the typist.
        vec![]
    } else {
        let mut items = names(document, offset);
        items.extend(words());
        items
    };
    CompletionResponse::Array(items)
}

/// Whether the line so far is `[@attributes] in TYPE ` (the channel's name comes next).
fn declares_channel(before: &str) -> bool {
    let line = before.rsplit('\n').next().unwrap_or(before);
    let words: Vec<&str> = line.split_whitespace().filter(|w| !w.starts_with('@')).collect();
    line.ends_with(char::is_whitespace) && words.len() == 2 && words[0] == "in"
}

fn item(label: &str, kind: CompletionItemKind, detail: String, doc: Option<&str>) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: Some(detail),
        documentation: doc
            .map(|d| Documentation::MarkupContent(MarkupContent { kind: MarkupKind::Markdown, value: d.to_string() })),
        ..CompletionItem::default()
    }
}

fn attributes() -> Vec<CompletionItem> {
    vocabulary::attributes()
        .iter()
        .map(|a| item(a.name, CompletionItemKind::PROPERTY, a.syntax.to_string(), Some(a.doc)))
        .collect()
}

/// The channels of the kit's G-buffer (`mrslc render`'s scenes), with the
/// types a program may declare over each.
fn channels() -> Vec<CompletionItem> {
    mrsl_lab::raster::CHANNELS
        .iter()
        .map(|(name, format)| {
            let detail = format!("channel: {}", crate::scene_check::readable_as(*format));
            item(name, CompletionItemKind::FIELD, detail, None)
        })
        .collect()
}

/// The declarations of the last version that parsed: the top-level ones,
/// and the locals and parameters whose scope holds the cursor there.
fn names(document: &Document, offset: usize) -> Vec<CompletionItem> {
    let (text, analysis) = &*document.parsed;
    // The cursor in the parsed version: the same offset, moved back by what
    // was added since (edits are small and near the cursor).
    let offset = offset.saturating_sub(document.text.text.len().saturating_sub(text.text.len()));
    analysis
        .declarations
        .iter()
        .filter(|d| d.visible.is_none_or(|v| v.range().contains(&offset) || v.end as usize == offset))
        .map(|d| {
            let kind = match d.kind {
                DeclarationKind::Function => CompletionItemKind::FUNCTION,
                DeclarationKind::Const => CompletionItemKind::CONSTANT,
                DeclarationKind::Input => CompletionItemKind::FIELD,
                DeclarationKind::Uniform => CompletionItemKind::PROPERTY,
                DeclarationKind::Effect | DeclarationKind::Output => CompletionItemKind::EVENT,
                DeclarationKind::Local | DeclarationKind::Parameter => CompletionItemKind::VARIABLE,
            };
            let doc = d.effect.and_then(|e| analysis.effects.get(e)).map(super::features::effect_markdown);
            item(&d.name, kind, d.signature.clone(), doc.as_deref())
        })
        .collect()
}

/// The builtins, types and keywords.
fn words() -> Vec<CompletionItem> {
    let builtins = vocabulary::builtins().into_iter().map(|b| {
        let detail = format!("{}({})", b.name, b.arguments);
        item(b.name, CompletionItemKind::FUNCTION, detail, Some(b.doc))
    });
    let types = vocabulary::types().into_iter().map(|t| item(t, CompletionItemKind::STRUCT, "type".into(), None));
    let keywords =
        vocabulary::keywords().into_iter().map(|k| item(k.text, CompletionItemKind::KEYWORD, "keyword".into(), None));
    builtins.chain(types).chain(keywords).collect()
}
