// The mrslc binary the tests run: $MRSLC when set (cargo's test of this
// suite, cli/tests/web.rs, passes the one it built), else built with cargo
// from this repository in the debug profile, as `cargo test` builds it.
import { execFileSync } from 'node:child_process';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const REPO = join(dirname(fileURLToPath(import.meta.url)), '..', '..', '..');

let binary;

/** Builds mrslc (a no-op when it is up to date) and returns its path. */
export function mrslcPath() {
  binary ??= process.env.MRSLC;
  if (binary) return binary;
  const out = execFileSync('cargo', ['build', '-q', '-p', 'mrslc', '--message-format=json'], {
    cwd: REPO,
    encoding: 'utf8',
    maxBuffer: 256 << 20,
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  for (const line of out.split('\n')) {
    if (!line.startsWith('{')) continue;
    const message = JSON.parse(line);
    if (message.reason === 'compiler-artifact' && message.target?.name === 'mrslc' && message.executable) binary = message.executable;
  }
  if (!binary) throw new Error('cargo built no mrslc executable');
  return binary;
}

/** Runs mrslc with `args` in the repository root; returns its standard output. */
export function mrslc(args, env = {}) {
  return execFileSync(mrslcPath(), args, {
    cwd: REPO,
    encoding: 'utf8',
    env: { ...process.env, ...env },
    maxBuffer: 64 << 20,
    stdio: ['ignore', 'pipe', 'pipe'],
  });
}
