// The html output's viewer (docs/outputs.md "Preview page"): reads the bake embedded in the
// page (<script id="treeanim-bake" type="application/json">, written by src/formats/html_sink.cpp)
// and plays it with three.js. Bundled by esbuild at build time; the page needs no network.
// page.html#t=SECONDS shows that time, stops, and sets document.title to "ready" once drawn;
// &tree=K shows the K-th tree alone (from 0; none past the last), framed as the whole page.
// The page follows its address: a new #t= or &tree= is shown without loading it again.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const bake = JSON.parse(document.getElementById('treeanim-bake').textContent);

// base64 => the bytes as a typed array of `Type` (the page's arrays are little-endian).
function decode(text, Type) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return new Type(bytes.buffer);
}

const samples = bake.plot.time.length;  // every written frame has a sample in the plots
const times = bake.plot.time;
const duration = samples > 1 ? times[samples - 1] - times[0] : 0;

// --- page layout ---
const style = document.createElement('style');
style.textContent = `
  body { margin: 0; font: 13px system-ui, sans-serif; background: #f4f5f2; color: #222; }
  #view { position: relative; width: 100%; height: 62vh; min-height: 320px; }
  #view canvas { display: block; }
  #bar { display: flex; flex-wrap: wrap; gap: 6px 10px; align-items: center; padding: 6px 10px; background: #e6e8e3; }
  #bar input[type=range] { flex: 1 1 160px; min-width: 0; }
  #clock { font-variant-numeric: tabular-nums; min-width: 13em; }
  #note { padding: 4px 10px; color: #8a4b00; }
  #plots { display: flex; flex-wrap: wrap; gap: 8px; padding: 8px 10px; }
  .plot { flex: 1 1 420px; min-width: 300px; margin: 0; background: #fff; border: 1px solid #ccd; }
  .plot figcaption { display: flex; flex-wrap: wrap; gap: 2px 16px; padding: 5px 10px 0 48px; font-size: 11px; color: #334; }
  .plot .legend::before { content: ''; display: inline-block; width: 14px; margin-right: 4px;
                          border-top: 2px solid currentColor; vertical-align: middle; }
  .plot canvas { display: block; width: 100%; height: 150px; }
  #title { position: absolute; left: 10px; top: 8px; color: #334; text-shadow: 0 0 3px #fff; }`;
document.head.appendChild(style);
const app = document.createElement('div');  // before the data, which stays in the page
app.innerHTML = `
  <div id="view"><div id="title"></div></div>
  <div id="bar">
    <button id="play">Pause</button>
    <label>speed <select id="speed">
      <option value="0.1">0.1×</option><option value="0.25">0.25×</option><option value="0.5">0.5×</option>
      <option value="1" selected>1×</option><option value="2">2×</option></select></label>
    <input id="scrub" type="range" min="0" max="${Math.max(samples - 1, 0)}" step="1" value="0">
    <span id="clock"></span>
  </div>
  <div id="note"></div>
  <div id="plots">
    <figure class="plot" id="windplot"><figcaption></figcaption><canvas></canvas></figure>
    <figure class="plot" id="dispplot"><figcaption></figcaption><canvas></canvas></figure>
  </div>`;
document.body.prepend(app);
document.getElementById('title').textContent = bake.title;
document.getElementById('note').textContent = bake.reduced;

// --- scene ---
const view = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xdfe8ef);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8c8c8c, 2.2));  // grey ground: shading keeps the hues
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(0.4, 1, 0.7);
scene.add(sun);

const srgb = (rgb) => new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace);
// A blade a few pixels long, or seen edge-on, falls between pixels, and a forest seen whole
// reads as bare twigs: every leaf under three dots long on screen is also drawn as a round
// dot of the leaf colour at its centre (dotPx, the drawing buffer's pixels; the uniforms the
// dots of every tree share).
const dotUniforms = { halfHeight: { value: 1 }, dotPx: { value: 1 } };
const leafDots = new THREE.ShaderMaterial({
  uniforms: { color: { value: new THREE.Color() }, ...dotUniforms },
  vertexShader: `
    attribute float leafSize;
    uniform float halfHeight, dotPx;
    void main() {
      vec4 at = modelViewMatrix * vec4(position, 1.0);
      gl_Position = projectionMatrix * at;
      gl_PointSize = dotPx;
      // a point of size 0 may still be drawn as one pixel: a leaf large enough is moved off screen
      if (leafSize * projectionMatrix[1][1] * halfHeight / -at.z >= 3.0 * dotPx) gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    }`,
  fragmentShader: `
    uniform vec3 color;
    void main() {
      if (length(gl_PointCoord - 0.5) > 0.5) discard;
      gl_FragColor = vec4(color, 1.0);
      #include <colorspace_fragment>
    }`,
});
const kLeafDotCssPx = 3;
// A tree's colours (its own, as a forest of several species has them, else the page's) => its
// bark and leaf materials and its leaf dots', one set per colour pair.
const materialSets = new Map();
function materialsOf(colors) {
  const key = JSON.stringify(colors);
  if (!materialSets.has(key)) {
    const leaf = new THREE.MeshLambertMaterial({ color: srgb(colors.leaf), side: THREE.DoubleSide });
    const dots = leafDots.clone();
    dots.uniforms = { color: { value: leaf.color }, ...dotUniforms };
    materialSets.set(key, { mesh: [new THREE.MeshLambertMaterial({ color: srgb(colors.bark) }), leaf], dots });
  }
  return materialSets.get(key);
}

// Triangle indices from `first` on => their vertices, one array per connected piece (a leaf).
function connectedPieces(index, first) {
  const parent = new Map();
  const root = (v) => {
    while (parent.get(v) !== v) v = parent.get(v);
    return v;
  };
  for (let i = first; i < index.length; ++i) parent.set(index[i], index[i]);
  for (let i = first; i < index.length; i += 3) {
    const a = root(index[i]);
    parent.set(root(index[i + 1]), a);
    parent.set(root(index[i + 2]), a);
  }
  const pieces = new Map();
  for (const v of parent.keys()) {
    const r = root(v);
    if (!pieces.has(r)) pieces.set(r, []);
    pieces.get(r).push(v);
  }
  return [...pieces.values()];
}

// Vertices of each leaf => their centres in `out` (x y z a leaf), from positions `p`.
function leafCentres(leaves, p, out) {
  leaves.forEach((leaf, k) => {
    let x = 0, y = 0, z = 0;
    for (const v of leaf) { x += p[3 * v]; y += p[3 * v + 1]; z += p[3 * v + 2]; }
    out[3 * k] = x / leaf.length; out[3 * k + 1] = y / leaf.length; out[3 * k + 2] = z / leaf.length;
  });
}

// A tree's leaves as dots (`material`, its leafDots) at their centres, in the tree's mesh.
function makeLeafDots(mesh, rest, barkIndices, material) {
  const leaves = connectedPieces(mesh.geometry.index.array, barkIndices);
  const centres = new THREE.BufferAttribute(new Float32Array(3 * leaves.length), 3);
  centres.setUsage(THREE.DynamicDrawUsage);
  leafCentres(leaves, rest, centres.array);
  const sizes = leaves.map((leaf, k) => 2 * Math.max(...leaf.map((v) => Math.hypot(
    rest[3 * v] - centres.array[3 * k], rest[3 * v + 1] - centres.array[3 * k + 1], rest[3 * v + 2] - centres.array[3 * k + 2]))));
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', centres);
  geometry.setAttribute('leafSize', new THREE.BufferAttribute(new Float32Array(sizes), 1));
  const dots = new THREE.Points(geometry, material);
  dots.frustumCulled = false;  // the leaves move past the rest pose's bounds
  mesh.add(dots);  // placed, and shown alone (&tree=K), with its tree
  return { leaves, centres };
}

// One tree: its mesh, placed as the bake places it, and its frames.
function makeTree(tree) {
  const rest = decode(tree.rest, Float32Array);
  const geometry = new THREE.BufferGeometry();
  const positions = new THREE.BufferAttribute(rest.slice(), 3);
  positions.setUsage(THREE.DynamicDrawUsage);
  geometry.setAttribute('position', positions);
  geometry.setIndex(new THREE.BufferAttribute(decode(tree.triangles, Uint32Array), 1));
  const barkIndices = 3 * tree.bark_triangles;
  geometry.addGroup(0, barkIndices, 0);
  geometry.addGroup(barkIndices, geometry.index.count - barkIndices, 1);
  geometry.computeVertexNormals();
  const own = materialsOf(tree.colors || bake.colors);
  const mesh = new THREE.Mesh(geometry, own.mesh);
  mesh.position.fromArray(tree.position);
  mesh.rotation.y = THREE.MathUtils.degToRad(tree.rotation);
  scene.add(mesh);
  const dots = makeLeafDots(mesh, rest, barkIndices, own.dots);
  const data = tree.frames.encoding === 'int16' ? decode(tree.frames.data, Int16Array)
                                                 : decode(tree.frames.data, Float32Array);
  const quantized = tree.frames.encoding === 'int16';
  return { rest, mesh, positions, dots, data, sample: tree.frames.sample, quantized,
           step: quantized ? decode(tree.frames.step, Float32Array) : null };
}
const trees = bake.trees.map(makeTree);

// Sample time t => the tree's positions, linear between the two kept frames around it.
function pose(tree, t) {
  const kept = tree.sample;
  let hi = kept.findIndex((s) => times[s] >= t);
  if (hi < 0) hi = kept.length - 1;
  const lo = Math.max(hi - 1, 0);
  const span = times[kept[hi]] - times[kept[lo]];
  const w = span > 0 ? Math.min(Math.max((t - times[kept[lo]]) / span, 0), 1) : 1;
  const n = tree.rest.length, out = tree.positions.array, d = tree.data;
  const a = lo * n, b = hi * n;
  for (let i = 0; i < n; ++i) {
    const pa = d[a + i], pb = d[b + i];
    const v = pa + (pb - pa) * w;
    out[i] = tree.quantized ? tree.rest[i] + v * tree.step[(i / 3) | 0] : v;
  }
  tree.positions.needsUpdate = true;
  leafCentres(tree.dots.leaves, out, tree.dots.centres.array);
  tree.dots.centres.needsUpdate = true;
  tree.mesh.geometry.computeVertexNormals();
}

// The box of every tree at rest.
const box = new THREE.Box3();
for (const tree of trees) {
  tree.mesh.geometry.computeBoundingBox();
  tree.mesh.updateMatrixWorld();
  box.union(tree.mesh.geometry.boundingBox.clone().applyMatrix4(tree.mesh.matrixWorld));
}
const size = box.getSize(new THREE.Vector3());
const center = box.getCenter(new THREE.Vector3());
const radius = Math.max(size.length() / 2, 0.1);
const camera = new THREE.PerspectiveCamera(35, 1, radius / 100, radius * 100);
const controls = new OrbitControls(camera, renderer.domElement);

// Ground grid: metre lines over the trees' footprint and two metres around it.
const extent = Math.ceil(Math.max(size.x, size.z) / 2 + 2);
const grid = new THREE.GridHelper(2 * extent, 2 * extent, 0x7d8a7a, 0xb4bdb1);
grid.position.set(Math.round(center.x), box.min.y, Math.round(center.z));
scene.add(grid);

// Wind arrow: the air velocity at the probe point, from upwind, 1 m/s = 4 % of the trees' height
// (not of a forest's width, which would draw it longer than the forest), and the fastest air
// of the bake at most 60 % of it: a storm's arrow four heights long took the view from the tree.
const probe = new THREE.Vector3().fromArray(bake.wind_probe);
const arrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), probe, 1, 0x2060d0);
scene.add(arrow);
const windSpeed = times.map((_, i) => Math.hypot(...bake.plot.wind.slice(3 * i, 3 * i + 3)));  // m/s, also plotted
const fastest = windSpeed.reduce((a, b) => Math.max(a, b), 0);
const arrowScale = Math.min(0.04, fastest > 0 ? 0.6 / fastest : 0.04) * size.y;
// The arrow at a sample: its tail, direction, length, and its head's length and width; none in still air.
function arrowAt(sample) {
  const w = new THREE.Vector3().fromArray(bake.plot.wind, 3 * sample);
  const speed = w.length();
  if (speed <= 1e-3) return null;
  const length = speed * arrowScale;
  const dir = w.clone().divideScalar(speed);
  const tail = probe.clone().addScaledVector(dir, -length - 0.5 * Math.max(size.x, size.z));
  return { tail, dir, length, head: Math.min(0.3 * length, 0.1 * radius), width: Math.min(0.15 * length, 0.05 * radius) };
}
function placeArrow(sample) {
  const a = arrowAt(sample);
  arrow.visible = a !== null;
  if (!a) return;
  arrow.position.copy(a.tail);
  arrow.setDirection(a.dir);
  arrow.setLength(a.length, a.head, a.width);
}

// Framing: the trees and the arrow at every sample (a forest's reaches well past the trees),
// from the front and a little above, the nearest to fill nine tenths of the view either way.
const framedBox = box.clone();
for (let i = 0; i < samples; ++i) {
  const a = arrowAt(i);
  if (!a) continue;
  const ends = new THREE.Box3().setFromPoints([a.tail, a.tail.clone().addScaledVector(a.dir, a.length)]);
  framedBox.union(ends.expandByScalar(a.width / 2));
}
const aim = framedBox.getCenter(new THREE.Vector3());
controls.target.copy(aim);
const viewDirection = new THREE.Vector3(0, 0.12, 1).normalize();
function frame() {
  const halfHeight = 0.9 * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2));
  const up = new THREE.Vector3(0, 1, 0).projectOnPlane(viewDirection).normalize();
  const right = new THREE.Vector3().crossVectors(up, viewDirection);
  // each corner of the box inside the view: the camera at least this far from the centre
  let reach = 0;
  for (let k = 0; k < 8; ++k) {
    const corner = new THREE.Vector3(k & 1 ? framedBox.max.x : framedBox.min.x, k & 2 ? framedBox.max.y : framedBox.min.y,
                                     k & 4 ? framedBox.max.z : framedBox.min.z).sub(aim);
    const toward = corner.dot(viewDirection);
    reach = Math.max(reach, toward + Math.abs(corner.dot(up)) / halfHeight,
                     toward + Math.abs(corner.dot(right)) / (halfHeight * camera.aspect));
  }
  camera.position.copy(aim).addScaledVector(viewDirection, reach);
}

// --- plots ---
const plotStyles = { grid: '#e3e6ea', axis: '#667', text: '#334', cursor: '#d03030' };
// A plot's title and legend: page text in its caption, which wraps the legend below the title
// rather than over it where the plot is narrow.
function caption(figure, title, unit, series) {
  const text = figure.querySelector('figcaption');
  const name = document.createElement('span');
  name.className = 'title';
  name.textContent = `${title} (${unit})`;
  text.append(name);
  for (const s of series) {
    const key = document.createElement('span');
    key.className = 'legend';
    key.style.color = s.color;
    key.textContent = s.name;
    text.append(key);
  }
}
// The step of about `count` ticks over `span`: 1, 2 or 5 times a power of ten, so that the
// ticks fall on round values.
function tickStep(span, count) {
  const rough = span / count, power = 10 ** Math.floor(Math.log10(rough));
  return [1, 2, 5, 10].find((m) => m * power >= rough) * power;
}
// A tick's label: as many decimals as its step has, no more (0.25 reads 0.25, 10 reads 10).
function tickLabel(value, step) {
  return value.toFixed(Math.max(0, -Math.floor(Math.log10(step) + 1e-9)));
}
function drawPlot(canvas, series, cursorTime) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  canvas.width = w * dpr;
  canvas.height = h * dpr;
  const g = canvas.getContext('2d');
  g.scale(dpr, dpr);
  const left = 48, right = 10, top = 10, bottom = 24;
  let ymax = 0;
  for (const s of series) for (const v of s.values) ymax = Math.max(ymax, v);
  // The axis ends on the first round tick 5 % or more above the largest value.
  const top5 = ymax > 0 ? 1.05 * ymax : 1, ystep = tickStep(top5, 4);
  ymax = Math.ceil(top5 / ystep - 1e-9) * ystep;
  const t0 = times[0], t1 = samples > 1 ? times[samples - 1] : t0 + 1;
  const x = (t) => left + ((t - t0) / (t1 - t0)) * (w - left - right);
  const y = (v) => h - bottom - (v / ymax) * (h - top - bottom);
  g.font = '11px system-ui, sans-serif';
  g.fillStyle = plotStyles.text;
  g.strokeStyle = plotStyles.grid;
  for (let k = 0; k * ystep <= ymax * (1 + 1e-9); ++k) {
    const v = k * ystep;
    g.beginPath(); g.moveTo(left, y(v)); g.lineTo(w - right, y(v)); g.stroke();
    g.fillText(tickLabel(v, ystep), 4, y(v) + 4);
  }
  // Time ticks on round times inside the bake's span (its last time is rarely one).
  const tstep = tickStep(t1 - t0, 5);
  for (let k = Math.ceil(t0 / tstep - 1e-9); k * tstep <= t1 + 1e-9 * tstep; ++k) {
    const t = k * tstep;
    g.fillText(`${tickLabel(t, tstep)} s`, Math.min(x(t) - 12, w - 36), h - 8);
  }
  for (const s of series) {
    g.strokeStyle = s.color;
    g.lineWidth = 1.5;
    g.beginPath();
    s.values.forEach((v, i) => (i ? g.lineTo(x(times[i]), y(v)) : g.moveTo(x(times[i]), y(v))));
    g.stroke();
  }
  g.strokeStyle = plotStyles.cursor;
  g.lineWidth = 1;
  g.beginPath(); g.moveTo(x(cursorTime), top); g.lineTo(x(cursorTime), h - bottom); g.stroke();
}
const windTitle = trees.length > 1 ? 'wind speed at the first tree' : 'wind speed at the tree';
const windSeries = [{ name: 'speed', values: windSpeed, color: '#2060d0' }];
const dispSeries = [{ name: 'largest', values: bake.plot.max_displacement, color: '#c05a00' },
                    { name: 'RMS', values: bake.plot.rms_displacement, color: '#2a8a3a' }];
const windPlot = document.getElementById('windplot'), dispPlot = document.getElementById('dispplot');
caption(windPlot, windTitle, 'm/s', windSeries);
caption(dispPlot, 'displacement from rest', 'm', dispSeries);
function drawPlots(t) {
  drawPlot(windPlot.querySelector('canvas'), windSeries, t);
  drawPlot(dispPlot.querySelector('canvas'), dispSeries, t);
}

// --- playback ---
const scrub = document.getElementById('scrub');
const clock = document.getElementById('clock');
const playButton = document.getElementById('play');
const speedSelect = document.getElementById('speed');
let playing = true;
let time = times[0];
let shown = null;
let framed = false;  // the first size frames the camera; later ones keep the user's view

function nearestSample(t) {
  let best = 0;
  for (let i = 1; i < samples; ++i) if (Math.abs(times[i] - t) < Math.abs(times[best] - t)) best = i;
  return best;
}

function show(t) {
  time = t;
  const sample = nearestSample(t);
  if (shown !== t) {
    for (const tree of trees) pose(tree, t);
    placeArrow(sample);
    drawPlots(t);
    shown = t;
  }
  scrub.value = String(sample);
  clock.textContent = `frame ${bake.plot.frame[sample]} · t = ${t.toFixed(3)} s`;
}

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h);
  dotUniforms.halfHeight.value = renderer.getDrawingBufferSize(new THREE.Vector2()).y / 2;
  dotUniforms.dotPx.value = kLeafDotCssPx * renderer.getPixelRatio();
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  if (!framed) frame();
  framed = true;
  shown = null;
}
window.addEventListener('resize', resize);

playButton.addEventListener('click', () => {
  playing = !playing;
  playButton.textContent = playing ? 'Pause' : 'Play';
});
scrub.addEventListener('input', () => {
  playing = false;
  playButton.textContent = 'Play';
  show(times[Number(scrub.value)]);
});

let last = null;
function tick(now) {
  if (playing && last !== null && duration > 0) {
    const dt = ((now - last) / 1000) * Number(speedSelect.value);
    show(times[0] + ((time - times[0] + dt) % duration));
  }
  last = now;
  controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(tick);
}

// The address's #t=SECONDS: that time, stopped, and the title says "ready" once the frame is on
// the canvas; &tree=K: that tree alone. => whether it asked for a time.
const pageTitle = document.title;
function follow(hash) {
  const requested = /(?:^#|&)t=([0-9.eE+-]+)/.exec(hash);
  const alone = /(?:^#|&)tree=([0-9]+)/.exec(hash);
  trees.forEach((tree, k) => { tree.mesh.visible = !alone || k === Number(alone[1]); });
  if (!requested) return false;
  playing = false;
  playButton.textContent = 'Play';
  show(Math.min(Math.max(Number(requested[1]), times[0]), times[samples - 1]));
  renderer.render(scene, camera);
  requestAnimationFrame(() => { document.title = 'ready'; });
  return true;
}
resize();
if (!follow(window.location.hash)) show(times[0]);
window.addEventListener('hashchange', () => {
  document.title = pageTitle;
  follow(window.location.hash);
});
requestAnimationFrame(tick);
