// onProgress: reports, cancellation by `false`, errors thrown by the callback, misuse from
// inside the callback, and that koffi callback slots are released every time.
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import path from 'node:path';
import { test } from 'node:test';

import { packageDir, packageUrl, torusPoints } from './helpers.mjs';

const gmpu = await import(packageUrl);
// The koffi instance the package uses (for its count of registered callbacks).
const koffi = createRequire(path.join(packageDir, 'index.js'))('koffi');
const liveCallbacks = () => koffi.stats().callbacks;

const { xyz } = torusPoints(6000);

function withSurface(fn) {
    const s = new gmpu.Surface({ resolution: 32 });
    try {
        return fn(s);
    } finally {
        s.close();
        assert.equal(liveCallbacks(), 0, 'a koffi callback stayed registered');
    }
}

test('reports every stage in order, fractions in [0, 1], non-decreasing, ending at 1', () => {
    const reports = [];
    const mesh = gmpu.reconstruct(xyz, {
        resolution: 32,
        onProgress: (stage, fraction) => {
            reports.push([stage, fraction]);
            assert.equal(liveCallbacks(), 1, 'one callback registered while a stage runs');
        },
    });
    assert.ok(mesh.faces.length > 0);
    assert.equal(liveCallbacks(), 0);
    const stages = [...new Set(reports.map(([s]) => s))];
    assert.deepEqual(stages, ['fit', 'orient', 'polygonize']);
    for (const stage of stages) {
        const fractions = reports.filter(([s]) => s === stage).map(([, f]) => f);
        fractions.forEach((f, i) => {
            assert.ok(f >= 0 && f <= 1, `${stage}: fraction ${f}`);
            if (i > 0) assert.ok(f >= fractions[i - 1], `${stage}: ${fractions[i - 1]} then ${f}`);
        });
        assert.equal(fractions.at(-1), 1, `${stage} ends at 1`);
    }
});

test('returning false cancels fit; the surface keeps its points but no fit', () => withSurface((s) => {
    s.setPoints(xyz);
    let calls = 0;
    s.onProgress = () => (++calls, false);
    assert.throws(() => s.fit(), (err) => {
        assert.ok(err instanceof gmpu.GmpuError && err instanceof Error);
        assert.equal(err.code, 'GMPU_ERROR_CANCELLED');
        assert.equal(err.status, gmpu.Status.GMPU_ERROR_CANCELLED);
        assert.match(err.message, /cancel/);
        return true;
    });
    assert.equal(calls, 1, 'no report after the one that cancelled');
    s.onProgress = null;
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_WRONG_ORDER' });
    assert.equal(s.pointCount, 6000);
    s.fit().orient();
    assert.ok(s.stat('leaves') > 1);
}));

test('cancelling orient or polygonize keeps the stages before it', () => withSurface((s) => {
    s.fit(xyz);
    s.onProgress = (stage) => stage !== 'orient';
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_CANCELLED' });
    s.onProgress = null;
    assert.throws(() => s.polygonize(), { code: 'GMPU_ERROR_WRONG_ORDER' }, 'orient was cancelled');
    s.orient();
    s.onProgress = (stage) => stage !== 'polygonize';
    assert.throws(() => s.polygonize(), { code: 'GMPU_ERROR_CANCELLED' });
    s.onProgress = undefined;
    assert.ok(s.polygonize().faces.length > 0, 'orientation kept after a cancelled polygonize');
}));

test('an error thrown by the callback cancels the stage and is rethrown as is', () => withSurface((s) => {
    const boom = new RangeError('stop here');
    let calls = 0;
    s.onProgress = () => {
        ++calls;
        throw boom;
    };
    assert.throws(() => s.fit(xyz), (err) => err === boom);
    assert.equal(calls, 1);
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_WRONG_ORDER' }, 'the fit was cancelled');
    // Thrown with the last report, when the stage has already completed: still rethrown
    // (and the finished mesh freed, not handed out).
    s.onProgress = null;
    s.fit().orient();
    s.onProgress = (stage, fraction) => {
        if (stage === 'polygonize' && fraction === 1) throw boom;
    };
    assert.throws(() => s.polygonize(), (err) => err === boom);
    // Non-Error values are rethrown too.
    s.onProgress = () => {
        throw 'a string';
    };
    assert.throws(() => gmpu.reconstruct(xyz, { onProgress: s.onProgress }), (err) => err === 'a string');
}));

test('using the surface from its own callback throws (and so cancels); close() there cancels and closes', () => withSurface((s) => {
    s.fit(xyz);
    let inner = null;
    s.onProgress = () => {
        try {
            s.stats();
        } catch (err) {
            inner = err;
            throw err;
        }
    };
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_WRONG_ORDER', message: /busy/ });
    assert.equal(inner?.code, 'GMPU_ERROR_WRONG_ORDER');
    s.onProgress = () => {
        s.close();
        assert.equal(s.closed, false, 'closed only once the stage has returned');
    };
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_CANCELLED' });
    assert.equal(s.closed, true);
    assert.throws(() => s.orient(), { code: 'GMPU_ERROR_INVALID_ARGUMENT', message: /closed/ });
}));

test('onProgress must be a function', () => withSurface((s) => {
    s.setPoints(xyz);
    s.onProgress = 42;
    assert.throws(() => s.fit(), { code: 'GMPU_ERROR_INVALID_ARGUMENT' });
    assert.throws(() => new gmpu.Surface({ onProgress: 'x' }), { code: 'GMPU_ERROR_INVALID_ARGUMENT' });
}));

test('many stages with callbacks leave no callback registered', () => withSurface((s) => {
    s.setPoints(xyz);
    for (let i = 0; i < 200; ++i) {
        s.onProgress = i % 2 ? () => false : () => {
            throw new Error('x');
        };
        assert.throws(() => s.fit());
    }
    assert.equal(liveCallbacks(), 0);
}));
