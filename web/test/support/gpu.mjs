// A WebGPU device for the tests: Dawn (npm `webgpu`) on SwiftShader, the
// Vulkan driver Debian's chromium package ships. Under CI=true a missing
// adapter fails the tests; elsewhere they are skipped, visibly.
import { create, globals } from 'webgpu';
import { existsSync, mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

Object.assign(globalThis, globals);

/** SwiftShader's Vulkan ICD as Debian's chromium installs it. */
export const SWIFTSHADER_ICD = '/usr/lib/chromium/vk_swiftshader_icd.json';

let cached;
let instance;

/** `{ device, adapter, description }`, or `{ skip: reason }` where no adapter is found outside CI. */
export async function testDevice() {
  cached ??= open();
  return cached;
}

async function open() {
  if (!process.env.VK_ICD_FILENAMES && existsSync(SWIFTSHADER_ICD)) process.env.VK_ICD_FILENAMES = SWIFTSHADER_ICD;
  // Dawn's Vulkan loader complains without one; a private one is enough.
  process.env.XDG_RUNTIME_DIR ??= mkdtempSync(join(tmpdir(), 'mrsl-web-xdg-'));
  const gpu = create([]);
  // Kept for the process's life: Dawn's instance must outlive its devices,
  // and a collected instance takes them down (a crash at the next GPU call).
  instance = gpu;
  const adapter = await gpu.requestAdapter();
  if (!adapter) {
    const reason = `no WebGPU adapter (Dawn over ${process.env.VK_ICD_FILENAMES ?? 'the default Vulkan driver'}); install Debian's chromium for SwiftShader`;
    if (process.env.CI === 'true') throw new Error(reason);
    console.log(`SKIPPED: ${reason}`);
    return { skip: reason };
  }
  const features = ['timestamp-query'].filter((f) => adapter.features.has(f));
  const device = await adapter.requestDevice({ requiredFeatures: features });
  device.addEventListener?.('uncapturederror', (e) => console.error('uncaptured WebGPU error:', e.error?.message));
  const info = adapter.info ?? {};
  const description = [info.vendor, info.architecture, info.description].filter(Boolean).join(' ') || 'unknown adapter';
  console.log(`web tests: Dawn on ${description}`);
  return { device, adapter, description };
}

/**
 * Another adapter of the same instance, for a device with limits of its own
 * (a WebGPU adapter makes one device); call after `testDevice`.
 */
export async function freshAdapter() {
  return instance.requestAdapter();
}
