// Starts mrsl's language server, `mrslc lsp`, over stdio for .mrsl files.
// Highlighting needs none of this (the grammar is static); the server adds
// diagnostics, hover and the rest. The `mrslc` run is the setting
// `mrsl.server.path`, or `mrslc` from PATH.
const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');

let client;

async function start() {
  const configured = vscode.workspace.getConfiguration('mrsl').get('server.path');
  const command = configured && configured.trim() !== '' ? configured : 'mrslc';
  const server = { command, args: ['lsp'] };
  client = new LanguageClient('mrsl', 'mrsl language server', { run: server, debug: server }, {
    documentSelector: [{ language: 'mrsl' }],
  });
  try {
    await client.start();
  } catch (error) {
    // Without a server the grammar still colours; say why the rest is missing.
    client = undefined;
    vscode.window.showWarningMessage(`mrsl: could not start \`${command} lsp\` (${error.message ?? error}); set mrsl.server.path.`);
  }
}

async function stop() {
  const running = client;
  client = undefined;
  if (running) await running.stop();
}

async function activate(context) {
  context.subscriptions.push(
    vscode.workspace.onDidChangeConfiguration(async (event) => {
      if (event.affectsConfiguration('mrsl.server.path')) {
        await stop();
        await start();
      }
    }),
  );
  await start();
}

function deactivate() {
  return stop();
}

module.exports = { activate, deactivate };
