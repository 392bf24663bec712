// The ...Async stages: same results as the blocking ones, the event loop keeps running
// while they work, AbortSignal and close() cancel, misuse while one runs is refused, and
// failures carry the C message although the C call ran on another thread.
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import path from 'node:path';
import { test } from 'node:test';

import { packageDir, packageUrl, torusPoints } from './helpers.mjs';

const gmpu = await import(packageUrl);
const koffi = createRequire(path.join(packageDir, 'index.js'))('koffi');
const liveCallbacks = () => koffi.stats().callbacks;

const { xyz } = torusPoints(6000);
const OPTIONS = { resolution: 32 };

function assertSameMesh(a, b) {
    assert.deepEqual(a.vertices, b.vertices);
    assert.deepEqual(a.faces, b.faces);
    assert.deepEqual(a.normals, b.normals);
}

test('reconstructAsync gives exactly the mesh reconstruct gives', async () => {
    const reports = [];
    const mesh = await gmpu.reconstructAsync(xyz, { ...OPTIONS, onProgress: (stage, f) => void reports.push([stage, f]) });
    assertSameMesh(mesh, gmpu.reconstruct(xyz, OPTIONS));
    assert.deepEqual([...new Set(reports.map(([s]) => s))], ['fit', 'orient', 'polygonize']);
    assert.equal(liveCallbacks(), 0, 'a koffi callback stayed registered');
});

test('two surfaces reconstruct at the same time, each as it would alone', async () => {
    const other = torusPoints(5000, 1, 0.25).xyz;
    const [a, b] = await Promise.all([gmpu.reconstructAsync(xyz, OPTIONS), gmpu.reconstructAsync(other, OPTIONS)]);
    assertSameMesh(a, gmpu.reconstruct(xyz, OPTIONS));
    assertSameMesh(b, gmpu.reconstruct(other, OPTIONS));
});

test('the event loop keeps running while a stage works', async () => {
    // A timer ticks every millisecond. A blocking call would hold it for the whole stage;
    // here the largest gap between ticks must stay well below the stage's duration.
    const big = torusPoints(150000).xyz;
    const surface = new gmpu.Surface(big);
    try {
        const ticks = [];
        const timer = setInterval(() => ticks.push(performance.now()), 1);
        const t0 = performance.now();
        await surface.fitAsync();
        const t1 = performance.now();
        clearInterval(timer);
        const inside = [t0, ...ticks.filter((t) => t >= t0 && t <= t1), t1];
        const gap = Math.max(...inside.slice(1).map((t, i) => t - inside[i]));
        assert.ok(t1 - t0 > 50, `the fit took ${(t1 - t0).toFixed(0)} ms: too short to tell`);
        assert.ok(gap < 0.5 * (t1 - t0), `the event loop stalled ${gap.toFixed(0)} ms during a ${(t1 - t0).toFixed(0)} ms fit`);
        assert.ok(surface.stat('leaves') > 0);
    } finally {
        surface.close();
    }
});

test('an AbortSignal cancels the running stage; the surface keeps what completed', async () => {
    const surface = new gmpu.Surface(xyz, OPTIONS);
    try {
        await surface.fitAsync();
        const controller = new AbortController();
        const reason = new Error('user pressed stop');
        surface.onProgress = () => controller.abort(reason);
        await assert.rejects(surface.orientAsync({ signal: controller.signal }), (err) => {
            assert.ok(err instanceof gmpu.GmpuError);
            assert.equal(err.code, 'GMPU_ERROR_CANCELLED');
            assert.match(err.message, /orient cancelled by its AbortSignal/);
            assert.equal(err.cause, reason);
            return true;
        });
        surface.onProgress = null;
        assert.ok(surface.stat('leaves') > 0, 'the fit survived the cancelled orient');
        await surface.orientAsync();
        assertSameMesh(await surface.polygonizeAsync(), gmpu.reconstruct(xyz, OPTIONS));
    } finally {
        surface.close();
    }
    assert.equal(liveCallbacks(), 0);
});

test('an already aborted signal rejects before any work', async () => {
    let reports = 0;
    const signal = AbortSignal.abort(new Error('too late'));
    await assert.rejects(gmpu.reconstructAsync(xyz, { signal, onProgress: () => void ++reports }), {
        code: 'GMPU_ERROR_CANCELLED', message: /fit not started/,
    });
    assert.equal(reports, 0);
    await assert.rejects(gmpu.reconstructAsync(xyz, { signal: 'stop' }), { code: 'GMPU_ERROR_INVALID_ARGUMENT', message: /AbortSignal/ });
});

test('close() during an async stage cancels it and frees the surface when it returns', async () => {
    const surface = new gmpu.Surface(torusPoints(60000).xyz);
    const running = surface.fitAsync();
    surface.close();
    assert.equal(surface.closed, false, 'still owned by the running stage');
    await assert.rejects(running, { code: 'GMPU_ERROR_CANCELLED' });
    assert.equal(surface.closed, true);
    assert.equal(liveCallbacks(), 0);
});

test('while an async stage runs, every other use of the surface is refused', async () => {
    const surface = new gmpu.Surface(xyz, OPTIONS);
    try {
        const running = surface.fitAsync();
        const busy = { code: 'GMPU_ERROR_WRONG_ORDER', message: /busy: an async stage is running/ };
        assert.throws(() => surface.orient(), busy);
        assert.throws(() => surface.evaluate([[0, 0, 0]]), busy);
        assert.throws(() => surface.setParam('error', 0.01), busy);
        await assert.rejects(surface.fitAsync(), busy);
        await running;
        await surface.orientAsync();
        assert.equal(surface.evaluate([[0, 0, 0]]).length, 1);
    } finally {
        surface.close();
    }
});

test('failures carry the C message although the C call ran on a worker thread', async () => {
    const surface = new gmpu.Surface();
    try {
        await assert.rejects(surface.orientAsync(), {
            code: 'GMPU_ERROR_WRONG_ORDER', message: 'GMPU_ERROR_WRONG_ORDER: gmpu_surface_orient needs gmpu_surface_fit first',
        });
        surface.setPoints(xyz).setParam('maxCells', 10);
        await assert.rejects(surface.fitAsync(), { code: 'GMPU_ERROR_LIMIT_EXCEEDED', message: /GMPU_PARAM_MAX_CELLS/ });
    } finally {
        surface.close();
    }
    const mine = new Error('from onProgress');
    await assert.rejects(gmpu.reconstructAsync(xyz, { onProgress: () => { throw mine; } }), (err) => err === mine);
    assert.equal(liveCallbacks(), 0);
});

test('polygonizeAsync overrides resolution for the call only', async () => {
    const surface = new gmpu.Surface(xyz, OPTIONS);
    try {
        await (await surface.fitAsync()).orientAsync();
        const coarse = await surface.polygonizeAsync({ resolution: 16 });
        assert.equal(surface.getParam('resolution'), 32);
        assertSameMesh(coarse, surface.polygonize({ resolution: 16 }));
        await assert.rejects(surface.polygonizeAsync({ colour: 1 }), { code: 'GMPU_ERROR_INVALID_ARGUMENT' });
    } finally {
        surface.close();
    }
});
