//! Positions as the protocol counts them: a line, and a column in UTF-16
//! code units (the protocol's default) or in bytes (UTF-8, when the client
//! offers it at initialisation), converted to and from the byte offsets the
//! compiler's spans hold. Lines end at `\n` (a `\r` before it belongs to
//! the line, as it takes no column an editor shows).

use lsp_types::{Position, Range};
use mrsl::Span;

/// How columns are counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    Utf8,
    Utf16,
}

/// A document's text with the byte offset of each line's start.
#[derive(Debug, Clone)]
pub struct Text {
    pub text: String,
    starts: Vec<usize>,
    encoding: Encoding,
}

impl Text {
    pub fn new(text: String, encoding: Encoding) -> Text {
        let starts = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
        Text { text, starts, encoding }
    }

    /// The position of a byte offset (clamped to the text, and back to a
    /// character boundary).
    pub fn position(&self, offset: usize) -> Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&start| start <= offset) - 1;
        let before = &self.text[self.starts[line]..offset];
        let column = match self.encoding {
            Encoding::Utf8 => before.len(),
            Encoding::Utf16 => before.encode_utf16().count(),
        };
        Position::new(line as u32, column as u32)
    }

    /// The byte offset of a position: a column past the line's end is its
    /// end, a line past the text's end is the text's end, and a column
    /// inside a character (half a surrogate pair) is that character's start.
    pub fn offset(&self, position: Position) -> usize {
        let Some(&start) = self.starts.get(position.line as usize) else { return self.text.len() };
        let end = self.starts.get(position.line as usize + 1).map_or(self.text.len(), |next| next - 1);
        let line = &self.text[start..end];
        let mut units = 0;
        for (i, c) in line.char_indices() {
            units += match self.encoding {
                Encoding::Utf8 => c.len_utf8(),
                Encoding::Utf16 => c.len_utf16(),
            };
            if units > position.character as usize {
                return start + i;
            }
        }
        end
    }

    pub fn range(&self, span: Span) -> Range {
        Range::new(self.position(span.start as usize), self.position(span.end as usize))
    }

    pub fn span(&self, range: Range) -> Span {
        Span::new(self.offset(range.start), self.offset(range.end))
    }

    /// The range of the whole text.
    pub fn whole(&self) -> Range {
        Range::new(Position::new(0, 0), self.position(self.text.len()))
    }

    /// The identifier around `offset` (touching it on either side), if any.
    pub fn word_at(&self, offset: usize) -> Option<(Span, &str)> {
        let offset = offset.min(self.text.len());
        let is_word = |c: char| c.is_alphanumeric() || c == '_';
        let start =
            self.text[..offset].char_indices().rev().take_while(|(_, c)| is_word(*c)).last().map_or(offset, |(i, _)| i);
        let end =
            self.text[offset..].char_indices().find(|(_, c)| !is_word(*c)).map_or(self.text.len(), |(i, _)| offset + i);
        (start < end).then(|| (Span::new(start, end), &self.text[start..end]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A comment with characters of two and four UTF-16 units moves the
    /// columns after it by their units, not their bytes.
    #[test]
    fn columns_count_utf16_units_or_bytes() {
        let source = "// é 😀\nfloat x; // 😀 y\n".to_string();
        let y = source.rfind('y').unwrap();
        let utf16 = Text::new(source.clone(), Encoding::Utf16);
        assert_eq!(utf16.position(y), Position::new(1, 15));
        assert_eq!(utf16.offset(Position::new(1, 15)), y);
        let utf8 = Text::new(source.clone(), Encoding::Utf8);
        assert_eq!(utf8.position(y), Position::new(1, 17));
        assert_eq!(utf8.offset(Position::new(1, 17)), y);
        // Inside the emoji's surrogate pair: the emoji's start.
        let emoji = source.find('😀').unwrap();
        assert_eq!(utf16.offset(Position::new(0, 6)), emoji);
        // Past the line's end and past the text's end.
        assert_eq!(utf16.offset(Position::new(0, 99)), source.find('\n').unwrap());
        assert_eq!(utf16.offset(Position::new(9, 0)), source.len());
        assert_eq!(utf16.position(source.len()), Position::new(2, 0));
        for offset in 0..=source.len() {
            if source.is_char_boundary(offset) {
                assert_eq!(utf16.offset(utf16.position(offset)), offset, "at {offset}");
                assert_eq!(utf8.offset(utf8.position(offset)), offset, "at {offset}");
            }
        }
        assert_eq!(utf16.word_at(y + 1).map(|(_, w)| w), Some("y"));
        assert_eq!(utf16.word_at(source.find("float").unwrap() + 2).map(|(_, w)| w), Some("float"));
    }
}
