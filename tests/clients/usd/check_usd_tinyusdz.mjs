// TinyUSDZ (its wasm build, a strict USD parser) against treeanim's .usda outputs
// (tests/usd_clients.cmake):
//   --bake BASE --points P.usda   the stage loads: one mesh, its rest points bit for bit the HDF5
//                                 bake's; the layer TinyUSDZ writes back keeps every time sample
//   --bake BASE --skinned S.usda  the same for the UsdSkel layer (its joints' keys written back)
//   --forest OUT                  OUT/forest.usda composed with its tree layers: one mesh per tree,
//                                 each tree at the place OUT/forest.json gives it
import fs from 'node:fs';
import path from 'node:path';
import { USDAParser } from 'three/examples/jsm/loaders/usd/USDAParser.js';
import { loadTinyUSDZ } from './tinyusdz_node.mjs';
import { readBake, expect, bitDifferences, option, timed } from './check_common.mjs';

const native = await loadTinyUSDZ();
const bakeBase = option('--bake');
const bake = bakeBase ? readBake(bakeBase) : null;

// Loads a layer as a stage => its mesh, after checking there is exactly one with the bake's rest points.
function checkStage(file) {
  const usd = new native.TinyUSDZLoaderNative();
  const ok = timed(`${file}: TinyUSDZ load`, () => usd.loadFromBinary(new Uint8Array(fs.readFileSync(file)), path.basename(file)));
  expect(ok, `${file}: TinyUSDZ refused it: ${usd.error()}`);
  expect(usd.numMeshes() === 1, `${file}: ${usd.numMeshes()} meshes`);
  const mesh = usd.getMesh(0);
  const diff = bitDifferences(mesh.points, bake.rest);
  expect(mesh.points.length === bake.rest.length && diff.count === 0,
    `${file}: ${mesh.absPath}: ${diff.count} of ${bake.rest.length} rest coordinates differ from the bake (first at ${diff.first})`);
  expect(mesh.faceVertexIndices.length === 3 * bake.triangles, `${file}: ${mesh.faceVertexIndices.length / 3} triangles`);
  console.log(`${file}: one mesh (${mesh.absPath}), ${bake.vertices} rest points equal to the bake bit for bit`);
  return mesh;
}

// The layer as TinyUSDZ writes it back, read again: the time samples of each attribute kept.
function checkWriteBack(file, attributes) {
  const layer = new native.TinyUSDZLoaderNative();
  expect(layer.loadAsLayerFromBinary(new Uint8Array(fs.readFileSync(file)), path.basename(file)),
    `${file}: TinyUSDZ refused it as a layer: ${layer.error()}`);
  const written = timed(`${file}: TinyUSDZ layerToString`, () => layer.layerToString());
  const original = new USDAParser().parseData(fs.readFileSync(file, 'utf8')).specsByPath;
  const back = new USDAParser().parseData(written).specsByPath;
  for (const attribute of attributes) {
    const a = original[attribute]?.fields.timeSamples, b = back[attribute]?.fields.timeSamples;
    expect(a && b, `${file}: ${attribute}: time samples missing (${a ? 'in the written-back layer' : 'in the layer'})`);
    expect(a.times.length === bake.frames.length && JSON.stringify(a.times) === JSON.stringify(b.times),
      `${file}: ${attribute}: ${b.times.length} samples written back of ${a.times.length}`);
    for (let k = 0; k < a.times.length; ++k) {
      const diff = bitDifferences(a.values[k], b.values[k]);
      expect(diff.count === 0 && a.values[k].length === b.values[k].length,
        `${file}: ${attribute} at ${a.times[k]}: ${diff.count} values differ after TinyUSDZ wrote the layer back`);
      if (attribute.endsWith('.points')) {
        const off = bitDifferences(b.values[k], bake.positions[k]);
        expect(off.count === 0, `${file}: points at ${b.times[k]}: ${off.count} values written back differ from the bake`);
      }
    }
    console.log(`${file}: ${attribute}: ${a.times.length} time samples written back unchanged`);
  }
}

const pointsFile = option('--points');
if (pointsFile) {
  checkStage(pointsFile);
  const withNormals = fs.readFileSync(pointsFile, 'utf8').includes('normal3f[] normals.timeSamples');
  checkWriteBack(pointsFile, ['/Tree/Mesh.points', '/Tree/Mesh.extent', ...(withNormals ? ['/Tree/Mesh.normals'] : [])]);
}

const skinnedFile = option('--skinned');
if (skinnedFile) {
  checkStage(skinnedFile);
  checkWriteBack(skinnedFile, ['/Tree/Skeleton/Wind.translations', '/Tree/Skeleton/Wind.rotations']);
}

const forestDir = option('--forest');
if (forestDir) {
  const manifest = JSON.parse(fs.readFileSync(path.join(forestDir, 'forest.json'), 'utf8'));
  const usd = new native.TinyUSDZLoaderNative();
  usd.setBaseWorkingPath(forestDir);
  for (const tree of manifest.trees) {
    const layer = tree.outputs.find((o) => o.format === 'usd').files[0];
    usd.setAsset('./' + layer, new Uint8Array(fs.readFileSync(path.join(forestDir, layer))));
  }
  const stage = new Uint8Array(fs.readFileSync(path.join(forestDir, 'forest.usda')));
  timed(`${forestDir}/forest.usda: TinyUSDZ load and compose`, () => {
    expect(usd.loadAsLayerFromBinary(stage, 'forest.usda'), `forest.usda: TinyUSDZ refused it: ${usd.error()}`);
    expect(usd.composeReferences(), `forest.usda: TinyUSDZ could not compose the references: ${usd.error()}`);
    expect(usd.layerToRenderScene(), `forest.usda: TinyUSDZ could not make a render scene: ${usd.error()}`);
  });
  expect(usd.numMeshes() === manifest.trees.length, `forest.usda: ${usd.numMeshes()} meshes for ${manifest.trees.length} trees`);
  const nodes = {};
  const visit = (node) => { nodes[node.absPath] = node; node.children.forEach(visit); };
  visit(usd.getDefaultRootNode());
  for (const tree of manifest.trees) {
    const name = tree.id.replace(/[^A-Za-z0-9_]/g, '_').replace(/^([0-9])/, '_$1');
    const node = nodes['/Forest/' + name];
    expect(node, `forest.usda: no node /Forest/${name} for tree ${tree.id} (nodes: ${Object.keys(nodes).join(', ')})`);
    const far = tree.matrix.findIndex((e, i) => Math.abs(e - node.globalMatrix[i]) > 1e-9);
    expect(far < 0, `forest.usda: tree ${tree.id} at ${node.globalMatrix}, forest.json says ${tree.matrix}`);
  }
  console.log(`${forestDir}/forest.usda: ${manifest.trees.length} trees composed, each at its forest.json matrix`);
}

// Exit explicitly: Node can stay alive after a wasm module has run (background tier-up work), and a
// check that has passed must not then hang until the test times out.
process.exit(0);
