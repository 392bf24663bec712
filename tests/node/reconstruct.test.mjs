// Reconstruction through the Node package: the sample against the C CLI (bit for bit),
// watertightness and orientation checked in JS, and the Surface stages on a sphere.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import {
    assertWatertight, orientationAccuracy, packageUrl, readPly, runCli, samplePly, testData, spherePoints, tempDir, torusPoints,
} from './helpers.mjs';

const gmpu = await import(packageUrl);

const bytesOf = (a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength);

test('sample: the Node mesh equals the C CLI mesh bit for bit, and is watertight', (t) => {
    const dir = tempDir(t);
    const cliOut = path.join(dir, 'cli.ply');
    const nodeOut = path.join(dir, 'node.ply');
    runCli([samplePly, '-o', cliOut, '--quiet']);

    const cloud = gmpu.readPoints(samplePly);
    assert.equal(cloud.count, 35000);
    assert.equal(cloud.normals, null);
    const mesh = gmpu.reconstruct(cloud.positions);
    gmpu.writeMesh(nodeOut, mesh);

    const cli = readPly(cliOut);
    const written = readPly(nodeOut);
    assert.equal(mesh.vertices.length, cli.vertices.length, 'vertex count');
    assert.equal(mesh.faces.length, cli.faces.length, 'face count');
    assert.ok(bytesOf(mesh.vertices).equals(bytesOf(cli.vertices)), 'vertex coordinates differ from the CLI');
    assert.ok(bytesOf(mesh.faces).equals(bytesOf(cli.faces)), 'faces differ from the CLI');
    assert.ok(bytesOf(mesh.normals).equals(bytesOf(cli.normals)), 'vertex normals differ from the CLI');
    // The file written through gmpu_mesh_create_with + gmpu_mesh_write is the CLI's file:
    // normals and confidence included.
    assert.ok(bytesOf(written.vertices).equals(bytesOf(cli.vertices)), 'written vertex coordinates differ');
    assert.ok(bytesOf(written.normals).equals(bytesOf(cli.normals)), 'written vertex normals differ');
    assert.ok(fs.readFileSync(nodeOut).equals(fs.readFileSync(cliOut)), 'the Node file differs from the CLI file');

    assertWatertight(mesh, 'bunny mesh');
    // A whole bunny, within the default mesh's budget: between 1 and 2 triangles per point.
    const triangles = mesh.faces.length / 3;
    assert.ok(triangles >= cloud.count && triangles <= 2 * cloud.count, `${triangles} triangles`);
    // Vertex normals are unit length.
    for (let i = 0; i < mesh.normals.length; i += 3) {
        const len = Math.hypot(mesh.normals[i], mesh.normals[i + 1], mesh.normals[i + 2]);
        assert.ok(Math.abs(len - 1) < 1e-6, `vertex ${i / 3} normal has length ${len}`);
    }
});

test('bunny_clean: oriented normals agree with the ground truth on at least 99.5% of points', () => {
    const clouds = path.join(testData(), 'clouds');
    const cloud = gmpu.readPoints(path.join(clouds, 'bunny_clean.ply'));
    const gt = gmpu.readPoints(path.join(clouds, 'bunny_clean_gt.ply'));
    assert.ok(gt.normals, 'ground truth has normals');
    assert.ok(bytesOf(cloud.positions).equals(bytesOf(gt.positions)), 'ground truth points are the same points, same order');

    const surface = new gmpu.Surface();
    try {
        surface.fit(cloud.positions).orient();
        const normals = surface.normals();
        assert.equal(normals.length, 3 * cloud.count);
        const accuracy = orientationAccuracy(normals, gt.normals);
        assert.ok(accuracy >= 0.995, `orientation accuracy ${(100 * accuracy).toFixed(2)}% < 99.5%`);
        // The measure can fail: flipped normals score near zero.
        assert.ok(orientationAccuracy(normals.map((v) => -v), gt.normals) <= 0.005);
        assert.equal(surface.stat('points'), cloud.count);
        assert.ok(surface.stat('leaves') > 0);
    } finally {
        surface.close();
    }
});

test('input forms: Float32Array, Float64Array, subarray and [x, y, z] triples give the same fit', () => {
    const { xyz } = spherePoints(1500, 2, [1, -2, 3]);
    const triples = Array.from({ length: 1500 }, (_, i) => [xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]]);
    const padded = new Float64Array(xyz.length + 6);
    padded.set(xyz, 3);
    const f32 = new Float32Array(xyz);
    const normalsOf = (points) => {
        const s = new gmpu.Surface({ threads: 1 });
        try {
            return s.fit(points).orient().normals();
        } finally {
            s.close();
        }
    };
    const reference = normalsOf(xyz);
    assert.ok(bytesOf(normalsOf(triples)).equals(bytesOf(reference)), 'triples differ from Float64Array');
    assert.ok(bytesOf(normalsOf(padded.subarray(3, 3 + xyz.length))).equals(bytesOf(reference)), 'subarray differs');
    // Float32 input goes through gmpu_surface_set_points_f32: same as the widened doubles.
    assert.ok(bytesOf(normalsOf(f32)).equals(bytesOf(normalsOf(Float64Array.from(f32)))), 'f32 differs from widened f64');
});

test('sphere: evaluate signs and gradients, normals, polygonize', () => {
    const center = [1, -2, 3], r = 2;
    const { xyz, normals: truth } = spherePoints(3000, r, center);
    const surface = new gmpu.Surface({ resolution: 32 });
    try {
        assert.equal(surface.fit(xyz), surface, 'fit chains');
        surface.orient();
        assert.equal(surface.pointCount, 3000);
        assert.ok(orientationAccuracy(surface.normals(), truth) > 0.99);

        const at = (dx, dy, dz) => [center[0] + dx, center[1] + dy, center[2] + dz];
        const values = surface.evaluate([at(0, 0, 0), at(0.9 * r, 0, 0), at(1.1 * r, 0, 0), at(0, 0, -1.1 * r), at(10, 10, 10)]);
        assert.ok(values instanceof Float64Array && values.length === 5);
        assert.ok(values[1] > 0, `f inside near the surface = ${values[1]}`);
        assert.ok(values[2] < 0 && values[3] < 0, `f outside near the surface = ${values[2]}, ${values[3]}`);
        assert.ok(values[4] < 0, `f far outside = ${values[4]}`);
        // Near the surface f is about the signed distance.
        assert.ok(Math.abs(values[1] - 0.1 * r) < 0.05 * r, `f(0.9 r) = ${values[1]}`);

        const { values: v2, gradients } = surface.evaluate(new Float32Array(at(1.05 * r, 0, 0)), { gradient: true });
        assert.equal(gradients.length, 3);
        assert.ok(v2[0] < 0);
        assert.ok(gradients[0] < -0.5, `∇f points inward: ${gradients}`);
        assert.equal(surface.evaluate([]).length, 0);

        const mesh = surface.polygonize();
        assertWatertight(mesh, 'sphere mesh');
        assert.equal(surface.stat('resolution'), 32);
        for (let i = 0; i < mesh.vertices.length; i += 3) {
            const d = Math.hypot(mesh.vertices[i] - center[0], mesh.vertices[i + 1] - center[1], mesh.vertices[i + 2] - center[2]);
            assert.ok(Math.abs(d - r) < 0.03 * r, `vertex ${i / 3} at distance ${d} from the center`);
        }
    } finally {
        surface.close();
    }
});

test('reconstruct: options and known normals', () => {
    const { xyz, normals } = spherePoints(2000, 1);
    const mesh = gmpu.reconstruct(xyz, { resolution: 24, threads: 1, sharpFeatures: false, normals });
    assertWatertight(mesh, 'sphere with normals');
    assert.ok(mesh.vertices instanceof Float64Array && mesh.faces instanceof Uint32Array && mesh.normals instanceof Float64Array);
    // Known normals given inward: the solid is then the complement, and the mesh is wound the other way.
    const inward = gmpu.reconstruct(xyz, { resolution: 24, normals: normals.map((v) => -v) });
    const s = new gmpu.Surface({ resolution: 24 });
    try {
        s.setPoints(xyz).setNormals(normals.map((v) => -v)).fit().orient();
        assert.ok(s.evaluate([[0, 0, 0]])[0] < 0, 'inward normals make the ball\'s inside outside');
    } finally {
        s.close();
    }
    assert.ok(inward.faces.length > 0);
});

test('point sources: a path, a PointCloud, points in the constructor; per-call polygonize options', (t) => {
    const dir = tempDir(t);
    const { xyz, normals } = torusPoints(3000);
    const file = path.join(dir, 'torus.ply');
    gmpu.writePoints(file, { positions: xyz });
    const fromArray = gmpu.reconstruct(xyz, { resolution: 24 });
    for (const source of [file, new URL(`file://${file}`), gmpu.readPoints(file)]) {
        const mesh = gmpu.reconstruct(source, { resolution: 24 });
        assert.ok(bytesOf(mesh.vertices).equals(bytesOf(fromArray.vertices)), `from ${typeof source}`);
    }

    const s = new gmpu.Surface(xyz, { resolution: 24, normals, threads: 1 });
    try {
        assert.equal(s.pointCount, 3000);
        assert.deepEqual(s.params(), { ...s.params(), resolution: 24, threads: 1 });
        assert.equal(s.setParams({ level: 0, sharpFeatures: true }), s);
        s.fit().orient();
        assert.ok(orientationAccuracy(s.normals(), normals) > 0.999, 'known normals orient the fits');
        const q = [[1.2, 0, 0], [0, 0, 0]]; // in the tube; in the hole
        const both = s.evaluate(q, { gradient: true });
        assert.ok(bytesOf(s.gradient(q)).equals(bytesOf(both.gradients)));
        assert.ok(bytesOf(s.evaluate(q)).equals(bytesOf(both.values)));
        assert.ok(both.values[0] > 0 && both.values[1] < 0, `f inside the tube, outside it: ${both.values}`);

        const coarse = s.polygonize({ resolution: 12 });
        assert.equal(s.stat('resolution'), 12);
        assert.equal(s.getParam('resolution'), 24, 'restored after the call');
        const fine = s.polygonize();
        assert.equal(s.stat('resolution'), 24);
        assert.ok(fine.faces.length > coarse.faces.length);
        assertWatertight(coarse, 'coarse torus');
        assert.throws(() => s.polygonize({ error: 0.1 }), { code: 'GMPU_ERROR_INVALID_ARGUMENT', message: /polygonize option 'error'/ });
        assert.throws(() => s.polygonize({ resolution: 2 }), { code: 'GMPU_ERROR_INVALID_ARGUMENT' });
        assert.equal(s.getParam('resolution'), 24, 'restored after a failed call');
    } finally {
        s.close();
    }
    assert.throws(() => new gmpu.Surface({ normals }), { code: 'GMPU_ERROR_WRONG_ORDER' });
    assert.throws(() => new gmpu.Surface(42, {}), { code: 'GMPU_ERROR_INVALID_ARGUMENT' });
});

test('parameters round-trip and statistics', () => {
    const s = new gmpu.Surface({ error: 0.004, maxDepth: 8, sharpFeatures: false });
    try {
        assert.equal(s.getParam('error'), 0.004);
        assert.equal(s.getParam('maxDepth'), 8);
        assert.equal(s.getParam('sharpFeatures'), 0);
        assert.equal(s.setParam('sharpFeatures', true), s);
        assert.equal(s.getParam('sharpFeatures'), 1);
        assert.equal(s.getParam('minPoints'), 15, 'default');
        for (const name of gmpu.parameterNames) assert.equal(typeof s.getParam(name), 'number', name);
        const stats = s.stats();
        assert.deepEqual(Object.keys(stats), [...gmpu.statisticNames]);
        assert.equal(stats.points, 0);
        assert.equal(s.pointCount, 0);
    } finally {
        s.close();
    }
});

test('readPoints / writePoints / writeMesh round trip through the C library', (t) => {
    const dir = tempDir(t);
    const { xyz, normals } = spherePoints(100, 1);
    for (const ext of ['ply', 'xyz']) {
        const file = path.join(dir, `cloud.${ext}`);
        gmpu.writePoints(file, { positions: xyz, normals });
        const back = gmpu.readPoints(file);
        assert.equal(back.count, 100);
        if (ext === 'ply') {
            assert.ok(bytesOf(back.positions).equals(bytesOf(xyz)), 'PLY stores doubles exactly');
            assert.ok(bytesOf(back.normals).equals(bytesOf(normals)));
        } else {
            for (let i = 0; i < xyz.length; ++i) assert.ok(Math.abs(back.positions[i] - xyz[i]) < 1e-9);
        }
    }
    gmpu.writePoints(new URL(`file://${path.join(dir, 'no-normals.ply')}`), { positions: [[0, 0, 0], [1, 2, 3]] });
    assert.equal(gmpu.readPoints(path.join(dir, 'no-normals.ply')).normals, null);

    const tetra = { vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], faces: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] };
    assertWatertight({ vertices: new Float64Array(tetra.vertices.flat()), faces: new Uint32Array(tetra.faces.flat()) }, 'tetrahedron');
    for (const ext of ['ply', 'obj', 'off']) {
        const file = path.join(dir, `tetra.${ext}`);
        gmpu.writeMesh(file, tetra);
        assert.ok(fs.statSync(file).size > 0);
    }
    const ply = readPly(path.join(dir, 'tetra.ply'));
    assert.deepEqual(Array.from(ply.faces), tetra.faces.flat());
    assert.deepEqual(Array.from(ply.vertices), tetra.vertices.flat());
});

test('libraryInfo names the loaded library', () => {
    const info = gmpu.libraryInfo();
    assert.match(info.version, /^\d+\.\d+\.\d+$/);
    assert.equal(info.abiVersion, 1);
    assert.ok(fs.existsSync(info.path) || !path.isAbsolute(info.path));
});
