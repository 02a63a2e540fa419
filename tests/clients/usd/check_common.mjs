// What the USD checks share: the reference frames export_frames.py wrote from an HDF5 bake
// (BASE.json, BASE.f32, BASE.rest.f32), the command line, timing and failing.
import fs from 'node:fs';

// The value after `name` on the command line, or undefined.
export function option(name) {
  const i = process.argv.indexOf(name);
  return i > 1 ? process.argv[i + 1] : undefined;
}

// Runs `run`, printing how long it took under `label`.
export function timed(label, run) {
  const start = performance.now();
  const result = run();
  console.log(`${label}: ${((performance.now() - start) / 1000).toFixed(2)} s`);
  return result;
}

export function readBake(base) {
  const info = JSON.parse(fs.readFileSync(base + '.json', 'utf8'));
  const bytes = fs.readFileSync(base + '.f32');
  const all = new Float32Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 4);
  const n = 3 * info.vertices;
  info.positions = info.frames.map((_, k) => all.subarray(k * n, (k + 1) * n));
  const rest = fs.readFileSync(base + '.rest.f32');
  info.rest = new Float32Array(rest.buffer, rest.byteOffset, rest.byteLength / 4);
  return info;
}

// Fails the check with `message` unless `ok`.
export function expect(ok, message) {
  if (!ok) {
    console.error('FAIL: ' + message);
    process.exit(1);
  }
}

// Indices k where two float arrays differ bit for bit (first few), with the count.
export function bitDifferences(a, b) {
  const fa = new Float32Array(a), fb = new Float32Array(b);
  let count = 0, first = -1;
  for (let i = 0; i < fa.length; ++i) {
    if (!Object.is(fa[i], fb[i])) {
      if (first < 0) first = i;
      ++count;
    }
  }
  return { count, first };
}
