// Syntax colouring of mrsl in CodeMirror: a stream tokenizer over the
// language's keywords, types, attributes, numbers and comments (the
// tokens of compiler/src/syntax). Hand-written because CodeMirror has no
// mrsl mode, and a stream parser is what it offers for a small language.

import { StreamLanguage, type StreamParser } from '@codemirror/language';

const KEYWORDS = new Set(['in', 'uniform', 'const', 'coarse', 'fine', 'effect', 'out', 'refine', 'if', 'else', 'for', 'break', 'continue', 'return']);
const ATOMS = new Set(['true', 'false']);
const TYPE = /^(?:float|int|uint|bool)(?:[234](?:x[234])?)?$|^(?:texture2d|sampler)$/;

interface State {
  inComment: boolean;
}

const parser: StreamParser<State> = {
  name: 'mrsl',
  startState: () => ({ inComment: false }),
  token(stream, state) {
    if (state.inComment) {
      if (stream.skipTo('*/')) {
        stream.pos += 2;
        state.inComment = false;
      } else stream.skipToEnd();
      return 'comment';
    }
    if (stream.eatSpace()) return null;
    if (stream.match('//')) {
      stream.skipToEnd();
      return 'comment';
    }
    if (stream.match('/*')) {
      state.inComment = true;
      return 'comment';
    }
    if (stream.match(/^0[xX][0-9a-fA-F]+[uU]?/) || stream.match(/^(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?[fFuUi]?/)) return 'number';
    if (stream.match(/^@[A-Za-z_]\w*/)) return 'meta';
    const word = stream.match(/^[A-Za-z_]\w*/);
    if (word) {
      const text = (word as RegExpMatchArray)[0];
      if (KEYWORDS.has(text)) return 'keyword';
      if (ATOMS.has(text)) return 'atom';
      if (TYPE.test(text)) return 'typeName';
      return stream.match(/^\s*\(/, false) ? 'variableName.function' : 'variableName';
    }
    stream.next();
    return /[-+*/%=<>!&|^~?:]/.test(stream.current()) ? 'operator' : null;
  },
  languageData: { commentTokens: { line: '//', block: { open: '/*', close: '*/' } } },
};

export const mrsl = StreamLanguage.define(parser);
