// Mesh operations through the Node binding: simplifyMesh keeps a closed mesh of the same
// topology within its triangle target; polygonize's meshes carry a per-vertex confidence;
// writeMesh keeps normals and colours; PLY colours reach the mesh; readPoints takes a
// budget and a progress callback.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import { assertWatertight, meshTopology, packageUrl, readPly, spherePoints, tempDir, torusPoints } from './helpers.mjs';

const gmpu = await import(packageUrl);

const euler = (mesh) => {
    const topo = meshTopology(mesh.vertices, mesh.faces);
    return new Set(mesh.faces).size - topo.edges + mesh.faces.length / 3;
};

test('simplifyMesh decimates a torus to a tenth, closed and still of genus 1', () => {
    const mesh = gmpu.reconstruct(torusPoints(4000).xyz);
    assert.equal(mesh.confidence.length, mesh.vertices.length / 3);
    assert.ok(mesh.confidence.every((c) => c >= 0 && c < 2));
    const target = Math.floor(mesh.faces.length / 3 / 10);
    const small = gmpu.simplifyMesh(mesh, { targetTriangles: target, targetError: 0.02 });
    assert.ok(small.faces.length / 3 <= target, `${small.faces.length / 3} > ${target}`);
    assertWatertight(small, 'simplified torus');
    assert.equal(euler(small), 0);
    assert.equal(small.normals.length, small.vertices.length);
    assert.equal(small.confidence.length, small.vertices.length / 3); // carried
});

test('writeMesh keeps the vertex normals, bit for bit, and the colours', (t) => {
    const dir = tempDir(t);
    const mesh = gmpu.reconstruct(spherePoints(1500).xyz, { resolution: 24 });
    const file = path.join(dir, 'mesh.ply');
    gmpu.writeMesh(file, mesh);
    const back = readPly(file);
    assert.deepEqual(back.normals, mesh.normals);
    assert.match(back.header, /property float confidence/);
    // From plain arrays too (normals of any length are made unit), and with colours.
    const colors = new Uint8Array(mesh.vertices.length).fill(7);
    gmpu.writeMesh(file, { vertices: mesh.vertices, faces: mesh.faces, normals: mesh.normals.map((x) => 2 * x), colors });
    const again = readPly(file);
    assert.ok(again.normals.every((x, i) => Math.abs(x - mesh.normals[i]) < 1e-12));
    assert.match(again.header, /property uchar red\nproperty uchar green\nproperty uchar blue/);
    assert.deepEqual(gmpu.readPoints(file).colors, colors);
    assert.throws(() => gmpu.writeMesh(file, { ...mesh, normals: mesh.normals.subarray(3) }), /mesh.normals has/);
});

// A binary PLY of a sphere whose +x half is red and -x half blue.
function colouredSphere(file, n) {
    const { xyz } = spherePoints(n);
    const header = `ply\nformat binary_little_endian 1.0\nelement vertex ${n}\nproperty double x\nproperty double y\n` +
        'property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n';
    const body = Buffer.alloc(27 * n);
    for (let i = 0; i < n; ++i) {
        for (let k = 0; k < 3; ++k) body.writeDoubleLE(xyz[3 * i + k], 27 * i + 8 * k);
        body.writeUInt8(xyz[3 * i] > 0 ? 255 : 0, 27 * i + 24);
        body.writeUInt8(xyz[3 * i] > 0 ? 0 : 255, 27 * i + 26);
    }
    fs.writeFileSync(file, Buffer.concat([Buffer.from(header), body]));
}

test('PLY colours reach the reconstructed mesh (nearest point) and its file', (t) => {
    const dir = tempDir(t);
    const file = path.join(dir, 'sphere.ply');
    colouredSphere(file, 2000);
    const cloud = gmpu.readPoints(file);
    assert.ok(cloud.colors instanceof Uint8Array && cloud.colors.length === 6000);
    const mesh = gmpu.reconstruct(file, { resolution: 24 });
    for (let v = 0; v < mesh.vertices.length / 3; ++v) {
        const x = mesh.vertices[3 * v];
        if (Math.abs(x) > 0.05) assert.deepEqual([...mesh.colors.subarray(3 * v, 3 * v + 3)], x > 0 ? [255, 0, 0] : [0, 0, 255]);
    }
    assert.deepEqual(gmpu.colorMesh({ vertices: mesh.vertices, faces: mesh.faces }, cloud).colors, mesh.colors);
    assert.equal(gmpu.reconstruct(cloud.positions, { resolution: 24 }).colors, null);
    assert.throws(() => gmpu.colorMesh(mesh, { positions: cloud.positions }), /no colors/);
});

test('readPoints reports progress, cancels on false, and honours maxMemory', (t) => {
    const dir = tempDir(t);
    const file = path.join(dir, 'sphere.ply');
    colouredSphere(file, 40000); // about 1.9 MB of points by the library's estimate
    const seen = [];
    assert.equal(gmpu.readPoints(file, { onProgress: (stage, f) => { seen.push([stage, f]); } }).count, 40000);
    assert.ok(seen.length >= 2 && seen.every(([stage]) => stage === 'read'));
    assert.equal(seen.at(-1)[1], 1);
    assert.throws(() => gmpu.readPoints(file, { onProgress: () => false }), /GMPU_ERROR_CANCELLED/);
    assert.throws(() => gmpu.readPoints(file, { onProgress: () => { throw new RangeError('mine'); } }), RangeError);
    assert.throws(() => gmpu.readPoints(file, { maxMemory: 1e6 }), /GMPU_ERROR_LIMIT_EXCEEDED/);
    assert.throws(() => gmpu.readPoints(file, { budget: 1 }), /unknown option 'budget'/);
});

test('simplifyMesh checks its options', () => {
    const mesh = gmpu.reconstruct(spherePoints(1500).xyz);
    assert.throws(() => gmpu.simplifyMesh(mesh, { targetTriangles: -1 }), /targetTriangles/);
    assert.throws(() => gmpu.simplifyMesh(mesh, { targetError: 2 }), /GMPU_ERROR_INVALID_ARGUMENT/);
    assert.throws(() => gmpu.simplifyMesh(mesh, { triangles: 10 }), /unknown option 'triangles'/);
    assert.equal(euler(gmpu.simplifyMesh(mesh, { targetTriangles: 50 })), 2);
});
