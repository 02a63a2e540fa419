// TinyUSDZ's wasm module in Node: its Emscripten build was made for browsers and asserts that it
// is not in Node, so it is loaded looking like a browser page, given its wasm binary directly.
// Its package declares no "type": "module", so Node 18 would read its ES module syntax as
// CommonJS (newer Node guesses): a copy named .mjs is loaded instead, a module on every Node.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

export async function loadTinyUSDZ() {
  const require = createRequire(import.meta.url);
  const wasmBinary = fs.readFileSync(require.resolve('tinyusdz/tinyusdz.wasm'));
  const folder = fs.mkdtempSync(path.join(os.tmpdir(), 'tinyusdz-'));
  const asModule = path.join(folder, 'tinyusdz.mjs');
  fs.copyFileSync(require.resolve('tinyusdz/tinyusdz.js'), asModule);
  const hadWindow = 'window' in globalThis;
  process.type = 'renderer';
  if (!hadWindow) globalThis.window = globalThis;
  try {
    const { default: init } = await import(pathToFileURL(asModule).href);
    return await init({ wasmBinary });
  } finally {
    delete process.type;
    if (!hadWindow) delete globalThis.window;
    fs.rmSync(folder, { recursive: true, force: true });
  }
}
