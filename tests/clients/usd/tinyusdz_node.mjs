// TinyUSDZ's wasm module in Node: its Emscripten build was made for browsers and asserts that it
// is not in Node, so it is loaded looking like a browser page, given its wasm binary directly.
import fs from 'node:fs';
import { createRequire } from 'node:module';

export async function loadTinyUSDZ() {
  const require = createRequire(import.meta.url);
  const wasmBinary = fs.readFileSync(require.resolve('tinyusdz/tinyusdz.wasm'));
  const hadWindow = 'window' in globalThis;
  process.type = 'renderer';
  if (!hadWindow) globalThis.window = globalThis;
  try {
    const { default: init } = await import('tinyusdz/tinyusdz.js');
    return await init({ wasmBinary });
  } finally {
    delete process.type;
    if (!hadWindow) delete globalThis.window;
  }
}
