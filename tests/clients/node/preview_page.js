#!/usr/bin/env node
// The html output's page in Debian's chromium (headless, software GL), driven by playwright-core:
//   preview_page.js shot PAGE.html OUT.png SECONDS [SECONDS...]
//       the page's 3D view at each time (page.html#t=SECONDS, once the title says "ready"; SECONDS
//       "largest": the frame of largest displacement), side by side in one PNG
//       (scripts/render-preview makes docs/demo.png so)
//   preview_page.js gallery OUT.png COLUMNS LABEL PAGE.html SECONDS [LABEL PAGE.html SECONDS...]
//       each page's view at rest (t = 0) and at SECONDS side by side under its LABEL, the pairs
//       in rows of COLUMNS (scripts/species-gallery makes docs/species.png so)
//   preview_page.js check PAGE.html --bark R,G,B --leaf R,G,B [--min-leaf-share F] [--trees N]
//       fails unless the view at the first and last third of the bake is not blank, the two
//       differ (the tree moves), bark and leaf pixels have the given sRGB colours (0..1) within
//       shading, leaves are at least F of the tree's pixels, and (--trees) the page holds N trees,
//       each drawn on its own (page.html#t=SECONDS&tree=K) and apart from the others on screen.
//   preview_page.js leaves PAGE.html --bark R,G,B --leaf R,G,B --min-leaf-share F
//       the view at the middle of the bake only: leaves at least F of the trees' pixels (a
//       forest seen whole, where leaves are a few pixels each).
//   preview_page.js arrow PAGE.html
//       the wind arrow alone (no tree shown) at the windiest frame, in a square, a tall and a
//       wide window: drawn, and clear of the view's edges (wholly inside it).
//   preview_page.js captions PAGE.html
//       in a wide and a narrow window: each plot's title and legend entries drawn, none over another.
// CHROMIUM names the browser (default /usr/bin/chromium).
'use strict';
const path = require('path');
const { chromium } = require('playwright-core');

// Browser windows: the checks' (the view 960 x 558), the pictures' (a tall view, 600 x 620) and
// the gallery's (a smaller tall view).
const kCheckSize = { width: 960, height: 900 };
const kShotSize = { width: 600, height: 1000 };
const kGallerySize = { width: 340, height: 640 };
// The wind arrow's windows: the checks', a tall and a wide one; the captions': the checks' and
// one where a plot is at its narrowest (300 px).
const kArrowSizes = [kCheckSize, kShotSize, { width: 1600, height: 700 }];
const kCaptionSizes = [kCheckSize, { width: 360, height: 900 }];

async function openBrowser() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

// The last page's tab at its window size, kept open: the page follows its address, so a view
// after the first sets a new #t= (the viewer's hashchange) instead of loading the page again.
// Another page or size closes it (a gallery of pages holds one at a time).
const tabs = new Map();

// The page at time t => PNG bytes of its 3D view, and what the page says about itself.
async function viewAt(browser, page, t, viewport = kCheckSize, more = '') {
  const hash = `#t=${t}${more}`;
  const key = `${path.resolve(page)} ${viewport.width}x${viewport.height}`;
  let open = tabs.get(key);
  if (!open) {
    for (const other of tabs.values()) await other.tab.close();
    tabs.clear();
    open = { tab: await browser.newPage({ viewport }), errors: [], hash };
    open.tab.on('pageerror', (e) => open.errors.push(String(e)));
    tabs.set(key, open);
    await open.tab.goto(`file://${path.resolve(page)}${hash}`);
  } else if (open.hash !== hash) {
    open.hash = hash;
    await open.tab.evaluate((h) => { document.title = 'moving'; window.location.hash = h; }, hash);
  }
  const { tab, errors } = open;
  try {
    await tab.waitForFunction(() => document.title === 'ready', null, { timeout: 120000 });
  } catch (e) {
    throw new Error(`${page}${hash}: the title never became "ready" (${errors.join('; ') || e.message})`);
  }
  if (errors.length) throw new Error(`${page}${hash}: ${errors.join('; ')}`);
  const png = await tab.locator('#view canvas').screenshot();
  const info = await tab.evaluate(() => ({
    clock: document.getElementById('clock').textContent,
    note: document.getElementById('note').textContent,
    // the count alone: the whole bake through the protocol took seconds a view on the demo's page
    trees: JSON.parse(document.getElementById('treeanim-bake').textContent).trees.length,
    // each plot's caption: its title's box and its legend entries' (page pixels)
    plots: [...document.querySelectorAll('#plots .plot')].map((plot) => {
      const box = (e) => { const r = e.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; };
      const title = plot.querySelector('.title');
      return { id: plot.id, title: title && box(title), legend: [...plot.querySelectorAll('.legend')].map(box) };
    }),
  }));
  return { png, info };
}

// The blank tab that decodes and draws images, opened once.
let scratch = null;
async function scratchTab(browser) {
  if (!scratch) scratch = await browser.newPage();
  return scratch;
}

// PNG images => their RGBA pixels, decoded by the browser itself.
async function pixels(browser, pngs) {
  const tab = await scratchTab(browser);
  const out = await tab.evaluate(async (sources) => Promise.all(sources.map(async (b64) => {
    const image = new Image();
    image.src = `data:image/png;base64,${b64}`;
    await image.decode();
    const canvas = new OffscreenCanvas(image.width, image.height);
    const g = canvas.getContext('2d');
    g.drawImage(image, 0, 0);
    // base64 crosses to Node in a fraction of the time a JSON array of every byte takes
    const bytes = g.getImageData(0, 0, image.width, image.height).data;
    let text = '';
    for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
    return { width: image.width, height: image.height, data: btoa(text) };
  })), pngs.map((p) => p.toString('base64')));
  return out.map((image) => ({ ...image, data: Buffer.from(image.data, 'base64') }));
}

// PNG images => one PNG of them side by side.
async function sideBySide(browser, pngs) {
  const tab = await scratchTab(browser);
  const b64 = await tab.evaluate(async (sources) => {
    const images = await Promise.all(sources.map(async (s) => {
      const image = new Image();
      image.src = `data:image/png;base64,${s}`;
      await image.decode();
      return image;
    }));
    const canvas = document.createElement('canvas');
    canvas.width = images.reduce((w, i) => w + i.width, 0);
    canvas.height = Math.max(...images.map((i) => i.height));
    const g = canvas.getContext('2d');
    let x = 0;
    for (const i of images) { g.drawImage(i, x, 0); x += i.width; }
    return canvas.toDataURL('image/png').split(',')[1];
  }, pngs.map((p) => p.toString('base64')));
  return Buffer.from(b64, 'base64');
}

// Labelled pairs of PNG images => one PNG: each pair side by side under its label, the pairs in
// rows of `columns`.
async function gallery(browser, cells, columns) {
  const tab = await scratchTab(browser);
  const b64 = await tab.evaluate(async ({ cells, columns }) => {
    const load = async (s) => {
      const image = new Image();
      image.src = `data:image/png;base64,${s}`;
      await image.decode();
      return image;
    };
    const pairs = await Promise.all(cells.map(async (c) => ({ label: c.label, images: await Promise.all(c.pngs.map(load)) })));
    const w = pairs[0].images[0].width, h = pairs[0].images[0].height, caption = 34;
    const canvas = document.createElement('canvas');
    canvas.width = Math.min(columns, pairs.length) * 2 * w;
    canvas.height = Math.ceil(pairs.length / columns) * (h + caption);
    const g = canvas.getContext('2d');
    g.fillStyle = '#fff';
    g.fillRect(0, 0, canvas.width, canvas.height);
    g.font = '20px sans-serif';
    g.textAlign = 'center';
    pairs.forEach((pair, k) => {
      const x = (k % columns) * 2 * w, y = Math.floor(k / columns) * (h + caption);
      g.fillStyle = '#222';
      g.fillText(pair.label, x + w, y + 24);
      pair.images.forEach((image, i) => g.drawImage(image, x + i * w, y + caption));
    });
    return canvas.toDataURL('image/png').split(',')[1];
  }, { cells: cells.map((c) => ({ label: c.label, pngs: c.pngs.map((p) => p.toString('base64')) })), columns });
  return Buffer.from(b64, 'base64');
}

// sRGB 0..255 => hue (degrees) and saturation (0..1) of HSV.
function hueSat(r, g, b) {
  const max = Math.max(r, g, b), min = Math.min(r, g, b), c = max - min;
  if (max === 0 || c === 0) return { hue: 0, sat: 0 };
  let hue;
  if (max === r) hue = ((g - b) / c) % 6;
  else if (max === g) hue = (b - r) / c + 2;
  else hue = (r - g) / c + 4;
  return { hue: (hue * 60 + 360) % 360, sat: c / max };
}

// Pixels whose hue is within 12 degrees of the colour's (shading scales brightness, not hue).
function countLike(image, rgb) {
  const want = hueSat(rgb[0] * 255, rgb[1] * 255, rgb[2] * 255);
  let n = 0;
  for (let i = 0; i < image.data.length; i += 4) {
    const got = hueSat(image.data[i], image.data[i + 1], image.data[i + 2]);
    const dh = Math.min(Math.abs(got.hue - want.hue), 360 - Math.abs(got.hue - want.hue));
    if (dh <= 12 && got.sat >= 0.5 * want.sat && image.data[i] + image.data[i + 1] + image.data[i + 2] > 15) ++n;
  }
  return n;
}

function parseColor(text, name) {
  const rgb = (text || '').split(',').map(Number);
  if (rgb.length !== 3 || rgb.some((v) => !(v >= 0 && v <= 1))) throw new Error(`--${name}: expected R,G,B in 0..1`);
  return rgb;
}

// Two images => how many pixels differ, and their centroid.
function difference(image, base) {
  let n = 0, x = 0, y = 0;
  for (let i = 0; i < image.data.length; i += 4) {
    const d = Math.abs(image.data[i] - base.data[i]) + Math.abs(image.data[i + 1] - base.data[i + 1]) +
              Math.abs(image.data[i + 2] - base.data[i + 2]);
    if (d <= 24) continue;
    ++n;
    x += (i / 4) % image.width;
    y += Math.floor(i / 4 / image.width);
  }
  return { n, x: n ? x / n : 0, y: n ? y / n : 0 };
}

// The page's bake (its JSON) without opening it in the browser.
function bakeOf(page) {
  const text = require('fs').readFileSync(page, 'utf8');
  const json = /<script id="treeanim-bake" type="application\/json">(.*?)<\/script>/s.exec(text);
  if (!json) throw new Error(`${page}: no <script id="treeanim-bake"> element`);
  return JSON.parse(json[1]);
}

// The view at the middle of the bake: leaves at least `minShare` of the leaf and bark pixels.
async function checkLeaves(browser, page, options) {
  const bark = parseColor(options.bark, 'bark'), leaf = parseColor(options.leaf, 'leaf');
  const times = bakeOf(page).plot.time;
  const t = times[Math.floor(times.length / 2)];
  const [image] = await pixels(browser, [(await viewAt(browser, page, t)).png]);
  const barkPixels = countLike(image, bark), leafPixels = countLike(image, leaf);
  const share = leafPixels / Math.max(1, leafPixels + barkPixels);
  console.log(`${page}: t=${t}: ${barkPixels} bark-coloured, ${leafPixels} leaf-coloured pixels ` +
              `(leaves ${(100 * share).toFixed(1)} % of the trees)`);
  const minShare = Number(options['min-leaf-share']);
  return share >= minShare ? []
    : [`leaves are ${(100 * share).toFixed(1)} % of the trees' pixels, below ${100 * minShare} %: foliage does not read`];
}

// The arrow alone (&tree=COUNT shows no tree) at the windiest sample, in each of kArrowSizes:
// its pixels (the arrow's blue) at least 2 pixels from every edge of the view.
async function checkArrow(browser, page) {
  const bake = bakeOf(page);
  const speeds = bake.plot.time.map((_, i) => Math.hypot(...bake.plot.wind.slice(3 * i, 3 * i + 3)));
  const t = bake.plot.time[speeds.indexOf(Math.max(...speeds))];
  const failures = [];
  for (const size of kArrowSizes) {
    const [image] = await pixels(browser, [(await viewAt(browser, page, t, size, `&tree=${bake.trees.length}`)).png]);
    const blue = hueSat(0x20, 0x60, 0xd0);
    let n = 0, x0 = Infinity, y0 = Infinity, x1 = -1, y1 = -1;
    for (let i = 0; i < image.data.length; i += 4) {
      const got = hueSat(image.data[i], image.data[i + 1], image.data[i + 2]);
      if (Math.abs(got.hue - blue.hue) > 12 || got.sat < 0.5 * blue.sat) continue;
      const x = (i / 4) % image.width, y = Math.floor(i / 4 / image.width);
      ++n; x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
    const where = `${size.width}x${size.height} window, t=${t}`;
    console.log(`${page}: ${where}: the arrow's ${n} pixels in x ${x0}..${x1}, y ${y0}..${y1} of ` +
                `${image.width}x${image.height}`);
    if (n < 20) failures.push(`${where}: no wind arrow (${n} pixels of its colour)`);
    else if (x0 < 2 || y0 < 2 || x1 > image.width - 3 || y1 > image.height - 3)
      failures.push(`${where}: the wind arrow reaches the view's edge (x ${x0}..${x1}, y ${y0}..${y1} ` +
                    `of ${image.width}x${image.height}): part of it is out of the view`);
  }
  return failures;
}

// In each of kCaptionSizes: every plot's title and legend entries, none over another.
async function checkCaptions(browser, page) {
  const t = bakeOf(page).plot.time[0];
  const failures = [];
  const apart = (a, b) => a.x + a.w <= b.x || b.x + b.w <= a.x || a.y + a.h <= b.y || b.y + b.h <= a.y;
  for (const size of kCaptionSizes) {
    const { plots } = (await viewAt(browser, page, t, size)).info;
    const where = `${size.width}x${size.height} window`;
    console.log(`${page}: ${where}: ` + plots.map((p) => `${p.id} title ${JSON.stringify(p.title)}, legend ` +
                                                          JSON.stringify(p.legend)).join('; '));
    if (plots.length !== 2) failures.push(`${where}: ${plots.length} captioned plots, expected 2`);
    for (const p of plots) {
      if (!p.title || !p.legend.length) failures.push(`${where}: plot ${p.id} lacks its title or its legend`);
      const boxes = [p.title, ...p.legend].filter(Boolean);
      for (let i = 0; i < boxes.length; ++i)
        for (let j = 0; j < i; ++j)
          if (!apart(boxes[i], boxes[j])) failures.push(`${where}: plot ${p.id}: ${j ? 'legend entries' : 'the title and a legend entry'} overlap`);
    }
  }
  return failures;
}

// Each of the page's trees alone at time t (&tree=K) against the view of none (&tree=COUNT:
// the grid and the wind arrow alone): drawn, and away from the others on screen.
async function checkTrees(browser, page, t, count, failures) {
  const views = [];
  for (let k = 0; k <= count; ++k) views.push((await viewAt(browser, page, t, kCheckSize, `&tree=${k}`)).png);
  const images = await pixels(browser, views);
  const none = images.pop();
  const total = none.width * none.height;
  const drawn = images.map((image) => difference(image, none));
  console.log(`${page}: each tree alone: ` +
              drawn.map((d, k) => `tree ${k} ${d.n} pixels around (${d.x.toFixed(0)}, ${d.y.toFixed(0)})`).join(', '));
  drawn.forEach((d, k) => {
    if (d.n < 0.001 * total) failures.push(`tree ${k} alone: ${d.n} of ${total} pixels differ from the view of no tree`);
    for (let j = 0; j < k; ++j) {
      const apart = Math.hypot(d.x - drawn[j].x, d.y - drawn[j].y);
      if (apart < 40) failures.push(`trees ${j} and ${k} are drawn at the same place (${apart.toFixed(1)} px apart)`);
    }
  });
}

// SECONDS of a command line => a time; "largest": the frame of the page's largest displacement.
function timeOf(page, text) {
  if (text !== 'largest') return text;
  const plot = bakeOf(page).plot;
  const k = plot.max_displacement.reduce((best, d, i) => (d > plot.max_displacement[best] ? i : best), 0);
  return plot.time[k];
}

async function check(browser, page, options) {
  const bark = parseColor(options.bark, 'bark'), leaf = parseColor(options.leaf, 'leaf');
  const times = bakeOf(page).plot.time;
  const t0 = times[Math.floor(times.length / 3)], t1 = times[Math.floor((2 * times.length) / 3)];
  const a = await viewAt(browser, page, t0), b = await viewAt(browser, page, t1);
  const [ia, ib] = await pixels(browser, [a.png, b.png]);
  const failures = [];
  const total = ia.width * ia.height;
  const background = ia.data.slice(0, 3);  // the top-left corner: sky
  let drawn = 0, changed = 0;
  for (let i = 0; i < ia.data.length; i += 4) {
    const d = Math.abs(ia.data[i] - background[0]) + Math.abs(ia.data[i + 1] - background[1]) +
              Math.abs(ia.data[i + 2] - background[2]);
    if (d > 24) ++drawn;
    if (Math.abs(ia.data[i] - ib.data[i]) + Math.abs(ia.data[i + 1] - ib.data[i + 1]) +
        Math.abs(ia.data[i + 2] - ib.data[i + 2]) > 24) ++changed;
  }
  const barkPixels = countLike(ia, bark), leafPixels = countLike(ia, leaf);
  const leafShare = leafPixels / Math.max(1, leafPixels + barkPixels);
  console.log(`${page}: t=${t0} "${a.info.clock}", t=${t1} "${b.info.clock}"; ${ia.width}x${ia.height} view, ` +
              `${drawn} pixels drawn, ${changed} changed between the two times, ${barkPixels} bark-coloured, ` +
              `${leafPixels} leaf-coloured (leaves ${(100 * leafShare).toFixed(1)} % of the tree)` +
              (a.info.note ? `; note: ${a.info.note}` : ''));
  if (drawn < 0.01 * total) failures.push(`blank view: ${drawn} of ${total} pixels differ from the sky`);
  if (changed < 0.001 * total) failures.push(`the tree does not move: ${changed} pixels changed between t=${t0} and t=${t1}`);
  if (barkPixels < 0.0005 * total) failures.push(`no bark of colour ${bark}: ${barkPixels} pixels`);
  if (leafPixels < 0.002 * total) failures.push(`no leaves of colour ${leaf}: ${leafPixels} pixels`);
  if (options['min-leaf-share'] && leafShare < Number(options['min-leaf-share']))
    failures.push(`leaves are ${(100 * leafShare).toFixed(1)} % of the tree's pixels, below ${100 * options['min-leaf-share']} %`);
  if (options['reduced'] && !a.info.note.startsWith('Reduced to fit'))
    failures.push(`the page says nothing about a reduction (note "${a.info.note}")`);
  if (options.trees && a.info.trees !== Number(options.trees))
    failures.push(`${a.info.trees} trees in the page, expected ${options.trees}`);
  if (options.trees) await checkTrees(browser, page, t0, Number(options.trees), failures);
  return failures;
}

async function main() {
  const [command, page, ...rest] = process.argv.slice(2);
  const browser = await openBrowser();
  try {
    if (command === 'shot') {
      const [out, ...times] = rest;
      const views = [];
      for (const t of times) views.push((await viewAt(browser, page, timeOf(page, t), kShotSize)).png);
      require('fs').writeFileSync(out, await sideBySide(browser, views));
      console.log(out);
      return 0;
    }
    if (command === 'gallery') {
      const [columns, ...triples] = rest;
      const cells = [];
      for (let i = 0; i + 2 < triples.length; i += 3) {
        const [label, file, t] = triples.slice(i, i + 3);
        const views = [];
        for (const time of [0, timeOf(file, t)]) views.push((await viewAt(browser, file, time, kGallerySize)).png);
        cells.push({ label, pngs: views });
      }
      require('fs').writeFileSync(page, await gallery(browser, cells, Number(columns)));
      console.log(page);
      return 0;
    }
    const checks = { check, leaves: checkLeaves, arrow: checkArrow, captions: checkCaptions };
    if (checks[command]) {
      const options = {};
      for (let i = 0; i < rest.length; i += 2) options[rest[i].replace(/^--/, '')] = rest[i + 1];
      const failures = await checks[command](browser, page, options);
      for (const f of failures) console.log(`FAIL: ${f}`);
      return failures.length ? 1 : 0;
    }
    console.error('usage: preview_page.js shot PAGE OUT.png SECONDS... | gallery OUT.png COLUMNS LABEL PAGE SECONDS...' +
                  ' | check PAGE --bark R,G,B --leaf R,G,B | leaves PAGE --bark R,G,B --leaf R,G,B --min-leaf-share F' +
                  ' | arrow PAGE | captions PAGE');
    return 2;
  } finally {
    await browser.close();
  }
}

main().then((code) => process.exit(code), (e) => { console.error(String(e.stack || e)); process.exit(1); });
