// The playground's CodeMirror mode (playground/src/language.ts) colours
// every word of the generated vocabulary as its kind, and that vocabulary
// holds the same words as the editors' TextMate grammar: both are written
// from the compiler's tables by compiler/tests/it/sourcegen.rs.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import * as esbuild from 'esbuild';
import { REPO } from './support/mrslc.mjs';

const SRC = join(REPO, 'web', 'playground', 'src');
let dir;
let mode;

before(async () => {
  // The mode is TypeScript importing CodeMirror: bundle it (and CodeMirror's
  // StringStream, which the editor hands the tokenizer) into one module.
  dir = mkdtempSync(join(tmpdir(), 'mrsl-language-'));
  const outfile = join(dir, 'language.mjs');
  await esbuild.build({
    stdin: {
      contents: "export { mrslParser } from './language.ts'; export * as vocabulary from './vocabulary.generated.ts'; export { StringStream } from '@codemirror/language';",
      resolveDir: SRC,
      loader: 'ts',
    },
    bundle: true,
    format: 'esm',
    platform: 'node',
    outfile,
    logLevel: 'warning',
  });
  mode = await import(pathToFileURL(outfile).href);
});

after(() => {
  if (dir) rmSync(dir, { recursive: true, force: true });
});

/** The tokens of `source`, line by line, as [text, token type]. */
function tokenize(source) {
  const { mrslParser, StringStream } = mode;
  const state = mrslParser.startState(4);
  const tokens = [];
  for (const line of source.split('\n')) {
    const stream = new StringStream(line, 4, 2);
    while (!stream.eol()) {
      const type = mrslParser.token(stream, state);
      assert.ok(stream.pos > stream.start, `the tokenizer advances in \`${line}\``);
      if (type) tokens.push([stream.current(), type]);
      stream.start = stream.pos;
    }
  }
  return tokens;
}

/** The type of `word` standing alone in `before WORD after`. */
function typeOf(word, before = '', after = '') {
  const found = tokenize(`${before}${word}${after}`).find(([text]) => text === word);
  return found?.[1];
}

test('every word of the vocabulary is coloured as its kind', () => {
  const v = mode.vocabulary;
  const expected = [
    [v.DECLARATION_KEYWORDS, 'definitionKeyword'],
    [v.RATE_KEYWORDS, 'modifier'],
    [v.CONTROL_KEYWORDS, 'controlKeyword'],
    [v.BOOLEANS, 'bool'],
    [v.TYPES, 'typeName'],
    [v.BUILTINS, 'variableName.special'],
    [v.OPERATORS, 'operator'],
    [v.PUNCTUATION.filter((p) => p !== '@'), 'punctuation'],
  ];
  for (const [words, type] of expected) {
    assert.ok(words.length > 0);
    for (const word of words) assert.equal(typeOf(word, 'a ', ' b'), type, `\`${word}\``);
  }
  for (const op of v.OPERATORS) assert.equal(typeOf(op, 'a', 'b'), 'operator', `\`a${op}b\`: the longest operator`);
  for (const name of v.ATTRIBUTES) assert.equal(typeOf(`@${name}`, '', '(0.4) in float3 n;'), 'meta', `@${name}`);
  assert.equal(typeOf('@', '', 'keys in float k;'), 'punctuation', 'not an attribute of the language');
  assert.equal(typeOf('float3x', 'uniform ', ' v;'), 'variableName');
  assert.equal(typeOf('lumière', 'float ', ' = 1.0;'), 'variableName', 'a Unicode name is one name');
  assert.equal(typeOf('shade', 'x = ', '(n);'), 'variableName.function');
});

test('numbers and comments', () => {
  for (const n of ['1.5', '1.', '.5', '1e3', '2.5e-2', '1f', '0x2A', '0x2Au', '42', '42u', '42i']) {
    assert.equal(typeOf(n, 'x = -', ';'), 'number', n);
  }
  assert.deepEqual(tokenize('1.5u'), [['1.5', 'number'], ['u', 'variableName']], 'as the lexer reads it');
  const tokens = tokenize('in float x; // in\n/* in\n in */ uniform');
  assert.deepEqual(tokens, [
    ['in', 'definitionKeyword'],
    ['float', 'typeName'],
    ['x', 'variableName'],
    [';', 'punctuation'],
    ['// in', 'comment'],
    ['/*', 'comment'],
    [' in', 'comment'],
    [' in */', 'comment'],
    ['uniform', 'definitionKeyword'],
  ]);
});

/** The words of a TextMate pattern `\b(?:a|b|c)\b`. */
function words(pattern) {
  const inner = /^\\b\(\?:(.*)\)\\b$/.exec(pattern);
  assert.ok(inner, `a word pattern: ${pattern}`);
  return inner[1].split('|').sort();
}

test('the playground and the TextMate grammar have the same words', () => {
  const v = mode.vocabulary;
  const grammar = JSON.parse(readFileSync(join(REPO, 'editors', 'vscode', 'syntaxes', 'mrsl.tmLanguage.json'), 'utf8'));
  const patterns = (key) => grammar.repository[key].patterns;
  const keywords = patterns('keywords').flatMap((p) => words(p.match));
  const playgroundKeywords = [...v.DECLARATION_KEYWORDS, ...v.RATE_KEYWORDS, ...v.CONTROL_KEYWORDS, ...v.BOOLEANS];
  assert.deepEqual(keywords.sort(), [...playgroundKeywords].sort());
  assert.deepEqual(patterns('types').flatMap((p) => words(p.match)), [...v.TYPES].sort());
  assert.deepEqual(patterns('builtins').flatMap((p) => words(p.match)).sort(), [...v.BUILTINS].sort());
  const attributes = /\\s\*\((.*)\)$/.exec(patterns('attributes')[0].match)[1];
  assert.deepEqual(words(attributes), [...v.ATTRIBUTES].sort());
  assert.deepEqual(patterns('numbers').map((p) => p.match), [...v.NUMBER_PATTERNS]);
});
