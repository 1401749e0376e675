// Validates WGSL files with Tint, Dawn's WGSL front end, on Dawn's null
// backend (no GPU needed): Tint parses and validates a module in full when
// it is created, as Chrome would. Usage: node validate.mjs DIR...
// Prints one line per refused module and a summary; exits 1 on any refusal.
import { create, globals } from 'webgpu';
import { readdirSync, readFileSync, statSync } from 'node:fs';
import { join } from 'node:path';

Object.assign(globalThis, globals);

function wgslFiles(dir) {
  return readdirSync(dir).flatMap((name) => {
    const path = join(dir, name);
    if (statSync(path).isDirectory()) return wgslFiles(path);
    return name.endsWith('.wgsl') ? [path] : [];
  }).sort();
}

const dirs = process.argv.slice(2);
if (dirs.length === 0) {
  console.error('usage: node validate.mjs DIR...');
  process.exit(2);
}
const gpu = create(['backend=null']);
let adapter = await gpu.requestAdapter();
if (!adapter) {
  console.error('tint: Dawn gave no adapter on its null backend');
  process.exit(2);
}
// The limits a page gets by default: the kernels must not need more.
let device = await adapter.requestDevice();
let accepted = 0;
const refused = [];
// Dawn keeps every module of a device alive; past about a thousand of them
// (fifteen kernels of each of 77 programs) the process aborted. A fresh
// device (from a fresh adapter: an adapter makes one device) every
// MODULES_PER_DEVICE modules releases the ones checked.
const MODULES_PER_DEVICE = 200;
let onDevice = 0;
for (const file of dirs.flatMap(wgslFiles)) {
  if (onDevice === MODULES_PER_DEVICE) {
    device.destroy();
    adapter = await gpu.requestAdapter();
    device = await adapter.requestDevice();
    onDevice = 0;
  }
  onDevice += 1;
  const code = readFileSync(file, 'utf8');
  device.pushErrorScope('validation');
  const module = device.createShaderModule({ code });
  const info = await module.getCompilationInfo();
  const scoped = await device.popErrorScope();
  const errors = info.messages.filter((m) => m.type === 'error');
  if (errors.length === 0 && !scoped) {
    accepted += 1;
    continue;
  }
  const first = errors[0];
  const where = first ? `${first.lineNum}:${first.linePos}: ${first.message}` : scoped.message;
  refused.push(`${file}:${where.split('\n')[0]}`);
}
for (const line of refused) console.log(`refused ${line}`);
console.log(`tint: ${accepted} accepted, ${refused.length} refused`);
device.destroy();
process.exit(refused.length === 0 ? 0 : 1);
