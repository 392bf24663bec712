// The examples in examples/node/ run end to end as a user would run them (importing
// 'gmpu' through examples/node/package.json), and agree with the C CLI.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

import { assertWatertight, examplesDir, readPly, runCli, samplePly, tempDir } from './helpers.mjs';

const bytesOf = (a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength);

function runExample(script, args) {
    const r = spawnSync(process.execPath, [path.join(examplesDir, script), ...args], { encoding: 'utf8', cwd: examplesDir });
    return { status: r.status, stdout: r.stdout, stderr: r.stderr };
}

// Both examples, and the CLI for reference, on the sample at one resolution (to stay quick).
const RESOLUTION = '48';

test('reconstruct.mjs: same mesh and oriented points as the C CLI with the same options', (t) => {
    const dir = tempDir(t);
    const out = path.join(dir, 'node.ply'), normals = path.join(dir, 'node_points.ply');
    const r = runExample('reconstruct.mjs', [samplePly, '-o', out, '--resolution', RESOLUTION, '--normals-out', normals]);
    assert.equal(r.status, 0, r.stderr);
    assert.match(r.stderr, /gmpu: fit\.\.\.\ngmpu: orient\.\.\.\ngmpu: polygonize\.\.\./);
    assert.match(r.stderr, /35000 points/);

    const cliOut = path.join(dir, 'cli.ply'), cliNormals = path.join(dir, 'cli_points.ply');
    runCli([samplePly, '-o', cliOut, '--resolution', RESOLUTION, '--normals-out', cliNormals, '--quiet']);
    const node = readPly(out), cli = readPly(cliOut);
    assert.equal(node.vertices.length, cli.vertices.length);
    assert.ok(bytesOf(node.vertices).equals(bytesOf(cli.vertices)), 'vertices differ from the CLI');
    assert.ok(bytesOf(node.faces).equals(bytesOf(cli.faces)), 'faces differ from the CLI');
    assert.ok(fs.readFileSync(normals).equals(fs.readFileSync(cliNormals)), 'oriented points file differs from the CLI');
    assertWatertight(node, 'reconstruct.mjs output');
    t.diagnostic(`${node.vertices.length / 3} vertices, ${node.faces.length / 3} triangles`);
});

test('reconstruct.mjs: usage errors exit 2, failures exit 1 with the C message', (t) => {
    const dir = tempDir(t);
    let r = runExample('reconstruct.mjs', [samplePly]);
    assert.equal(r.status, 2);
    assert.match(r.stderr, /usage:/);
    r = runExample('reconstruct.mjs', [samplePly, '-o', path.join(dir, 'x.ply'), '--error', 'abc']);
    assert.equal(r.status, 2);
    assert.match(r.stderr, /--error needs a number/);
    // The C CLI's flags: -o for the output, --sharp (no --no-sharp, no positional OUTPUT).
    r = runExample('reconstruct.mjs', [samplePly, path.join(dir, 'x.ply')]);
    assert.equal(r.status, 2);
    r = runExample('reconstruct.mjs', [samplePly, '-o', path.join(dir, 'x.ply'), '--no-sharp']);
    assert.equal(r.status, 2);
    r = runExample('reconstruct.mjs', [path.join(dir, 'missing.ply'), '-o', path.join(dir, 'x.ply')]);
    assert.equal(r.status, 1);
    assert.match(r.stderr, /GMPU_ERROR_IO: .*missing\.ply/);
    r = runExample('reconstruct.mjs', [samplePly, '-o', path.join(dir, 'x.ply'), '--max-depth', '99']);
    assert.equal(r.status, 1);
    assert.match(r.stderr, /GMPU_ERROR_INVALID_ARGUMENT: GMPU_PARAM_MAX_DEPTH/);
    assert.deepEqual(fs.readdirSync(dir), [], 'no output on failure');
});

test('to-glb.mjs: the .glb parses back with @gltf-transform/core and holds the gmpu mesh', async (t) => {
    const dir = tempDir(t);
    const glb = path.join(dir, 'bunny.glb');
    const r = runExample('to-glb.mjs', [samplePly, glb, '--resolution', RESOLUTION]);
    assert.equal(r.status, 0, r.stderr);
    assert.equal(fs.readFileSync(glb).subarray(0, 4).toString('latin1'), 'glTF');

    // The same package the example used, resolved from examples/node.
    const require = createRequire(path.join(examplesDir, 'package.json'));
    const { NodeIO } = await import(pathToFileURL(require.resolve('@gltf-transform/core')).href);
    const doc = await new NodeIO().read(glb);
    const meshes = doc.getRoot().listMeshes();
    assert.equal(meshes.length, 1);
    const [prim] = meshes[0].listPrimitives();
    const position = prim.getAttribute('POSITION'), normal = prim.getAttribute('NORMAL'), indices = prim.getIndices();
    assert.ok(position && normal && indices, 'POSITION, NORMAL and indices present');
    assert.equal(position.getArray().constructor, Float32Array);
    assert.equal(indices.getArray().constructor, Uint32Array);
    assert.equal(normal.getCount(), position.getCount());
    assert.equal(doc.getRoot().listScenes()[0].listChildren()[0].getMesh(), meshes[0]);

    // Same mesh as the CLI's at this resolution (positions rounded to float32).
    const cliOut = path.join(dir, 'cli.ply');
    runCli([samplePly, '-o', cliOut, '--resolution', RESOLUTION, '--quiet']);
    const cli = readPly(cliOut);
    assert.equal(position.getCount(), cli.vertices.length / 3);
    assert.ok(bytesOf(position.getArray()).equals(bytesOf(new Float32Array(cli.vertices))), 'positions differ');
    assert.ok(bytesOf(normal.getArray()).equals(bytesOf(new Float32Array(cli.normals))), 'normals differ');
    assert.ok(bytesOf(indices.getArray()).equals(bytesOf(cli.faces)), 'indices differ');
    assertWatertight({ vertices: position.getArray(), faces: indices.getArray() }, 'glb mesh');
});

test('to-glb.mjs: bad usage exits 2, a bad input exits 1', (t) => {
    const dir = tempDir(t);
    let r = runExample('to-glb.mjs', [samplePly, path.join(dir, 'out.gltf')]);
    assert.equal(r.status, 2);
    assert.match(r.stderr, /\.glb/);
    r = runExample('to-glb.mjs', [path.join(examplesDir, 'package.json'), path.join(dir, 'out.glb')]);
    assert.equal(r.status, 1);
    assert.match(r.stderr, /GMPU_ERROR_UNSUPPORTED/);
    assert.deepEqual(fs.readdirSync(dir), []);
});
