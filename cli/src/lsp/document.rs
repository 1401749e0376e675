//! An open document: its text and its analysis, made when the text
//! arrives so that every request after it reads the same facts.

use super::text::{Encoding, Text};
use mrsl::{Analysis, Declaration, EffectFacts};
use std::sync::Arc;

/// A document and what the compiler found in it.
pub struct Document {
    pub text: Text,
    pub analysis: Analysis,
    /// The last version of the document that parsed, and its analysis: a
    /// program being typed rarely parses, and completion still offers the
    /// names it declared (at that version's offsets).
    pub parsed: Arc<(Text, Analysis)>,
    /// The effects of the last version without errors: while an edit is
    /// being typed, hover and inlay hints show the costs and slots the
    /// effects had then (and say so) rather than none.
    pub settled: Arc<Vec<EffectFacts>>,
}

impl Document {
    /// Analyses `text`; `previous` is the document's last version, whose
    /// parsed version is kept when this one does not parse.
    pub fn new(text: String, encoding: Encoding, previous: Option<Document>) -> Document {
        let text = Text::new(text, encoding);
        let analysis = analyze(&text.text);
        let parsed = match &previous {
            Some(previous) if analysis.declarations.is_empty() => previous.parsed.clone(),
            _ => Arc::new((text.clone(), analysis.clone())),
        };
        let errors = analysis.diagnostics.iter().any(|d| d.is_error());
        let settled = match previous.map(|p| p.settled) {
            Some(settled) if errors => settled,
            _ => Arc::new(analysis.effects.clone()),
        };
        Document { text, analysis, parsed, settled }
    }

    /// The facts of effect `index`, and whether they come from the last
    /// version without errors (its layout facts, by name) rather than this one.
    pub fn effect(&self, index: usize) -> Option<(EffectFacts, bool)> {
        let facts = self.analysis.effects.get(index)?;
        if facts.layout.is_some() {
            return Some((facts.clone(), false));
        }
        let settled = self.settled.iter().find(|e| e.name == facts.name && e.layout.is_some());
        Some(match settled {
            Some(old) => (EffectFacts { layout: old.layout.clone(), ..facts.clone() }, true),
            None => (facts.clone(), false),
        })
    }

    /// The declaration of the name at `offset`: the one a reference there
    /// refers to, or the one whose name is there.
    pub fn declaration_at(&self, offset: usize) -> Option<(usize, &Declaration)> {
        let touches = |span: mrsl::Span| span.start as usize <= offset && offset <= span.end as usize;
        let analysis = &self.analysis;
        let index = analysis
            .references
            .iter()
            .find(|r| touches(r.span))
            .map(|r| r.declaration)
            .or_else(|| analysis.declarations.iter().position(|d| touches(d.name_span)))?;
        Some((index, analysis.declarations.get(index)?))
    }
}

/// `mrsl::analyze`, with a panic (a bug in the compiler) reported as a
/// diagnostic of the document instead of ending the server.
fn analyze(source: &str) -> Analysis {
    std::panic::catch_unwind(|| mrsl::analyze(source)).unwrap_or_else(|_| Analysis {
        diagnostics: vec![
            mrsl::Diagnostic::bug("internal compiler error: the analysis of this program panicked")
                .with_note("this is a bug in mrsl; please report it with the program (the server's log has the panic)"),
        ],
        ..Analysis::default()
    })
}
