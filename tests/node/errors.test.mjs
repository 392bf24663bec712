// Error paths: every failure is a GmpuError (an Error) with the C status name as `code`
// and the C library's message.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import { pathToFileURL } from 'node:url';

import { packageDir, packageUrl, repoRoot, spherePoints, tempDir, torusPoints } from './helpers.mjs';

const gmpu = await import(packageUrl);
const { xyz } = torusPoints(2000);

// assert.throws matcher: a GmpuError with this code whose message matches `message`.
const gmpuError = (code, message) => (err) => {
    assert.ok(err instanceof gmpu.GmpuError, `expected a GmpuError, got ${err}`);
    assert.ok(err instanceof Error);
    assert.equal(err.name, 'GmpuError');
    assert.equal(err.code, code, err.message);
    assert.ok(err.message.startsWith(`${code}: `), err.message);
    if (message) assert.match(err.message, message);
    return true;
};

test('a NaN or infinite point is reported with its index', () => {
    const bad = xyz.slice();
    bad[3 * 42 + 2] = NaN;
    assert.throws(() => gmpu.reconstruct(bad), gmpuError('GMPU_ERROR_INVALID_INPUT', /\bpoint 42\b/));
    const triples = Array.from({ length: 50 }, (_, i) => [xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]]);
    triples[17][0] = Infinity;
    assert.throws(() => gmpu.reconstruct(triples), gmpuError('GMPU_ERROR_INVALID_INPUT', /\bpoint 17\b/));
    const f32 = new Float32Array(xyz);
    f32[3 * 1999] = -Infinity;
    const s = new gmpu.Surface();
    try {
        assert.throws(() => s.setPoints(f32), gmpuError('GMPU_ERROR_INVALID_INPUT', /\bpoint 1999\b/));
        // Queries too.
        s.fit(xyz).orient();
        assert.throws(() => s.evaluate([[0, 0, 0], [0, NaN, 0]]), gmpuError('GMPU_ERROR_INVALID_INPUT', /\b1\b/));
    } finally {
        s.close();
    }
});

test('too few points, no points, degenerate points', () => {
    assert.throws(() => gmpu.reconstruct([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
        gmpuError('GMPU_ERROR_INVALID_INPUT', /4 points/));
    assert.throws(() => gmpu.reconstruct(new Float64Array(0)), gmpuError('GMPU_ERROR_INVALID_INPUT', /0 points/));
    assert.throws(() => gmpu.reconstruct([]), gmpuError('GMPU_ERROR_INVALID_INPUT', /0 points/));
    assert.throws(() => gmpu.reconstruct(xyz.subarray(0, 3 * 100), { minPoints: 200 }),
        gmpuError('GMPU_ERROR_INVALID_INPUT', /100 points/));
    const plane = Array.from({ length: 60 }, (_, i) => [i % 8, Math.floor(i / 8), 0]);
    assert.throws(() => gmpu.reconstruct(plane), gmpuError('GMPU_ERROR_DEGENERATE_INPUT', /coplanar/));
});

test('a failed setPoints keeps the previous points', () => {
    const s = new gmpu.Surface();
    try {
        s.setPoints(xyz);
        assert.throws(() => s.setPoints([[0, 0, 0]]), gmpuError('GMPU_ERROR_INVALID_INPUT'));
        assert.equal(s.pointCount, 2000);
        s.fit().orient();
    } finally {
        s.close();
    }
});

test('stages called in the wrong order', () => {
    const s = new gmpu.Surface();
    try {
        assert.throws(() => s.fit(), gmpuError('GMPU_ERROR_WRONG_ORDER', /set_points/));
        assert.throws(() => s.orient(), gmpuError('GMPU_ERROR_WRONG_ORDER', /fit/));
        assert.throws(() => s.setNormals(xyz), gmpuError('GMPU_ERROR_WRONG_ORDER'));
        s.setPoints(xyz);
        assert.throws(() => s.evaluate([[0, 0, 0]]), gmpuError('GMPU_ERROR_WRONG_ORDER', /evaluate needs .*orient/));
        assert.throws(() => s.normals(), gmpuError('GMPU_ERROR_WRONG_ORDER', /copy_normals needs .*orient/));
        assert.throws(() => s.polygonize(), gmpuError('GMPU_ERROR_WRONG_ORDER', /polygonize needs .*orient/));
        s.fit();
        // Messages of const calls are their own, not the last failure of the surface.
        assert.throws(() => s.evaluate([[0, 0, 0]]), gmpuError('GMPU_ERROR_WRONG_ORDER', /evaluate/));
        assert.throws(() => s.normalsAt([0]), gmpuError('GMPU_ERROR_WRONG_ORDER', /copy_normals_at needs .*orient/));
        s.orient();
        // The normals of chosen points are rows of every point's; a bad index is named.
        const all = s.normals(), n = all.length / 3;
        const at = s.normalsAt([n - 1, 0, 5]);
        assert.deepEqual(Array.from(at), [...all.slice(3 * (n - 1)), ...all.slice(0, 3), ...all.slice(15, 18)]);
        assert.deepEqual(Array.from(s.normalsAt(new BigInt64Array([2n]))), Array.from(all.slice(6, 9)));
        assert.equal(s.normalsAt([]).length, 0);
        assert.throws(() => s.normalsAt([1, n]), gmpuError('GMPU_ERROR_INVALID_ARGUMENT', new RegExp(`indices\\[1\\] = ${n} is not a point`)));
        assert.throws(() => s.normalsAt([0.5]), TypeError);
        // A fit parameter discards the fit (and so the orientation).
        s.setParam('error', 0.01);
        assert.throws(() => s.polygonize(), gmpuError('GMPU_ERROR_WRONG_ORDER'));
    } finally {
        s.close();
    }
});

test('a closed Surface throws, close() is idempotent', () => {
    const s = new gmpu.Surface();
    s.close();
    s.close();
    assert.equal(s.closed, true);
    for (const call of [() => s.fit(xyz), () => s.orient(), () => s.normals(), () => s.evaluate([[0, 0, 0]]),
        () => s.polygonize(), () => s.stats(), () => s.pointCount, () => s.setParam('level', 1)])
        assert.throws(call, gmpuError('GMPU_ERROR_INVALID_ARGUMENT', /closed/));
});

test('bad arguments are rejected before reaching C', (t) => {
    const s = new gmpu.Surface();
    t.after(() => s.close());
    const cases = [
        [() => gmpu.reconstruct(new Float64Array(10)), /multiple of 3/],
        [() => gmpu.reconstruct(new Int32Array(9)), /Int32Array/],
        [() => gmpu.reconstruct([1, 2, 3]), /points\[0\] is not an \[x, y, z\] triple/],
        [() => gmpu.reconstruct([[1, 2]]), /points\[0\]/],
        [() => gmpu.reconstruct([[1, 2, '3']]), /points\[0\]\[2\] is not a number/],
        [() => gmpu.reconstruct(true), /got boolean/],
        [() => gmpu.reconstruct(null), /got null/],
        [() => gmpu.reconstruct(xyz, { maxdepth: 3 }), /unknown option 'maxdepth'/],
        [() => gmpu.reconstruct(xyz, { error: '0.1' }), /must be a number/],
        [() => s.setParam('nope', 1), /unknown parameter 'nope'/],
        [() => s.stat('nope'), /unknown statistic 'nope'/],
        [() => gmpu.readPoints(''), /non-empty/],
        [() => gmpu.readPoints(42), /non-empty/],
        [() => gmpu.readPoints('cloud\0.ply'), /NUL/],
        [() => gmpu.writeMesh('/tmp/x.ply', null), /mesh must be/],
        [() => gmpu.writeMesh('/tmp/x.ply', { vertices: [[0, 0, 0]], faces: [0, 0] }), /multiple of 3/],
        [() => s.evaluate(new Float32Array(4)), /multiple of 3/],
        [() => s.setNormals({ length: 3 }), /got object/],
    ];
    for (const [call, message] of cases) assert.throws(call, gmpuError('GMPU_ERROR_INVALID_ARGUMENT', message));
});

test('parameters out of range: the C message names the range', () => {
    assert.throws(() => gmpu.reconstruct(xyz, { maxDepth: 99 }), gmpuError('GMPU_ERROR_INVALID_ARGUMENT', /MAX_DEPTH.*range/));
    assert.throws(() => new gmpu.Surface({ error: NaN }), gmpuError('GMPU_ERROR_INVALID_ARGUMENT', /GMPU_PARAM_ERROR/));
    assert.throws(() => new gmpu.Surface({ resolution: 3 }), gmpuError('GMPU_ERROR_INVALID_ARGUMENT', /RESOLUTION/));
});

test('resource caps surface as GMPU_ERROR_LIMIT_EXCEEDED', () => {
    assert.throws(() => gmpu.reconstruct(xyz, { maxCells: 3 }), gmpuError('GMPU_ERROR_LIMIT_EXCEEDED'));
    assert.throws(() => gmpu.reconstruct(xyz, { resolution: 32, maxTriangles: 10 }), gmpuError('GMPU_ERROR_LIMIT_EXCEEDED'));
});

test('bad paths: missing, unsupported, malformed, unwritable', (t) => {
    const dir = tempDir(t);
    const missing = path.join(dir, 'missing.ply');
    assert.throws(() => gmpu.readPoints(missing), gmpuError('GMPU_ERROR_IO', new RegExp(`${missing}.*No such file`)));
    assert.throws(() => gmpu.readPoints(path.join(repoRoot, 'README.md')), gmpuError('GMPU_ERROR_UNSUPPORTED', /\.md/));
    assert.throws(() => gmpu.reconstruct(missing), gmpuError('GMPU_ERROR_IO', /missing\.ply/));
    assert.throws(() => new gmpu.Surface('points'), gmpuError('GMPU_ERROR_UNSUPPORTED', /no file extension/));
    const broken = path.join(dir, 'broken.ply');
    fs.writeFileSync(broken, 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1\n');
    assert.throws(() => gmpu.readPoints(broken), gmpuError('GMPU_ERROR_PARSE'));
    const mesh = { vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces: [[0, 1, 2]] };
    assert.throws(() => gmpu.writeMesh(path.join(dir, 'no', 'such', 'dir.ply'), mesh), gmpuError('GMPU_ERROR_IO', /No such file/));
    assert.throws(() => gmpu.writeMesh(path.join(dir, 'mesh.wrl'), mesh), gmpuError('GMPU_ERROR_UNSUPPORTED', /\.wrl/));
    assert.throws(() => gmpu.writeMesh(path.join(dir, 'mesh.ply'), { ...mesh, faces: [[0, 1, 3]] }),
        gmpuError('GMPU_ERROR_INVALID_INPUT', /triangle 0/));
    assert.throws(() => gmpu.writeMesh(path.join(dir, 'mesh.ply'), { ...mesh, faces: [[0, -1, 2]] }),
        gmpuError('GMPU_ERROR_INVALID_INPUT', /triangle 0/));
    assert.deepEqual(fs.readdirSync(dir), ['broken.ply'], 'failed writes leave no file behind');
    const { xyz: sphere } = spherePoints(10);
    assert.throws(() => gmpu.writePoints(path.join(dir, 'p.ply'), { positions: sphere, normals: sphere.subarray(3) }),
        gmpuError('GMPU_ERROR_INVALID_INPUT', /normals/));
});

function runWithLibrary(env, url = packageUrl) {
    const script = `import(${JSON.stringify(url)}).then((g) => {
        try { console.log('loaded ' + g.libraryInfo().path); }
        catch (e) { console.log(JSON.stringify({ name: e.name, code: e.code, message: e.message })); }
    });`;
    const r = spawnSync(process.execPath, ['--input-type=module', '-e', script], {
        env: { ...process.env, ...env }, encoding: 'utf8',
    });
    assert.equal(r.status, 0, r.stderr);
    return r.stdout.trim();
}

test('GMPU_LIBRARY: a wrong path fails with a GmpuError listing where it looked; a right one loads', (t) => {
    const out = JSON.parse(runWithLibrary({ GMPU_LIBRARY: '/nonexistent/libgmpu.so.1' }));
    assert.equal(out.name, 'GmpuError');
    assert.equal(out.code, 'GMPU_LIBRARY_NOT_FOUND');
    assert.match(out.message, /\/nonexistent\/libgmpu\.so\.1 \(GMPU_LIBRARY\): no such file/);
    const notLib = path.join(tempDir(t), 'libgmpu.so.1');
    fs.writeFileSync(notLib, 'not a library');
    assert.match(JSON.parse(runWithLibrary({ GMPU_LIBRARY: notLib })).message, new RegExp(`${notLib} \\(GMPU_LIBRARY\\): .+`));
    assert.equal(runWithLibrary({ GMPU_LIBRARY: gmpu.libraryInfo().path }), `loaded ${gmpu.libraryInfo().path}`);
});

test('without GMPU_LIBRARY: the meson build directory beside the package, then the system', (t) => {
    // A copy of the package in a tree of its own: <tmp>/bindings/node, <tmp>/build/lib.
    const root = tempDir(t);
    const pkg = path.join(root, 'bindings', 'node');
    fs.mkdirSync(path.join(pkg, 'lib'), { recursive: true });
    for (const f of ['index.js', 'package.json', path.join('lib', 'native.js')])
        fs.copyFileSync(path.join(packageDir, f), path.join(pkg, f));
    fs.symlinkSync(path.join(packageDir, 'node_modules'), path.join(pkg, 'node_modules'));
    const url = pathToFileURL(path.join(pkg, 'index.js')).href;
    const env = { GMPU_LIBRARY: '', LD_LIBRARY_PATH: '' };

    const mesonLib = path.join(root, 'build', 'lib', 'libgmpu.so.1');
    const out = runWithLibrary(env, url);
    if (out !== 'loaded libgmpu.so.1') { // unless a libgmpu is installed system-wide
        const err = JSON.parse(out);
        assert.equal(err.code, 'GMPU_LIBRARY_NOT_FOUND');
        assert.ok(err.message.includes(`${mesonLib} (meson build directory): no such file`), err.message);
        assert.match(err.message, /libgmpu\.so\.1 \(system library path\): /);
    }
    fs.mkdirSync(path.dirname(mesonLib), { recursive: true });
    fs.symlinkSync(gmpu.libraryInfo().path, mesonLib);
    assert.equal(runWithLibrary(env, url), `loaded ${mesonLib}`);
});
