//! An open document: its text and its analysis, made when the text
//! arrives so that every request after it reads the same facts.

use super::text::{Encoding, Text};
use mrsl::{Analysis, Declaration};
use std::sync::Arc;

/// A document and what the compiler found in it.
pub struct Document {
    pub text: Text,
    pub analysis: Analysis,
    /// The last version of the document that parsed, and its analysis: a
    /// program being typed rarely parses, and completion still offers the
    /// names it declared (at that version's offsets).
    pub parsed: Arc<(Text, Analysis)>,
}

impl Document {
    /// Analyses `text`; `previous` is the document's last version, whose
    /// parsed version is kept when this one does not parse.
    pub fn new(text: String, encoding: Encoding, previous: Option<Document>) -> Document {
        let text = Text::new(text, encoding);
        let analysis = mrsl::analyze(&text.text);
        let parsed = if !analysis.declarations.is_empty() || previous.is_none() {
            Arc::new((text.clone(), analysis.clone()))
        } else {
            previous.map(|p| p.parsed).expect("checked above")
        };
        Document { text, analysis, parsed }
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
