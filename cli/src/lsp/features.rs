//! The answers read from a document's analysis: diagnostics, hover,
//! definition, references, document symbols, inlay hints (each effect's
//! cost), code actions (the fixes diagnostics name) and formatting.

use super::document::Document;
use lsp_types::{
    CodeAction, CodeActionKind, CodeActionOrCommand, CodeActionParams, DiagnosticRelatedInformation,
    DiagnosticSeverity, DocumentFormattingParams, DocumentSymbol, DocumentSymbolParams, DocumentSymbolResponse,
    GotoDefinitionParams, GotoDefinitionResponse, Hover, HoverContents, HoverParams, InlayHint, InlayHintLabel,
    InlayHintParams, InlayHintTooltip, Location, MarkupContent, MarkupKind, NumberOrString, ReferenceParams,
    SymbolKind, TextEdit, Uri, WorkspaceEdit,
};
use mrsl::{Declaration, DeclarationKind, EffectFacts, Severity, vocabulary};
use std::collections::HashMap;

/// Request parameters that name a document.
pub trait Addressed {
    fn uri(&self) -> &Uri;
}

macro_rules! addressed {
    ($($params:ty => |$p:ident| $uri:expr;)*) => {
        $(impl Addressed for $params {
            fn uri(&self) -> &Uri {
                let $p = self;
                &$uri
            }
        })*
    };
}

addressed! {
    HoverParams => |p| p.text_document_position_params.text_document.uri;
    GotoDefinitionParams => |p| p.text_document_position_params.text_document.uri;
    ReferenceParams => |p| p.text_document_position.text_document.uri;
    DocumentSymbolParams => |p| p.text_document.uri;
    InlayHintParams => |p| p.text_document.uri;
    CodeActionParams => |p| p.text_document.uri;
    lsp_types::CompletionParams => |p| p.text_document_position.text_document.uri;
    DocumentFormattingParams => |p| p.text_document.uri;
}

/// The compiler's diagnostics in the protocol's terms: the code, the
/// message with the primary label and the notes (help included) under it,
/// and the secondary labels as related information.
pub fn diagnostics(document: &Document, uri: &Uri) -> Vec<lsp_types::Diagnostic> {
    let text = &document.text;
    document
        .analysis
        .diagnostics
        .iter()
        .map(|d| {
            let primary = d.labels.iter().find(|l| l.primary);
            let mut message = d.message.clone();
            if let Some(label) = primary.filter(|l| !l.message.is_empty()) {
                message.push_str(&format!(" ({})", label.message));
            }
            for note in &d.notes {
                message.push('\n');
                message.push_str(note);
            }
            let related: Vec<DiagnosticRelatedInformation> = d
                .labels
                .iter()
                .filter(|l| !l.primary)
                .map(|l| DiagnosticRelatedInformation {
                    location: Location::new(uri.clone(), text.range(l.span)),
                    message: l.message.clone(),
                })
                .collect();
            lsp_types::Diagnostic {
                range: text.range(d.span().unwrap_or_default()),
                severity: Some(match d.severity {
                    Severity::Warning => DiagnosticSeverity::WARNING,
                    Severity::Error | Severity::Bug => DiagnosticSeverity::ERROR,
                }),
                code: Some(NumberOrString::String(d.code.to_string())),
                source: Some("mrsl".into()),
                message,
                related_information: (!related.is_empty()).then_some(related),
                ..lsp_types::Diagnostic::default()
            }
        })
        .collect()
}

pub fn hover(document: &Document, params: HoverParams) -> Option<Hover> {
    let offset = document.text.offset(params.text_document_position_params.position);
    let (markdown, span) = match document.declaration_at(offset) {
        Some((_, declaration)) => {
            let span = document.analysis.references.iter().find(|r| r.span.range().contains(&offset)).map(|r| r.span);
            (declaration_markdown(document, declaration), span.unwrap_or(declaration.name_span))
        }
        None => {
            let (span, word) = document.text.word_at(offset)?;
            let after_at = document.text.text[..span.start as usize].ends_with('@');
            (word_markdown(word, after_at)?, span)
        }
    };
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent { kind: MarkupKind::Markdown, value: markdown }),
        range: Some(document.text.range(span)),
    })
}

/// A declaration's signature, and for an effect what the compiler decided about it.
fn declaration_markdown(document: &Document, declaration: &Declaration) -> String {
    let mut out = format!("```mrsl\n{}\n```\n{}", declaration.signature, declaration.kind.word());
    if let Some((facts, settled)) = declaration.effect.and_then(|e| document.effect(e)) {
        out.push_str(&format!(" at rate `{}`\n\n", facts.rate));
        out.push_str(&effect_markdown(&facts));
        if settled {
            out.push_str("\n\n*(cost and slot as of the last version without errors)*");
        }
    } else {
        out.push_str(&format!(" · `{}`", declaration.ty));
    }
    out
}

/// Cost, slot, refinement and evaluations of an effect, a line each.
pub fn effect_markdown(facts: &EffectFacts) -> String {
    let Some(layout) = &facts.layout else {
        return "(cost and slot once the program has no errors)".into();
    };
    let mut lines = vec![];
    if !layout.live {
        lines.push("not computed: no output reads it".to_string());
    }
    if let Some(operations) = layout.operations {
        let mut cost = format!("**cost**: {} operations per evaluation", thousands(operations));
        if let Some(inlined) = layout.inlined_operations {
            // The size budget counts the inlined code, each loop body once (E0701).
            cost.push_str(&format!(
                "; its inlined code: {} of the size budget's {}",
                thousands(inlined),
                thousands(mrsl::MAX_EFFECT_OPERATIONS)
            ));
        }
        lines.push(cost);
    }
    if let Some(evaluations) = layout.sample_evaluations {
        lines.push(format!("**evaluated** {evaluations}× per coarse sample"));
    }
    match &layout.slot {
        Some(slot) if slot.shared_with.is_empty() => lines.push(format!(
            "**slot** {} (words {}..{}), not shared",
            slot.index,
            slot.offset,
            slot.offset + slot.size
        )),
        Some(slot) => lines.push(format!(
            "**slot** {} (words {}..{}), shared with {}",
            slot.index,
            slot.offset,
            slot.offset + slot.size,
            quoted(&slot.shared_with)
        )),
        None if facts.rate.starts_with("coarse") => lines.push("**slot**: none (not passed to the fine pass)".into()),
        None => {}
    }
    if !layout.keys.is_empty() {
        lines.push(format!("**refined by keys** {}", quoted(&layout.keys)));
    }
    for predicate in &facts.predicates {
        lines.push(format!("**refines where** `{predicate}`"));
    }
    if let Some(condition) = &layout.pass_condition {
        lines.push(format!("**passed when** `{condition}`"));
    }
    lines.join("  \n")
}

fn quoted(names: &[String]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}

/// `12345` as `12,345`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// What the vocabulary says of a word that is no declaration: a builtin,
/// an attribute (after `@`), a type or a keyword.
fn word_markdown(word: &str, after_at: bool) -> Option<String> {
    if after_at {
        let attribute = vocabulary::attributes().iter().find(|a| a.name == word)?;
        return Some(format!("```mrsl\n{}\n```\n{}", attribute.syntax, attribute.doc));
    }
    if let Some(builtin) = vocabulary::builtins().into_iter().find(|b| b.name == word) {
        let derivative = if builtin.derivative { "\n\nA derivative: effect bodies only." } else { "" };
        return Some(format!("```mrsl\n{}\n```\n{}: {}{derivative}", builtin.name, builtin.arguments, builtin.doc));
    }
    if vocabulary::types().contains(&word) {
        return Some(format!("```mrsl\n{word}\n```\ntype"));
    }
    vocabulary::keywords().iter().any(|k| k.text == word).then(|| format!("```mrsl\n{word}\n```\nkeyword"))
}

pub fn definition(document: &Document, params: GotoDefinitionParams) -> Option<GotoDefinitionResponse> {
    let position = &params.text_document_position_params;
    let (_, declaration) = document.declaration_at(document.text.offset(position.position))?;
    let location = Location::new(position.text_document.uri.clone(), document.text.range(declaration.name_span));
    Some(GotoDefinitionResponse::Scalar(location))
}

pub fn references(document: &Document, params: ReferenceParams) -> Option<Vec<Location>> {
    let position = &params.text_document_position;
    let (index, declaration) = document.declaration_at(document.text.offset(position.position))?;
    let uri = &position.text_document.uri;
    let declared = params.context.include_declaration.then_some(declaration.name_span);
    let uses = document.analysis.references.iter().filter(|r| r.declaration == index).map(|r| r.span);
    Some(declared.into_iter().chain(uses).map(|span| Location::new(uri.clone(), document.text.range(span))).collect())
}

/// The top-level declarations, with their parameters and locals inside.
pub fn symbols(document: &Document, _: DocumentSymbolParams) -> DocumentSymbolResponse {
    let analysis = &document.analysis;
    let symbol = |d: &Declaration, children: Option<Vec<DocumentSymbol>>| {
        let detail = match d.effect.and_then(|e| analysis.effects.get(e)) {
            Some(facts) => effect_detail(facts, &d.ty),
            None => d.ty.clone(),
        };
        #[allow(deprecated)] // `deprecated` is a field every constructor must set.
        DocumentSymbol {
            name: d.name.clone(),
            detail: Some(detail),
            kind: symbol_kind(d.kind),
            tags: None,
            deprecated: None,
            range: document.text.range(d.span),
            selection_range: document.text.range(d.name_span),
            children,
        }
    };
    let is_local = |d: &&Declaration| d.visible.is_some();
    let top = analysis.declarations.iter().filter(|d| !is_local(d)).map(|item| {
        let inside = analysis
            .declarations
            .iter()
            .filter(is_local)
            .filter(|d| item.span.range().contains(&(d.span.start as usize)));
        symbol(item, Some(inside.map(|d| symbol(d, None)).collect()))
    });
    DocumentSymbolResponse::Nested(top.collect())
}

/// `coarse float3 · 1,234 ops`.
fn effect_detail(facts: &EffectFacts, ty: &str) -> String {
    let cost = facts.layout.as_ref().and_then(|l| l.operations).map(|n| format!(" · {} ops", thousands(n)));
    format!("{} {ty}{}", facts.rate, cost.unwrap_or_default())
}

fn symbol_kind(kind: DeclarationKind) -> SymbolKind {
    match kind {
        DeclarationKind::Input => SymbolKind::FIELD,
        DeclarationKind::Uniform => SymbolKind::PROPERTY,
        DeclarationKind::Const => SymbolKind::CONSTANT,
        DeclarationKind::Function => SymbolKind::FUNCTION,
        DeclarationKind::Effect => SymbolKind::EVENT,
        DeclarationKind::Output => SymbolKind::INTERFACE,
        DeclarationKind::Local | DeclarationKind::Parameter => SymbolKind::VARIABLE,
    }
}

/// After each effect's name: its cost in operations, and its evaluations
/// per coarse sample where they are more than one.
pub fn inlay_hints(document: &Document, params: InlayHintParams) -> Vec<InlayHint> {
    let wanted = document.text.span(params.range);
    let analysis = &document.analysis;
    analysis
        .declarations
        .iter()
        .filter(|d| wanted.start <= d.name_span.end && d.name_span.start <= wanted.end)
        .filter_map(|d| {
            let (facts, _) = document.effect(d.effect?)?;
            let layout = facts.layout.as_ref()?;
            let mut label = format!("{} ops", thousands(layout.operations?));
            if let Some(n) = layout.sample_evaluations.filter(|&n| n > 1) {
                label.push_str(&format!(" ×{n}"));
            }
            Some(InlayHint {
                position: document.text.position(d.name_span.end as usize),
                label: InlayHintLabel::String(label),
                kind: None,
                text_edits: None,
                tooltip: Some(InlayHintTooltip::MarkupContent(MarkupContent {
                    kind: MarkupKind::Markdown,
                    value: effect_markdown(&facts),
                })),
                padding_left: Some(true),
                padding_right: None,
                data: None,
            })
        })
        .collect()
}

/// The document in `mrslc fmt`'s layout (`mrsl::format`), as one edit of
/// the whole text; no edit when it is formatted already or does not parse
/// (its syntax error is among the published diagnostics).
pub fn format(document: &Document, _: DocumentFormattingParams) -> Vec<TextEdit> {
    match mrsl::format(&document.text.text) {
        Ok(formatted) if formatted != document.text.text => vec![TextEdit::new(document.text.whole(), formatted)],
        _ => vec![],
    }
}

/// A quick fix for each diagnostic in the range whose note names a
/// mechanical replacement (`mrsl::quick_fix`).
pub fn code_actions(document: &Document, params: CodeActionParams) -> Vec<CodeActionOrCommand> {
    let wanted = document.text.span(params.range);
    let published = diagnostics(document, &params.text_document.uri);
    document
        .analysis
        .diagnostics
        .iter()
        .zip(published)
        .filter_map(|(d, published)| {
            let fix = mrsl::quick_fix(d)?;
            (fix.span.start <= wanted.end && wanted.start <= fix.span.end).then_some((fix, published))
        })
        .map(|(fix, published)| {
            let old = document.text.text.get(fix.span.range()).unwrap_or_default();
            let edit = TextEdit::new(document.text.range(fix.span), fix.replacement.clone());
            CodeActionOrCommand::CodeAction(CodeAction {
                title: format!("Replace `{old}` with `{}`", fix.replacement),
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![published]),
                edit: Some(WorkspaceEdit {
                    changes: Some(HashMap::from([(params.text_document.uri.clone(), vec![edit])])),
                    ..WorkspaceEdit::default()
                }),
                is_preferred: Some(true),
                ..CodeAction::default()
            })
        })
        .collect()
}
