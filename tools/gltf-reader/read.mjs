#!/usr/bin/env node
// Reads one .glb with glTF Transform (@gltf-transform/core and /extensions, pinned in
// package.json), a glTF reader that honours the extensions it knows (here
// KHR_mesh_quantization, KHR_texture_transform and EXT_mesh_gpu_instancing: quantized
// attributes come back dequantized, instanced meshes with their instance transforms) and
// refuses files that require one it does not know. Prints as JSON what a viewer would show:
// per scene, its root nodes; per node (with its children), its mesh's triangles, its instance
// count (1 unless EXT_mesh_gpu_instancing gives more), the triangles it draws (mesh triangles
// times instances, children included), world bounds of everything it draws (every instance),
// and each primitive's material, triangles, lowest world height and texture coordinates.
// `levels` lists the same for the scene's tree and the coarser levels its MSFT_lod extension
// names (read from the JSON chunk: glTF Transform keeps the nodes but not that extension).
// Exit status: 0 when read, 1 when the reader fails, 2 on bad usage or a missing package.
import { readFileSync } from 'node:fs';

let core;
let extensions;
try {
  core = await import('@gltf-transform/core');
  extensions = await import('@gltf-transform/extensions');
} catch (e) {
  console.error('@gltf-transform/core and /extensions are not installed: run `npm install` in ' +
    'tools/gltf-reader (scripts/setup.sh does it)');
  process.exit(2);
}
const file = process.argv[2];
if (!file) {
  console.error('usage: node read.mjs FILE.glb');
  process.exit(2);
}

const io = new core.NodeIO().registerExtensions(extensions.ALL_EXTENSIONS);
let document;
try {
  document = await io.read(file);
} catch (e) {
  console.error(`glTF Transform cannot read ${file}: ${e.message}`);
  process.exit(1);
}
const root = document.getRoot();

// Column-major 4×4 matrix times point.
function transform(m, p) {
  return [0, 1, 2].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
}

// Quaternion (x, y, z, w) rotation of v.
function rotate(q, v) {
  const [x, y, z, w] = q;
  const t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])];
  return [
    v[0] + w * t[0] + (y * t[2] - z * t[1]),
    v[1] + w * t[1] + (z * t[0] - x * t[2]),
    v[2] + w * t[2] + (x * t[1] - y * t[0]),
  ];
}

// The instance transforms of a node: functions from mesh space to the node's space.
function instances(node) {
  const instancing = node.getExtension('EXT_mesh_gpu_instancing');
  if (!instancing) return [(p) => p];
  const t = instancing.getAttribute('TRANSLATION');
  const r = instancing.getAttribute('ROTATION');
  const s = instancing.getAttribute('SCALE');
  const count = [t, r, s].find((a) => a).getCount();
  const out = [];
  for (let i = 0; i < count; i++) {
    const ti = t ? t.getElement(i, [0, 0, 0]) : [0, 0, 0];
    const ri = r ? r.getElement(i, [0, 0, 0, 0]) : [0, 0, 0, 1];
    const si = s ? s.getElement(i, [0, 0, 0]) : [1, 1, 1];
    const norm = Math.hypot(...ri) || 1;
    const q = ri.map((c) => c / norm);
    out.push((p) => {
      const v = rotate(q, [p[0] * si[0], p[1] * si[1], p[2] * si[2]]);
      return [v[0] + ti[0], v[1] + ti[1], v[2] + ti[2]];
    });
  }
  return out;
}

function nodeInfo(node) {
  const mesh = node.getMesh();
  const world = node.getWorldMatrix();
  const placements = instances(node);
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  const primitives = (mesh ? mesh.listPrimitives() : []).map((primitive) => {
    const position = primitive.getAttribute('POSITION');
    const indices = primitive.getIndices();
    const count = indices ? indices.getCount() : position.getCount();
    let lowest = Infinity;
    const p = [0, 0, 0];
    for (let i = 0; i < position.getCount(); i++) {
      position.getElement(i, p);
      for (const place of placements) {
        const w = transform(world, place(p));
        lowest = Math.min(lowest, w[1]);
        for (let k = 0; k < 3; k++) {
          min[k] = Math.min(min[k], w[k]);
          max[k] = Math.max(max[k], w[k]);
        }
      }
    }
    const material = primitive.getMaterial();
    return {
      material: material ? material.getName() : null,
      triangles: Math.floor(count / 3),
      lowest_y: lowest,
      texcoord0: primitive.getAttribute('TEXCOORD_0') !== null,
    };
  });
  const children = node.listChildren().map(nodeInfo);
  const meshTriangles = primitives.reduce((sum, p) => sum + p.triangles, 0);
  for (const child of children) {
    for (let k = 0; k < 3; k++) {
      min[k] = Math.min(min[k], child.min[k]);
      max[k] = Math.max(max[k], child.max[k]);
    }
  }
  return {
    name: node.getName(),
    triangles: meshTriangles,
    instances: placements.length,
    drawn_triangles: meshTriangles * placements.length +
      children.reduce((sum, c) => sum + c.drawn_triangles, 0),
    min,
    max,
    primitives,
    children,
  };
}

// The MSFT_lod ids of the default scene's first node, from the JSON chunk.
function lodIds() {
  const glb = readFileSync(file);
  const jsonLength = glb.readUInt32LE(12);
  const json = JSON.parse(glb.subarray(20, 20 + jsonLength).toString('utf8'));
  const scene = json.scenes?.[json.scene ?? 0];
  const first = scene?.nodes?.[0];
  if (first === undefined) return [];
  return [first, ...(json.nodes[first].extensions?.MSFT_lod?.ids ?? [])];
}

const nodes = root.listNodes();
const scenes = root.listScenes().map((scene) => ({
  name: scene.getName(),
  nodes: scene.listChildren().map(nodeInfo),
}));
console.log(JSON.stringify({
  scenes,
  default_scene: root.getDefaultScene() ? root.listScenes().indexOf(root.getDefaultScene()) : null,
  extensions_used: root.listExtensionsUsed().map((e) => e.extensionName),
  extensions_required: root.listExtensionsRequired().map((e) => e.extensionName),
  levels: lodIds().map((i) => nodeInfo(nodes[i])),
}, null, 1));
