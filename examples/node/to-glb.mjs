#!/usr/bin/env node
// to-glb.mjs — point cloud in, glTF binary (.glb) out, ready for any web viewer (three.js,
// Babylon.js, <model-viewer>, Blender).
//
//   node to-glb.mjs INPUT OUTPUT.glb [--resolution R] [--error E]
//
// The mesh is gmpu's closed, outward-facing surface: glTF's counter-clockwise front faces
// match gmpu's winding, and the per-vertex normals are gmpu's outward normals.
// Exit status 0 on success, 1 on a failure, 2 on bad usage.
import { Document, NodeIO } from '@gltf-transform/core';
import { parseArgs } from 'node:util';

import { GmpuError, readPoints, reconstruct } from 'gmpu';

const usage = 'usage: node to-glb.mjs INPUT OUTPUT.glb [--resolution R] [--error E]';

let values, positionals;
try {
    ({ values, positionals } = parseArgs({
        allowPositionals: true,
        options: { resolution: { type: 'string' }, error: { type: 'string' }, help: { type: 'boolean', short: 'h' } },
    }));
} catch (err) {
    console.error(`to-glb.mjs: ${err.message}\n${usage}`);
    process.exit(2);
}
if (values.help) {
    console.log(usage);
    process.exit(0);
}
if (positionals.length !== 2 || !positionals[1].toLowerCase().endsWith('.glb')) {
    console.error(`to-glb.mjs: expected INPUT and an OUTPUT ending in .glb\n${usage}`);
    process.exit(2);
}
const options = {};
for (const name of ['resolution', 'error']) {
    if (values[name] === undefined) continue;
    options[name] = Number(values[name]);
    if (values[name].trim() === '' || !Number.isFinite(options[name])) {
        console.error(`to-glb.mjs: --${name} needs a number, got '${values[name]}'\n${usage}`);
        process.exit(2);
    }
}
const [input, output] = positionals;

let mesh;
try {
    mesh = reconstruct(readPoints(input).positions, options);
} catch (err) {
    if (!(err instanceof GmpuError)) throw err;
    console.error(`to-glb.mjs: ${err.message}`);
    process.exit(1);
}

// glTF stores float32 positions and normals; indices stay uint32.
const doc = new Document();
const buffer = doc.createBuffer();
const position = doc.createAccessor('POSITION').setType('VEC3').setArray(new Float32Array(mesh.vertices)).setBuffer(buffer);
const normal = doc.createAccessor('NORMAL').setType('VEC3').setArray(new Float32Array(mesh.normals)).setBuffer(buffer);
const indices = doc.createAccessor('indices').setType('SCALAR').setArray(mesh.faces).setBuffer(buffer);
const material = doc.createMaterial('gmpu').setBaseColorFactor([0.8, 0.78, 0.74, 1]).setRoughnessFactor(0.7).setMetallicFactor(0);
const primitive = doc.createPrimitive()
    .setAttribute('POSITION', position)
    .setAttribute('NORMAL', normal)
    .setIndices(indices)
    .setMaterial(material);
const gltfMesh = doc.createMesh('surface').addPrimitive(primitive);
const node = doc.createNode('surface').setMesh(gltfMesh);
doc.createScene('scene').addChild(node);
doc.getRoot().getAsset().generator = 'gmpu to-glb.mjs';

try {
    await new NodeIO().write(output, doc);
} catch (err) {
    console.error(`to-glb.mjs: cannot write ${output}: ${err.message}`);
    process.exit(1);
}
console.error(`gmpu: ${mesh.vertices.length / 3} vertices, ${mesh.faces.length / 3} triangles -> ${output}`);
