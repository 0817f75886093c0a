#!/usr/bin/env node
// Reads one .glb with glTF Transform (@gltf-transform/core, pinned in package.json), a glTF
// reader that honours the extensions it knows and skips unknown ones that are not required, and
// prints as JSON what a viewer would show: per scene, its root nodes; per node, its mesh's
// triangles, world bounds, and each primitive's material, triangles, lowest height and
// instance count (1 unless EXT_mesh_gpu_instancing gives more).
// Exit status: 0 when read, 1 when the reader fails, 2 on bad usage or a missing package.
let core;
try {
  core = await import('@gltf-transform/core');
} catch (e) {
  console.error('@gltf-transform/core is not installed: run `npm install` in tools/gltf-reader ' +
    '(scripts/setup.sh does it)');
  process.exit(2);
}
const file = process.argv[2];
if (!file) {
  console.error('usage: node read.mjs FILE.glb');
  process.exit(2);
}

const io = new core.NodeIO();
let document;
try {
  document = await io.read(file);
} catch (e) {
  console.error(`glTF Transform cannot read ${file}: ${e.message}`);
  process.exit(1);
}
const root = document.getRoot();

function primitiveInfo(primitive) {
  const position = primitive.getAttribute('POSITION');
  const indices = primitive.getIndices();
  const count = indices ? indices.getCount() : position.getCount();
  let lowest = Infinity;
  const p = [0, 0, 0];
  for (let i = 0; i < position.getCount(); i++) {
    position.getElement(i, p);
    lowest = Math.min(lowest, p[1]);
  }
  const material = primitive.getMaterial();
  return {
    material: material ? material.getName() : null,
    triangles: Math.floor(count / 3),
    lowest_y: lowest,
    texcoord0: primitive.getAttribute('TEXCOORD_0') !== null,
  };
}

function nodeInfo(node) {
  const mesh = node.getMesh();
  const primitives = mesh ? mesh.listPrimitives().map(primitiveInfo) : [];
  const instancing = node.getExtension('EXT_mesh_gpu_instancing');
  const bounds = core.getBounds(node);
  return {
    name: node.getName(),
    triangles: primitives.reduce((sum, p) => sum + p.triangles, 0),
    instances: instancing ? instancing.getAttribute('TRANSLATION').getCount() : 1,
    min: bounds.min,
    max: bounds.max,
    primitives,
    children: node.listChildren().map(nodeInfo),
  };
}

const scenes = root.listScenes().map((scene) => ({
  name: scene.getName(),
  nodes: scene.listChildren().map(nodeInfo),
}));
console.log(JSON.stringify({
  scenes,
  default_scene: root.getDefaultScene() ? root.listScenes().indexOf(root.getDefaultScene()) : null,
  extensions_used: root.listExtensionsUsed().map((e) => e.extensionName),
}, null, 1));
