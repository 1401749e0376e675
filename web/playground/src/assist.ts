// Hover and completion in the playground's editor, answered by the language
// server's own functions through `mrslc serve` (`POST /api/hover` and
// `/api/complete`, docs/serve.md): the same facts an editor running
// `mrslc lsp` shows, an effect's rate and cost among them.

import type { CompletionContext, CompletionResult } from '@codemirror/autocomplete';
import { EditorState, type Text } from '@codemirror/state';
import { hoverTooltip } from '@codemirror/view';
import * as api from './api.js';

/** A document offset as the language server counts it: 0-based line, UTF-16 column. */
function position(doc: Text, offset: number): api.Position {
  const line = doc.lineAt(offset);
  return { line: line.number - 1, character: offset - line.from };
}

function offset(doc: Text, at: api.Position): number {
  const line = doc.line(Math.min(at.line + 1, doc.lines));
  return Math.min(line.from + at.character, line.to);
}

/**
 * The hover's Markdown as DOM nodes: fenced code as `<pre>`, `code` spans as
 * `<code>`, the rest as text (built with nodes, never parsed as HTML).
 */
function markdown(text: string): HTMLElement {
  const root = document.createElement('div');
  root.className = 'mrsl-hover';
  let fence: HTMLElement | null = null;
  for (const line of text.split('\n')) {
    if (line.startsWith('```')) {
      if (fence) fence = null;
      else root.append((fence = document.createElement('pre')));
      continue;
    }
    if (fence) {
      fence.append(`${fence.textContent ? '\n' : ''}${line}`);
      continue;
    }
    const block = document.createElement('div');
    line.replace(/\*/g, '').split('`').forEach((part, i) => {
      if (i % 2 === 0) block.append(part);
      else block.append(Object.assign(document.createElement('code'), { textContent: part }));
    });
    root.append(block);
  }
  return root;
}

export const hover = hoverTooltip(async (view, pos) => {
  const doc = view.state.doc;
  const reply = await api.hover(doc.toString(), position(doc, pos)).catch(() => null);
  if (!reply) return null;
  return {
    pos: reply.range ? offset(doc, reply.range.start) : pos,
    end: reply.range ? offset(doc, reply.range.end) : pos,
    above: true,
    create: () => ({ dom: markdown(reply.contents.value) }),
  };
});

/** CodeMirror's completion types for the protocol's item kinds. */
const KINDS: Record<number, string> = { 3: 'function', 5: 'property', 6: 'variable', 7: 'type', 10: 'property', 14: 'keyword', 21: 'constant', 22: 'type', 25: 'type' };

async function complete(context: CompletionContext): Promise<CompletionResult | null> {
  const word = context.matchBefore(/[\p{L}\p{N}_]*/u);
  const afterAt = context.state.sliceDoc(Math.max(0, (word?.from ?? context.pos) - 1), word?.from ?? context.pos) === '@';
  if (!word || (word.from === word.to && !context.explicit && !afterAt)) return null;
  const doc = context.state.doc;
  const items = await api.complete(doc.toString(), position(doc, context.pos)).catch(() => []);
  const info = (item: api.CompletionItem) => (typeof item.documentation === 'object' ? item.documentation.value : item.documentation);
  return {
    from: word.from,
    options: items.map((item) => ({ label: item.label, detail: item.detail, type: KINDS[item.kind ?? 0] ?? 'text', info: info(item) })),
  };
}

/** The completion source, offered through the language data that `basicSetup`'s autocompletion reads. */
export const completion = EditorState.languageData.of(() => [{ autocomplete: complete }]);
