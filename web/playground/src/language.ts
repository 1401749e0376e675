// Syntax colouring of mrsl in CodeMirror: a stream tokenizer over the
// language's words. The words come from vocabulary.generated.ts, which the
// compiler's tests write from the compiler's own tables (mrsl::vocabulary,
// as the editors' TextMate grammar is), so the playground colours what the
// compiler reads. CodeMirror has no mrsl mode, and a stream parser is what
// it offers for a small language.

import { StreamLanguage, type StreamParser } from '@codemirror/language';
import {
  ATTRIBUTES,
  BLOCK_COMMENT,
  BOOLEANS,
  BUILTINS,
  CONTROL_KEYWORDS,
  DECLARATION_KEYWORDS,
  LINE_COMMENT,
  NUMBER_PATTERNS,
  OPERATORS,
  PUNCTUATION,
  RATE_KEYWORDS,
  TYPES,
} from './vocabulary.generated.js';

// Each name's token type (CodeMirror's highlighting tags, `.`-joined). The
// builtins are `special` names: the default style colours those, not `standard`.
const WORDS = new Map<string, string>([
  ...DECLARATION_KEYWORDS.map((w) => [w, 'definitionKeyword'] as const),
  ...RATE_KEYWORDS.map((w) => [w, 'modifier'] as const),
  ...CONTROL_KEYWORDS.map((w) => [w, 'controlKeyword'] as const),
  ...BOOLEANS.map((w) => [w, 'bool'] as const),
  ...TYPES.map((w) => [w, 'typeName'] as const),
  ...BUILTINS.map((w) => [w, 'variableName.special'] as const),
]);
const ATTRIBUTE_NAMES = new Set(ATTRIBUTES);
const NUMBERS = NUMBER_PATTERNS.map((p) => new RegExp(`^(?:${p})`));
const [BLOCK_OPEN, BLOCK_CLOSE] = BLOCK_COMMENT;

interface State {
  inComment: boolean;
}

export const mrslParser: StreamParser<State> = {
  name: 'mrsl',
  startState: () => ({ inComment: false }),
  token(stream, state) {
    if (state.inComment) {
      if (stream.skipTo(BLOCK_CLOSE)) {
        stream.pos += BLOCK_CLOSE.length;
        state.inComment = false;
      } else stream.skipToEnd();
      return 'comment';
    }
    if (stream.eatSpace()) return null;
    if (stream.match(LINE_COMMENT)) {
      stream.skipToEnd();
      return 'comment';
    }
    if (stream.match(BLOCK_OPEN)) {
      state.inComment = true;
      return 'comment';
    }
    // In order: a float's digits would also match as a decimal.
    if (NUMBERS.some((n) => stream.match(n))) return 'number';
    const attribute = stream.match(/^@\s*([\p{XID_Start}_]\p{XID_Continue}*)/u, false) as RegExpMatchArray | null;
    if (attribute && ATTRIBUTE_NAMES.has(attribute[1] ?? '')) {
      stream.pos += attribute[0].length;
      return 'meta';
    }
    const word = stream.match(/^[\p{XID_Start}_]\p{XID_Continue}*/u) as RegExpMatchArray | null;
    if (word) {
      const type = WORDS.get(word[0]);
      if (type) return type;
      return stream.match(/^\s*\(/, false) ? 'variableName.function' : 'variableName';
    }
    if (OPERATORS.some((op) => stream.match(op))) return 'operator';
    if (PUNCTUATION.some((p) => stream.match(p))) return 'punctuation';
    stream.next();
    return null;
  },
  languageData: { commentTokens: { line: LINE_COMMENT, block: { open: BLOCK_OPEN, close: BLOCK_CLOSE } } },
};

export const mrsl = StreamLanguage.define(mrslParser);
