// Mesh operations through the Node binding: simplifyMesh keeps a closed mesh of the same
// topology within its triangle target; polygonize's meshes carry a per-vertex confidence.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { assertWatertight, meshTopology, packageUrl, spherePoints, torusPoints } from './helpers.mjs';

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
    assert.equal(small.confidence, null);
});

test('simplifyMesh checks its options', () => {
    const mesh = gmpu.reconstruct(spherePoints(1500).xyz);
    assert.throws(() => gmpu.simplifyMesh(mesh, { targetTriangles: -1 }), /targetTriangles/);
    assert.throws(() => gmpu.simplifyMesh(mesh, { targetError: 2 }), /GMPU_ERROR_INVALID_ARGUMENT/);
    assert.throws(() => gmpu.simplifyMesh(mesh, { triangles: 10 }), /unknown option 'triangles'/);
    assert.equal(euler(gmpu.simplifyMesh(mesh, { targetTriangles: 50 })), 2);
});
