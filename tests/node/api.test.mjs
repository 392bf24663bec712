// The package's surface: exports vs index.d.ts, enums and functions vs bindings/abi.txt (the
// ABI summary generated from include/gmpu/gmpu.h; the Python tests keep it current),
// a TypeScript type check of typical use, and self-checks of the test helpers.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';

import { meshTopology, packageDir, packageUrl, readPly, repoRoot, tempDir } from './helpers.mjs';

const gmpu = await import(packageUrl);
const dts = fs.readFileSync(path.join(packageDir, 'index.d.ts'), 'utf8');
// One declaration per line, tab-separated: [kind, ...fields].
const abi = fs.readFileSync(path.join(repoRoot, 'bindings', 'abi.txt'), 'utf8')
    .split('\n').filter((l) => l && !l.startsWith('#')).map((l) => l.split('\t'));

test('index.js exports exactly the values index.d.ts declares', () => {
    const declared = [...dts.matchAll(/^export (?:declare )?(const|function|class|type|interface) (\w+)/gm)];
    const values = declared.filter(([, kind]) => ['const', 'function', 'class'].includes(kind)).map(([, , name]) => name);
    assert.deepEqual([...values].sort(), Object.keys(gmpu).sort());
    for (const [, kind, name] of declared) {
        if (kind === 'function' || kind === 'class') assert.equal(typeof gmpu[name], 'function', name);
        if (kind === 'const') assert.equal(typeof gmpu[name], 'object', name);
    }
    // Surface methods declared in the .d.ts exist on the class.
    const body = dts.slice(dts.indexOf('export declare class Surface'));
    const methods = [...body.slice(0, body.indexOf('\n}')).matchAll(/^ {4}(\w+)\(/gm)].map((m) => m[1]);
    assert.ok(methods.length >= 14, methods.join());
    for (const m of methods) assert.equal(typeof gmpu.Surface.prototype[m], 'function', `Surface.${m}`);
});

const camel = (snake) => snake.toLowerCase().replace(/_(\w)/g, (_, c) => c.toUpperCase());
const abiEnum = (type) => abi.filter(([kind, t]) => kind === 'enum' && t === type).map(([, , n, v]) => [n, Number(v)]);
const headerEnum = (type, prefix) => abiEnum(type).map(([n, v]) => [n.slice(prefix.length), v]);

test('status codes, parameters and statistics match the ABI summary', () => {
    const statuses = abiEnum('gmpu_status');
    assert.ok(statuses.length >= 12);
    assert.deepEqual(Object.entries(gmpu.Status), statuses);
    assert.ok(Object.isFrozen(gmpu.Status));

    const params = headerEnum('gmpu_param', 'GMPU_PARAM_');
    assert.deepEqual([...gmpu.parameterNames], params.map(([n]) => camel(n)));
    const stats = headerEnum('gmpu_stat', 'GMPU_STAT_');
    assert.deepEqual(stats.map(([, v]) => v), stats.map((_, i) => i + 1), 'statistic values are 1..n');
    assert.deepEqual([...gmpu.statisticNames], stats.map(([n]) => camel(n)));
    // Every name is in the .d.ts interfaces.
    for (const name of [...gmpu.parameterNames, ...gmpu.statisticNames]) assert.match(dts, new RegExp(`^ {4}${name}\\??: `, 'm'));
});

test('every function of the ABI summary is declared in lib/native.js, and nothing else', () => {
    const native = fs.readFileSync(path.join(packageDir, 'lib', 'native.js'), 'utf8');
    const functions = abi.filter(([kind]) => kind === 'fn').map(([, name]) => name);
    assert.ok(functions.length >= 35, `${functions.length} functions found in the header`);
    const missing = functions.filter((f) => !native.includes(`'${f}'`));
    assert.deepEqual(missing, []);
    const declared = [...native.matchAll(/'(gmpu_\w+)'/g)].map((m) => m[1]);
    assert.deepEqual(declared.filter((f) => !functions.includes(f)), []);
    // gmpu_param_info_t's fields, in order.
    const fields = abi.filter(([kind, t]) => kind === 'field' && t === 'gmpu_param_info_t').map(([, , n]) => n);
    const at = native.indexOf('koffi.struct({');
    const block = native.slice(at, native.indexOf('})', at));
    assert.deepEqual([...block.matchAll(/^\s+(\w+): '/gm)].map((m) => m[1]), fields);
    assert.match(native, new RegExp(`TYPE_INT: ${Object.fromEntries(abiEnum('gmpu_value_type')).GMPU_TYPE_INT},`));
});

test('parameterInfo() is the library\'s table: a new surface\'s values, its ranges enforced', () => {
    const info = gmpu.parameterInfo();
    assert.deepEqual(info.map((p) => p.name), [...gmpu.parameterNames]);
    assert.deepEqual(info.map((p) => p.key), info.map((_, i) => i + 1));
    const s = new gmpu.Surface();
    try {
        const actual = s.params();
        for (const p of info) {
            assert.equal(actual[p.name], p.default, p.name);
            assert.equal(p.name, camel(p.cName), p.name);
            assert.ok(p.doc.length > 10 && p.min < p.max, p.name);
            const beyond = p.max + (p.type === 'int' ? 1 : p.max * 1e-9 + 1e-12);
            assert.throws(() => s.setParam(p.name, beyond), /GMPU_ERROR_INVALID_ARGUMENT/, p.name);
        }
        // maxMemory's default depends on the machine: half its physical memory.
        const half = os.totalmem() / 2;
        assert.ok(Math.abs(actual.maxMemory - half) <= 0.01 * half, `maxMemory ${actual.maxMemory}, half of ${os.totalmem()}`);
    } finally {
        s.close();
    }
});

test('GmpuError is an Error with code, status and the C message', () => {
    let err;
    try {
        gmpu.reconstruct([[0, 0, 0]]);
    } catch (e) {
        err = e;
    }
    assert.ok(err instanceof gmpu.GmpuError);
    assert.ok(err instanceof Error);
    assert.equal(err.name, 'GmpuError');
    assert.equal(err.code, 'GMPU_ERROR_INVALID_INPUT');
    assert.equal(err.status, 2);
    assert.match(err.message, /^GMPU_ERROR_INVALID_INPUT: 1 points given/);
    assert.match(err.stack, /GmpuError: GMPU_ERROR_INVALID_INPUT/);
    const own = new gmpu.GmpuError('GMPU_ERROR_IO', 'x', { cause: 'c' });
    assert.equal(own.status, 8);
    assert.equal(own.cause, 'c');
});

test('index.d.ts type-checks typical use and rejects misuse (tsc --strict)', (t) => {
    const tsc = path.join(packageDir, 'node_modules', 'typescript', 'bin', 'tsc');
    assert.ok(fs.existsSync(tsc), 'typescript missing: run `npm ci` in bindings/node');
    const dir = tempDir(t);
    fs.mkdirSync(path.join(dir, 'node_modules'));
    fs.symlinkSync(packageDir, path.join(dir, 'node_modules', 'gmpu'));
    fs.writeFileSync(path.join(dir, 'package.json'), '{ "type": "module" }\n');
    // The only non-ES2022 globals index.d.ts uses (declared by @types/node and lib.dom, both
    // slow to load): minimal stand-ins keep this check at well under a second of CPU.
    fs.writeFileSync(path.join(dir, 'url.d.ts'), 'declare class URL { constructor(url: string); readonly href: string; }\n' +
        'declare class AbortSignal { readonly aborted: boolean; readonly reason: unknown; }\n' +
        'declare class AbortController { readonly signal: AbortSignal; abort(reason?: unknown): void; }\n');
    fs.writeFileSync(path.join(dir, 'use.ts'), `
import { reconstruct, reconstructAsync, readPoints, writeMesh, writePoints, Surface, GmpuError, Status, libraryInfo,
         parameterNames, statisticNames, type Mesh, type Stage, type Statistics } from 'gmpu';

async function inTheBackground(points: Float64Array): Promise<Mesh> {
    const controller = new AbortController();
    const one: Mesh = await reconstructAsync(points, { resolution: 32, signal: controller.signal });
    const s = new Surface(points);
    const fitted: Surface = await s.fitAsync({ signal: null });
    await (await fitted.orientAsync()).polygonizeAsync({ level: 3, signal: controller.signal });
    await s.fitAsync(points, { signal: controller.signal });
    // @ts-expect-error a signal is an AbortSignal
    await reconstructAsync(points, { signal: 'stop' });
    return one;
}
export { inTheBackground };

// Explicit resource management: the surface is closed when the scope ends.
function scoped(points: Float64Array): number {
    using t = new Surface(points);
    return t.pointCount;
}
async function scopedAsync(points: Float64Array): Promise<Mesh> {
    await using t = new Surface(points);
    return (await (await t.fitAsync()).orientAsync()).polygonizeAsync();
}
export { scoped, scopedAsync };

const cloud = readPoints(new URL('file:///tmp/cloud.ply'));
const mesh: Mesh = reconstruct(cloud.positions, { resolution: 64, sharpFeatures: false,
    onProgress: (stage: Stage, fraction: number) => fraction < 1 || stage !== 'polygonize' });
const v: Float64Array = mesh.vertices;
const f: Uint32Array = mesh.faces;
reconstruct([[0, 0, 0], [1, 2, 3]], { normals: new Float32Array(6) });
writeMesh('out.ply', mesh);
writeMesh('out.off', { vertices: [[0, 0, 0]], faces: [[0, 0, 0]] });
writePoints('p.ply', { positions: cloud.positions, normals: cloud.normals });
const s = new Surface({ maxDepth: 8 });
s.onProgress = null;
const values: Float64Array = s.fit(cloud.positions).orient().evaluate([[0, 0, 0]]);
const both: { values: Float64Array; gradients: Float64Array } = s.evaluate(new Float64Array(3), { gradient: true });
const stats: Statistics = s.stats();
const g: Float64Array = s.gradient([[0, 0, 0]]);
const coarse: Mesh = s.polygonize({ resolution: 16 });
const e: number = s.setParams({ error: 0.01, sharpFeatures: false }).params().error;
const s2 = new Surface(cloud, { normals: cloud.normals, resolution: 32 });
const s3 = new Surface('cloud.ply');
reconstruct(new URL('file:///tmp/cloud.ply'));
export { g, coarse, e, s2, s3 };
// @ts-expect-error polygonize takes resolution and level only
s.polygonize({ error: 0.1 });
const n: number = s.stat('components') + s.getParam('error') + s.pointCount + stats.leaves;
s.setParam('threads', 1).setParam('sharpFeatures', true);
s.close();
const closed: boolean = s.closed;
try { s.normals(); } catch (e) {
    if (e instanceof GmpuError && e.code === 'GMPU_ERROR_INVALID_ARGUMENT' && e.status === Status.GMPU_ERROR_INVALID_ARGUMENT) {}
}
const info: string = libraryInfo().path;
const names: readonly string[] = [...parameterNames, ...statisticNames];
export { v, f, values, both, n, closed, info, names };

// @ts-expect-error unknown option
reconstruct(cloud.positions, { maxdepth: 3 });
// @ts-expect-error unknown parameter
s.setParam('maxdepth', 3);
// @ts-expect-error unknown statistic
s.stat('nope');
// @ts-expect-error Int32Array is not accepted as points
reconstruct(new Int32Array(3));
// @ts-expect-error the stage is a name, not a number
reconstruct([], { onProgress: (stage: number) => {} });
// @ts-expect-error evaluate without gradients returns the values only
const wrong: { values: Float64Array } = s.evaluate([[0, 0, 0]]);
// @ts-expect-error code is a status name
const badCode: GmpuError['code'] = 'EIO';
export { wrong, badCode };
`);
    const r = spawnSync(process.execPath, [tsc, '--noEmit', '--strict', '--target', 'es2022', '--lib', 'es2022',
        '--module', 'nodenext', '--moduleResolution', 'nodenext', 'use.ts', 'url.d.ts'], { cwd: dir, encoding: 'utf8' });
    assert.equal(r.status, 0, `tsc failed:\n${r.stdout}${r.stderr}`);
});

test('helper self-checks: the mesh checks and the PLY reader can fail', (t) => {
    const v = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
    const closed = new Uint32Array([0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
    const good = meshTopology(v, closed);
    assert.deepEqual([good.boundaryOrNonManifold, good.inconsistent, good.degenerate], [0, 0, 0]);
    assert.ok(Math.abs(good.volume - 1 / 6) < 1e-12);
    assert.equal(meshTopology(v, closed.subarray(0, 9)).boundaryOrNonManifold, 3, 'an open mesh');
    const flippedOne = closed.slice();
    flippedOne.set([1, 3, 2], 9);
    assert.ok(meshTopology(v, flippedOne).inconsistent > 0, 'one triangle wound the other way');
    const inside = closed.slice().reverse();
    assert.ok(meshTopology(v, inside).volume < 0, 'inside out');

    const dir = tempDir(t);
    const file = path.join(dir, 'm.ply');
    gmpu.writeMesh(file, { vertices: v, faces: closed });
    assert.deepEqual(Array.from(readPly(file).faces), Array.from(closed));
    fs.appendFileSync(file, Buffer.from([0]));
    assert.throws(() => readPly(file), /trailing bytes/);
});
