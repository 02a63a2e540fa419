// three.js's USD reader (USDAParser, USDLoader) against treeanim's .usda outputs
// (tests/usd_clients.cmake):
//   --bake BASE --points P.usda   every frame's points bit for bit equal to the HDF5 bake's float32
//   --bake BASE --skinned S.usda  the UsdSkel animation, evaluated with three's skinning, within
//                                 the error the layer claims (per frame RMS and largest)
//   --forest OUT                  OUT/forest.usda packed with its tree layers: every tree at the
//                                 place OUT/forest.json gives it
import fs from 'node:fs';
import path from 'node:path';
import { AnimationMixer, LoopOnce, Matrix4, SRGBColorSpace, Vector3 } from 'three';
import { USDAParser } from 'three/examples/jsm/loaders/usd/USDAParser.js';
import { USDLoader } from 'three/examples/jsm/loaders/USDLoader.js';
import { zipSync, strToU8 } from 'three/examples/jsm/libs/fflate.module.js';
import { readBake, expect, bitDifferences, option, timed } from './check_common.mjs';


function meshesOf(group) {
  const meshes = [];
  group.traverse((o) => { if (o.isMesh) meshes.push(o); });
  return meshes;
}

// The stage metadata every treeanim layer carries, from the parser's tree of the layer header
// (its specs keep no start and end time codes).
function checkStage(text, bake, file) {
  const root = new USDAParser().parseText(text)['#usda 1.0'];
  const number = (key) => Number(root[key]);
  expect(root.upAxis === '"Y"', `${file}: upAxis ${root.upAxis}`);
  expect(number('metersPerUnit') === 1, `${file}: metersPerUnit ${root.metersPerUnit}`);
  expect(number('timeCodesPerSecond') === bake.fps && number('framesPerSecond') === bake.fps,
    `${file}: timeCodesPerSecond ${root.timeCodesPerSecond}, framesPerSecond ${root.framesPerSecond}, fps ${bake.fps}`);
  expect(number('startTimeCode') === bake.frames[0] && number('endTimeCode') === bake.frames.at(-1),
    `${file}: time codes ${root.startTimeCode}..${root.endTimeCode}, frames ${bake.frames[0]}..${bake.frames.at(-1)}`);
  expect(root.defaultPrim === '"Tree"', `${file}: defaultPrim ${root.defaultPrim}`);
}

// Two materials bound by GeomSubsets: bark and leaves, in the scene's sRGB colours (within one
// 8-bit step: three reads the linear values back), the leaves over the bake's leaf triangles.
function checkMaterials(mesh, bake, file) {
  const materials = Array.isArray(mesh.material) ? mesh.material : [mesh.material];
  expect(materials.length === 2 && mesh.geometry.groups.length === 2,
    `${file}: ${materials.length} materials, ${mesh.geometry.groups.length} groups (expected bark and leaves)`);
  const srgb = (m) => { const c = {}; m.color.getRGB(c, SRGBColorSpace); return [c.r, c.g, c.b]; };
  const near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) <= 1 / 255);
  const colors = materials.map(srgb);
  console.log(`${file}: bark and leaf materials, sRGB ${colors.map((c) => c.map((x) => x.toFixed(3)).join(' ')).join(', ')}`);
  expect(colors.some((c) => near(c, bake.bark_color)) && colors.some((c) => near(c, bake.leaf_color)),
    `${file}: colours ${JSON.stringify(colors)}, scene bark ${bake.bark_color} leaf ${bake.leaf_color}`);
  const leaf = mesh.geometry.groups[materials.findIndex((c) => near(srgb(c), bake.leaf_color))];
  expect(leaf && leaf.count === 3 * bake.leaf_triangles, `${file}: leaf subset of ${leaf && leaf.count / 3} triangles, bake ${bake.leaf_triangles}`);
}

const bakeBase = option('--bake');
const bake = bakeBase ? readBake(bakeBase) : null;

const pointsFile = option('--points');
if (pointsFile) {
  const text = fs.readFileSync(pointsFile, 'utf8');
  const specs = timed(`${pointsFile}: USDAParser`, () => new USDAParser().parseData(text).specsByPath);
  checkStage(text, bake, pointsFile);
  const samples = specs['/Tree/Mesh.points'].fields.timeSamples;
  expect(samples.times.length === bake.frames.length, `${pointsFile}: ${samples.times.length} samples, bake ${bake.frames.length}`);
  for (let k = 0; k < bake.frames.length; ++k) {
    expect(samples.times[k] === bake.frames[k], `${pointsFile}: sample ${k} at ${samples.times[k]}, bake frame ${bake.frames[k]}`);
    const diff = bitDifferences(samples.values[k], bake.positions[k]);
    expect(samples.values[k].length === bake.positions[k].length && diff.count === 0,
      `${pointsFile}: frame ${bake.frames[k]}: ${diff.count} of ${bake.positions[k].length} floats differ from the bake (first at ${diff.first})`);
  }
  console.log(`${pointsFile}: ${bake.frames.length} frames x ${bake.vertices} vertices equal to the bake bit for bit`);
  const extent = specs['/Tree/Mesh.extent'].fields.timeSamples;
  expect(extent.times.length === bake.frames.length, `${pointsFile}: ${extent.times.length} extents`);
  const group = timed(`${pointsFile}: USDLoader`, () => new USDLoader().parse(text));
  const meshes = meshesOf(group);
  expect(meshes.length === 1, `${pointsFile}: ${meshes.length} meshes`);
  const geometry = meshes[0].geometry;
  const triangles = (geometry.index ? geometry.index.count : geometry.attributes.position.count) / 3;
  expect(triangles === bake.triangles, `${pointsFile}: ${triangles} triangles, bake ${bake.triangles}`);
  checkMaterials(meshes[0], bake, pointsFile);
}

const skinnedFile = option('--skinned');
if (skinnedFile) {
  const text = fs.readFileSync(skinnedFile, 'utf8');
  const specs = new USDAParser().parseData(text).specsByPath;
  checkStage(text, bake, skinnedFile);
  // The fit's claim, from the layer's customLayerData (three keeps no layer dictionaries).
  const claim = (key) => Number(text.match(new RegExp(`double ${key} = ([^\\n]+)`))[1]);
  const claimedFrames = JSON.parse(text.match(/double\[\] frame_rms_error_m = (\[[^\]]*\])/)[1]);
  const largest = claim('largest_error_m');
  const group = timed(`${skinnedFile}: USDLoader`, () => new USDLoader().parse(text));
  const meshes = meshesOf(group);
  expect(meshes.length === 1 && meshes[0].isSkinnedMesh, `${skinnedFile}: expected one skinned mesh`);
  const mesh = meshes[0];
  const joints = specs['/Tree/Skeleton.joints'].fields.default.length;
  expect(mesh.skeleton.bones.length === joints, `${skinnedFile}: ${mesh.skeleton.bones.length} bones, ${joints} joints`);
  expect(group.animations.length === 1, `${skinnedFile}: ${group.animations.length} animations`);
  checkMaterials(mesh, bake, skinnedFile);
  // three draws a subset mesh unindexed, triangles sorted by subset (bark, then leaves, each in
  // the subset's face order): corner c of its geometry is vertex vertexOf[c] of the layer.
  const triangles = specs['/Tree/Mesh.faceVertexIndices'].fields.default;
  const subsets = ['bark', 'leaves'].map((name) => specs[`/Tree/Mesh/${name}.indices`].fields.default);
  const vertexOf = [];
  for (const g of mesh.geometry.groups)
    for (const face of subsets[g.materialIndex]) vertexOf.push(triangles[3 * face], triangles[3 * face + 1], triangles[3 * face + 2]);
  const rest = mesh.geometry.attributes.position.array;
  expect(vertexOf.length === rest.length / 3 && vertexOf.every((v, c) =>
    [0, 1, 2].every((a) => Object.is(rest[3 * c + a], bake.rest[3 * v + a]))),
    `${skinnedFile}: three's corners do not map onto the layer's vertices by its subsets`);
  const cornerOf = new Map();
  vertexOf.forEach((v, c) => { if (!cornerOf.has(v)) cornerOf.set(v, c); });
  expect(cornerOf.size === bake.vertices, `${skinnedFile}: ${cornerOf.size} of ${bake.vertices} vertices drawn`);
  const mixer = new AnimationMixer(group);
  // Played once and held at the end: repeating, the last frame's time, a float32 key time
  // rounded below the double frame / fps, would wrap round to the first key.
  const action = mixer.clipAction(group.animations[0]);
  action.setLoop(LoopOnce);
  action.clampWhenFinished = true;
  action.play();
  const p = new Vector3();
  let worst = 0, worstFrame = 0;
  for (let k = 0; k < bake.frames.length; ++k) {
    mixer.setTime(bake.frames[k] / bake.fps);
    group.updateMatrixWorld(true);
    let squared = 0;
    for (const [v, c] of cornerOf) {
      mesh.getVertexPosition(c, p);
      const b = bake.positions[k];
      const e2 = (p.x - b[3 * v]) ** 2 + (p.y - b[3 * v + 1]) ** 2 + (p.z - b[3 * v + 2]) ** 2;
      squared += e2;
      if (Math.sqrt(e2) > worst) { worst = Math.sqrt(e2); worstFrame = bake.frames[k]; }
    }
    const rms = Math.sqrt(squared / bake.vertices);
    expect(Math.abs(rms - claimedFrames[k]) <= 2e-5,
      `${skinnedFile}: frame ${bake.frames[k]}: three's skinned mesh is ${rms} m RMS from the bake, the layer claims ${claimedFrames[k]} m`);
  }
  expect(worst <= largest + 2e-5, `${skinnedFile}: largest error ${worst} m (frame ${worstFrame}), the layer claims ${largest} m`);
  console.log(`${skinnedFile}: ${joints} joints; every frame's RMS error within 2e-5 m of the claim; largest ${worst.toExponential(3)} m <= ${largest.toExponential(3)} m`);
}

const forestDir = option('--forest');
if (forestDir) {
  // Packed as a USDZ (the stage first, then each tree's layer under its relative name), the form
  // in which three's loader resolves references.
  const manifest = JSON.parse(fs.readFileSync(path.join(forestDir, 'forest.json'), 'utf8'));
  const files = { 'forest.usda': new Uint8Array(fs.readFileSync(path.join(forestDir, 'forest.usda'))) };
  for (const tree of manifest.trees) {
    const layer = tree.outputs.find((o) => o.format === 'usd').files[0];
    files[layer] = new Uint8Array(fs.readFileSync(path.join(forestDir, layer)));
  }
  const group = timed(`${forestDir}/forest.usda: USDLoader`, () => new USDLoader().parse(zipSync(files, { level: 0 }).buffer));
  group.updateMatrixWorld(true);
  const byName = {};
  group.traverse((o) => { byName[o.name] = byName[o.name] || o; });
  for (const tree of manifest.trees) {
    const prim = byName[tree.id.replace(/[^A-Za-z0-9_]/g, '_').replace(/^([0-9])/, '_$1')];
    expect(prim, `forest: no object for tree ${tree.id}`);
    const expected = new Matrix4().fromArray(tree.matrix);  // column-major, as three's
    const got = prim.matrixWorld.elements;
    const far = expected.elements.findIndex((e, i) => Math.abs(e - got[i]) > 1e-9);
    expect(far < 0, `forest: tree ${tree.id} at ${got}, forest.json says ${expected.elements}`);
    expect(meshesOf(prim).length === 1, `forest: tree ${tree.id} holds ${meshesOf(prim).length} meshes`);
  }
  console.log(`${forestDir}/forest.usda: ${manifest.trees.length} trees, each at its forest.json matrix with its mesh`);
}
