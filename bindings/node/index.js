// gmpu for Node.js: unoriented point cloud in, oriented implicit surface and watertight
// mesh out. A thin layer over the C ABI (include/gmpu/gmpu.h) through koffi; see index.d.ts
// for the documented API.
import { fileURLToPath } from 'node:url';
import { getNative, copyArray, koffi, LibraryError } from './lib/native.js';

// ---- errors ----------------------------------------------------------------------------

/** gmpu_status values by name (fixed forever by the C ABI). */
export const Status = Object.freeze({
    GMPU_OK: 0,
    GMPU_ERROR_INVALID_ARGUMENT: 1,
    GMPU_ERROR_INVALID_INPUT: 2,
    GMPU_ERROR_DEGENERATE_INPUT: 3,
    GMPU_ERROR_WRONG_ORDER: 4,
    GMPU_ERROR_OUT_OF_MEMORY: 5,
    GMPU_ERROR_LIMIT_EXCEEDED: 6,
    GMPU_ERROR_CANCELLED: 7,
    GMPU_ERROR_IO: 8,
    GMPU_ERROR_PARSE: 9,
    GMPU_ERROR_UNSUPPORTED: 10,
    GMPU_ERROR_INTERNAL: 11,
    GMPU_ERROR_BUSY: 12,
});
const statusNames = Object.fromEntries(Object.entries(Status).map(([k, v]) => [v, k]));

/** Every failure of this package: `code` is the C status name, `message` the C message. */
export class GmpuError extends Error {
    constructor(code, message, options) {
        super(message, options);
        this.name = 'GmpuError';
        this.code = code;
        this.status = Object.hasOwn(Status, code) ? Status[code] : undefined;
    }
}

// A failure detected on the JS side, worded like the C library's messages.
function jsError(code, text) {
    return new GmpuError(code, `${code}: ${text}`);
}
const invalidArgument = (text) => jsError('GMPU_ERROR_INVALID_ARGUMENT', text);

function lib() {
    try {
        return getNative();
    } catch (err) {
        if (err instanceof LibraryError) throw new GmpuError(err.code, err.message);
        throw err;
    }
}

// The error of a failed call: status name and message from the library. A synchronous
// call runs on the JS thread, so gmpu_last_error() (thread-local, any function) is the
// message of this failure. gmpu_surface_last_error(handle) is only a fallback: const calls
// (evaluate, copy_normals, get_param, get_stat) do not set it, so it may hold an older one.
// An async stage ran on a worker thread: its caller passes the surface's message.
function failure(status, handle, message = null) {
    const n = lib();
    const code = statusNames[status] ?? n.status_name(status);
    message ||= n.last_error() || (handle ? n.surface_last_error(handle) : '') || code;
    return new GmpuError(code, message);
}

function check(status, handle) {
    if (status !== 0) throw failure(status, handle);
}

// ---- parameters, stages, statistics ----------------------------------------------------

// The library's parameter table (gmpu_param_count / gmpu_param_info): names, keys, types,
// defaults, ranges and docs all come from libgmpu, read once, on first use.
let paramTable = null;
const camelCase = (snake) => snake.replace(/_(\w)/g, (_, c) => c.toUpperCase());

function paramsByName() {
    if (paramTable) return paramTable;
    const n = lib();
    const rows = new Map();
    for (let key = 1; key <= n.param_count(); ++key) {
        const info = {};
        check(n.param_info(key, info));
        const integer = info.type === n.TYPE_INT;
        const row = Object.freeze({
            key,
            name: camelCase(info.name),
            cName: info.name,
            type: integer ? 'int' : 'real',
            default: info.default_value,
            min: info.min,
            max: info.max,
            minExclusive: info.min_exclusive !== 0,
            maxExclusive: info.max_exclusive !== 0,
            refits: info.refits !== 0,
            doc: info.doc,
        });
        rows.set(row.name, row);
    }
    paramTable = rows;
    return rows;
}

// Read at import when the library loads, so that the names are a plain array; when it does
// not, the list is empty and the first call reports why.
function namesAtImport() {
    try {
        return [...paramsByName().keys()];
    } catch {
        return [];
    }
}

// The statistics' keys by camelCase name, from the library (gmpu_stat_count /
// gmpu_stat_name), read at import like the parameters' names (empty when it does not load).
function statsAtImport() {
    try {
        const n = lib();
        const keys = {};
        for (let key = 1; key <= n.stat_count(); ++key) keys[camelCase(n.stat_name(key))] = key;
        return Object.freeze(keys);
    } catch {
        return Object.freeze({});
    }
}
const STATS = statsAtImport();

const STAGES = Object.freeze({ 1: 'fit', 2: 'orient', 3: 'polygonize', 4: 'read' });

/** Names of the parameters (Surface options) and statistics. */
export const parameterNames = Object.freeze(namesAtImport());
export const statisticNames = Object.freeze(Object.keys(STATS));

/** The library's description of every parameter (key, type, default, range, doc), in key order. */
export function parameterInfo() {
    return [...paramsByName().values()];
}

function paramKey(name) {
    const row = paramsByName().get(name);
    if (!row) throw invalidArgument(`unknown parameter '${String(name)}' (one of: ${[...paramsByName().keys()].join(', ')})`);
    return row.key;
}

function paramValue(name, value) {
    if (typeof value === 'boolean') return value ? 1 : 0;
    if (typeof value !== 'number')
        throw invalidArgument(`parameter '${name}' must be a number, got ${typeof value}`);
    return value;
}

// ---- input conversion ------------------------------------------------------------------

function describe(value) {
    if (value === null) return 'null';
    if (ArrayBuffer.isView(value)) return value.constructor.name;
    if (Array.isArray(value)) return 'Array';
    return typeof value;
}

// points → { data: Float64Array | Float32Array, count }. Typed arrays are used as they
// are (no copy); an array of [x, y, z] triples is packed into a Float64Array.
function toXyz(points, what, { allowF32 = true } = {}) {
    if (points instanceof Float64Array || points instanceof Float32Array) {
        if (points.length % 3 !== 0)
            throw invalidArgument(`${what}: length ${points.length} is not a multiple of 3 (x y z per point)`);
        const data = !allowF32 && points instanceof Float32Array ? Float64Array.from(points) : points;
        return { data, count: points.length / 3 };
    }
    if (Array.isArray(points)) {
        const out = new Float64Array(3 * points.length);
        for (let i = 0; i < points.length; ++i) {
            const p = points[i];
            if (p === null || typeof p !== 'object' || p.length !== 3)
                throw invalidArgument(`${what}[${i}] is not an [x, y, z] triple`);
            for (let k = 0; k < 3; ++k) {
                const v = p[k];
                if (typeof v !== 'number') throw invalidArgument(`${what}[${i}][${k}] is not a number`);
                out[3 * i + k] = v;
            }
        }
        return { data: out, count: points.length };
    }
    throw invalidArgument(
        `${what} must be a Float32Array or Float64Array of x y z triples, or an array of [x, y, z]; got ${describe(points)}`,
    );
}

// faces → Uint32Array (flat, 3 per triangle). Accepts any typed or plain array of
// integers, flat or as [a, b, c] triples.
function toFaces(faces, what) {
    if (faces instanceof Uint32Array) {
        if (faces.length % 3 !== 0) throw invalidArgument(`${what}: length ${faces.length} is not a multiple of 3`);
        return faces;
    }
    let flat;
    if (Array.isArray(faces) && faces.length > 0 && typeof faces[0] === 'object' && faces[0] !== null) {
        flat = [];
        faces.forEach((t, i) => {
            if (t === null || typeof t !== 'object' || t.length !== 3) throw invalidArgument(`${what}[${i}] is not an [a, b, c] triple`);
            flat.push(t[0], t[1], t[2]);
        });
    } else if (Array.isArray(faces) || ArrayBuffer.isView(faces)) {
        flat = faces;
    } else {
        throw invalidArgument(`${what} must be a Uint32Array or an array of vertex indices; got ${describe(faces)}`);
    }
    if (flat.length % 3 !== 0) throw invalidArgument(`${what}: length ${flat.length} is not a multiple of 3`);
    const out = new Uint32Array(flat.length);
    for (let i = 0; i < flat.length; ++i) {
        const v = Number(flat[i]);
        if (!Number.isInteger(v) || v < 0 || v > 0xffffffff)
            throw jsError('GMPU_ERROR_INVALID_INPUT', `${what}: triangle ${Math.floor(i / 3)} has an invalid vertex index ${flat[i]}`);
        out[i] = v;
    }
    return out;
}

// What setPoints accepts besides coordinates: a PointCloud from readPoints, or a file.
function isPointSource(v) {
    return ArrayBuffer.isView(v) || Array.isArray(v) || typeof v === 'string' || v instanceof URL ||
        (v !== null && typeof v === 'object' && 'positions' in v);
}

function pointSource(points) {
    if (typeof points === 'string' || points instanceof URL) return readPoints(points).positions;
    if (points !== null && typeof points === 'object' && !Array.isArray(points) && !ArrayBuffer.isView(points) && 'positions' in points)
        return points.positions;
    return points;
}

function toPath(p, what = 'path') {
    if (p instanceof URL) p = fileURLToPath(p);
    if (typeof p !== 'string' || p.length === 0) throw invalidArgument(`${what} must be a non-empty string or a file: URL`);
    // koffi would silently cut the string at a NUL byte.
    if (p.includes('\0')) throw invalidArgument(`${what} contains a NUL character`);
    return p;
}

// A non-NULL pointer for empty input, so that the C library reports "too few points"
// (INVALID_INPUT) rather than "xyz is NULL" for an empty array.
const EMPTY_F64 = new Float64Array(3);
const EMPTY_I64 = new BigInt64Array(1);
const EMPTY_F32 = new Float32Array(3);
const nonEmpty = (data) => (data.length > 0 ? data : data instanceof Float32Array ? EMPTY_F32 : EMPTY_F64);

// ---- surface ---------------------------------------------------------------------------

// Safety net only: a Surface that was never closed frees its handle when collected.
const finalizer = new FinalizationRegistry((cell) => {
    if (cell.ptr !== null) {
        const ptr = cell.ptr;
        cell.ptr = null;
        getNative().surface_destroy(ptr);
    }
});

/**
 * A reconstruction: points → fit → orient → evaluate / normals / polygonize.
 * Owns a native handle: call close() when done (it is idempotent).
 */
export class Surface {
    #cell; // { ptr } shared with the finalizer
    #busy = false; // inside a synchronous fit / orient / polygonize (only onProgress can call in)
    #running = false; // an ...Async stage is running on a worker thread
    #closeRequested = false;

    /** @type {((stage: string, fraction: number) => unknown) | null} */
    onProgress = null;

    /**
     * new Surface([points], [options]): options are parameters, `onProgress` and `normals`
     * (known outward normals for the points); points as for setPoints.
     */
    constructor(pointsOrOptions, options) {
        let points;
        if (pointsOrOptions === undefined || pointsOrOptions === null) {
            // new Surface() or new Surface(undefined, options)
        } else if (isPointSource(pointsOrOptions)) {
            points = pointsOrOptions;
        } else if (options === undefined) {
            options = pointsOrOptions;
        } else {
            throw invalidArgument(`points must be point coordinates, a PointCloud or a path; got ${describe(pointsOrOptions)}`);
        }
        options ??= {};
        if (typeof options !== 'object') throw invalidArgument('options must be an object');
        const n = lib();
        const out = [null];
        check(n.surface_create(out));
        this.#cell = { ptr: out[0] };
        finalizer.register(this, this.#cell, this.#cell);
        try {
            applyOptions(this, options, ['normals']);
            if (points !== undefined) this.setPoints(points);
            if (options.normals !== undefined && options.normals !== null) {
                if (points === undefined) throw jsError('GMPU_ERROR_WRONG_ORDER', 'normals given without points');
                this.setNormals(options.normals);
            }
        } catch (err) {
            this.close();
            throw err;
        }
    }

    /** True once close() has run. */
    get closed() {
        return this.#cell.ptr === null;
    }

    // The live handle, or an error if closed or re-entered from the progress callback.
    #handle() {
        if (this.#cell.ptr === null) throw invalidArgument('the Surface is closed');
        if (this.#busy)
            throw jsError('GMPU_ERROR_WRONG_ORDER', 'the Surface is busy: it cannot be used from its own progress callback');
        if (this.#running)
            throw jsError('GMPU_ERROR_WRONG_ORDER',
                'the Surface is busy: an async stage is running (await it first, or cancel it with close() or its AbortSignal)');
        return this.#cell.ptr;
    }

    /**
     * Frees the native surface. Idempotent. Inside onProgress, or while an async stage runs,
     * cancels the running stage and frees the surface when it has returned.
     */
    close() {
        if (this.#cell.ptr === null) return;
        if (this.#busy || this.#running) {
            this.#closeRequested = true;
            return;
        }
        const ptr = this.#cell.ptr;
        this.#cell.ptr = null;
        finalizer.unregister(this.#cell);
        lib().surface_destroy(ptr);
    }

    setParam(name, value) {
        const h = this.#handle();
        check(lib().surface_set_param(h, paramKey(name), paramValue(name, value)), h);
        return this;
    }

    getParam(name) {
        const h = this.#handle();
        const out = [0];
        check(lib().surface_get_param(h, paramKey(name), out));
        return out[0];
    }

    stat(name) {
        const h = this.#handle();
        if (!Object.hasOwn(STATS, name))
            throw invalidArgument(`unknown statistic '${String(name)}' (one of: ${statisticNames.join(', ')})`);
        const out = [0];
        check(lib().surface_get_stat(h, STATS[name], out));
        return out[0];
    }

    /** Sets several parameters: { name: value }. */
    setParams(params) {
        if (params === null || typeof params !== 'object') throw invalidArgument('params must be an object');
        for (const [name, value] of Object.entries(params)) if (value !== undefined) this.setParam(name, value);
        return this;
    }

    /** Every parameter, by name. */
    params() {
        return Object.fromEntries([...paramsByName().keys()].map((name) => [name, this.getParam(name)]));
    }

    /** Every statistic, by name. */
    stats() {
        return Object.fromEntries(statisticNames.map((name) => [name, this.stat(name)]));
    }

    get pointCount() {
        return Number(lib().surface_point_count(this.#handle()));
    }

    setPoints(points) {
        const h = this.#handle();
        const { data, count } = toXyz(pointSource(points), 'points');
        const n = lib();
        const fn = data instanceof Float32Array ? n.surface_set_points_f32 : n.surface_set_points_f64;
        check(fn(h, nonEmpty(data), count, 0), h);
        return this;
    }

    setNormals(normals) {
        const h = this.#handle();
        const { data, count } = toXyz(normals, 'normals');
        const n = lib();
        const fn = data instanceof Float32Array ? n.surface_set_normals_f32 : n.surface_set_normals_f64;
        check(fn(h, nonEmpty(data), count, 0), h);
        return this;
    }

    /** Builds the octree of local fits; with `points`, sets them first. */
    fit(points) {
        if (points !== undefined && points !== null) this.setPoints(points);
        this.#stage((h) => lib().surface_fit(h));
        return this;
    }

    orient() {
        this.#stage((h) => lib().surface_orient(h));
        return this;
    }

    evaluate(points, options = {}) {
        const h = this.#handle();
        const { data, count } = toXyz(points, 'points', { allowF32: false });
        const values = new Float64Array(count);
        const gradients = options?.gradient ? new Float64Array(3 * count) : null;
        if (count > 0) check(lib().surface_evaluate(h, data, count, values, gradients));
        else check(lib().surface_evaluate(h, EMPTY_F64, 0, EMPTY_F64, null));
        return gradients !== null ? { values, gradients } : values;
    }

    /** ∇f at each point (3 per point): it points into the solid. */
    gradient(points) {
        return this.evaluate(points, { gradient: true }).gradients;
    }

    /** Oriented unit normal of every input point: Float64Array, 3 per point. */
    normals() {
        const h = this.#handle();
        const n = lib();
        const count = Number(n.surface_point_count(h));
        const out = new Float64Array(3 * count);
        check(n.surface_copy_normals(h, count > 0 ? out : EMPTY_F64, count));
        return out;
    }

    /**
     * Oriented unit normals of the input points `indices` (an array of integers, or a
     * BigInt64Array): Float64Array, 3 per index, as normals() gives them.
     */
    normalsAt(indices) {
        const idx = indices instanceof BigInt64Array ? indices : BigInt64Array.from(indices, (i) => {
            if (!Number.isInteger(i)) throw new TypeError(`indices must be integers (got ${i})`);
            return BigInt(i);
        });
        const h = this.#handle();
        const out = new Float64Array(3 * idx.length);
        check(lib().surface_copy_normals_at(h, idx.length > 0 ? idx : EMPTY_I64, idx.length,
            idx.length > 0 ? out : EMPTY_F64));
        return out;
    }

    /**
     * The zero set as a closed mesh: { vertices, faces, normals }. `resolution` and `level`
     * apply to this call only (the surface's parameters are restored afterwards).
     */
    polygonize(options = {}) {
        return this.#polygonizeWith(options, (out) => this.#stage((h) => lib().surface_polygonize(h, out)));
    }

    // ---- the same stages without blocking the event loop ----
    // Each runs the C stage on a koffi worker thread and resolves when it returns. Until
    // then every other method of this Surface throws "busy" (they would otherwise wait for
    // the stage, blocking the event loop); close() and `signal` cancel the stage.

    /** fit() on a worker thread; with `points`, sets them first (synchronously: they are copied). */
    async fitAsync(pointsOrOptions, options) {
        if (isPointSource(pointsOrOptions)) this.setPoints(pointsOrOptions);
        else options ??= pointsOrOptions;
        await this.#stageAsync('surface_fit', [], signalOf(options));
        return this;
    }

    /** orient() on a worker thread. */
    async orientAsync(options) {
        await this.#stageAsync('surface_orient', [], signalOf(options));
        return this;
    }

    /** polygonize() on a worker thread; options as polygonize's, plus `signal`. */
    async polygonizeAsync(options = {}) {
        const { signal, ...overrides } = options ?? {};
        signalOf({ signal });
        return this.#polygonizeWith(overrides, (out) => this.#stageAsync('surface_polygonize', [out], signal));
    }

    // Polygonize with per-call parameters, restored afterwards. run(out) runs the stage
    // (returning nothing, or a promise for the async stage); the mesh it leaves in out[0]
    // is copied out and freed. A mesh completed while onProgress threw at the stage's very
    // end is freed too.
    #polygonizeWith(overrides, run) {
        const out = [null];
        const saved = this.#overrideForPolygonize(overrides);
        const done = () => {
            this.#restoreParams(saved);
            return takeMesh(out[0]);
        };
        const failed = (err) => {
            if (out[0] !== null) lib().mesh_destroy(out[0]);
            this.#restoreParams(saved);
            throw err;
        };
        let pending;
        try {
            pending = run(out);
        } catch (err) {
            failed(err);
        }
        return pending instanceof Promise ? pending.then(done, failed) : done();
    }

    // Sets polygonize's per-call parameters; returns the values to restore.
    #overrideForPolygonize(options) {
        const overrides = Object.entries(options ?? {}).filter(([, v]) => v !== undefined);
        for (const [name] of overrides)
            if (name !== 'resolution' && name !== 'level')
                throw invalidArgument(`unknown polygonize option '${name}' (options: resolution, level)`);
        const saved = overrides.map(([name]) => [name, this.getParam(name)]);
        try {
            for (const [name, value] of overrides) this.setParam(name, value);
        } catch (err) {
            this.#restoreParams(saved);
            throw err;
        }
        return saved;
    }

    #restoreParams(saved) {
        if (!this.closed) for (const [name, value] of saved) this.setParam(name, value);
    }

    // The progress callback of one stage run, or null when the run needs none. It forwards
    // to onProgress and returns 1 (cancel) once onProgress has thrown or returned false,
    // close() was called, or run.signal has aborted.
    #progressCallback(n, run, always) {
        const user = this.onProgress;
        if (user !== null && user !== undefined && typeof user !== 'function')
            throw invalidArgument('onProgress must be a function');
        if (!user && !always) return null;
        return koffi.register((_user, stage, fraction) => {
            if (run.thrown !== null || this.#closeRequested || run.signal?.aborted) return 1;
            if (!user) return 0;
            try {
                const result = user(STAGES[stage] ?? String(stage), fraction);
                return result === false || this.#closeRequested ? 1 : 0;
            } catch (err) {
                run.thrown = { err };
                return 1;
            }
        }, n.progressType);
    }

    // Runs one stage with the progress callback registered for its duration only.
    #stage(call) {
        const h = this.#handle();
        const n = lib();
        const run = { thrown: null, signal: null };
        const callback = this.#progressCallback(n, run, false);
        let error = null;
        try {
            if (callback !== null) check(n.surface_set_progress(h, callback, null), h);
            this.#busy = true;
            try {
                const status = call(h);
                if (status !== 0) error = failure(status, h); // before any other gmpu call
            } finally {
                this.#busy = false;
            }
        } finally {
            if (callback !== null) {
                n.surface_set_progress(h, null, null);
                koffi.unregister(callback);
            }
        }
        this.#endStage(run, error);
    }

    // The async twin of #stage: the C call runs on a koffi worker thread; koffi queues its
    // progress callbacks to this thread, so they run whenever the event loop is free. The
    // callback is always installed, so that close() and the signal can cancel.
    async #stageAsync(name, args, signal) {
        const h = this.#handle();
        const n = lib();
        const stage = name.replace('surface_', '');
        if (signal?.aborted) throw cancelledBy(signal, `${stage} not started: the signal was already aborted`);
        const run = { thrown: null, signal };
        const callback = this.#progressCallback(n, run, true);
        let status;
        try {
            check(n.surface_set_progress(h, callback, null), h);
            this.#running = true;
            try {
                status = await new Promise((resolve, reject) =>
                    n[name].async(h, ...args, (err, value) => (err ? reject(err) : resolve(value))));
            } finally {
                this.#running = false;
            }
        } finally {
            n.surface_set_progress(h, null, null);
            koffi.unregister(callback);
        }
        let error = null;
        if (status !== 0) {
            // gmpu_last_error() is the worker thread's; the surface keeps the stage's message.
            error = failure(status, null, n.surface_last_error(h));
            if (status === Status.GMPU_ERROR_CANCELLED && signal?.aborted && run.thrown === null)
                error = cancelledBy(signal, `${stage} cancelled by its AbortSignal`);
        }
        this.#endStage(run, error);
    }

    // After a stage: a close() requested meanwhile happens now; then the error, if any.
    #endStage(run, error) {
        if (this.#closeRequested) {
            this.#closeRequested = false;
            this.close();
        }
        if (run.thrown !== null) throw run.thrown.err;
        if (error !== null) throw error;
    }
}

// options.signal, checked: an AbortSignal or nothing.
function signalOf(options) {
    const signal = options?.signal;
    if (signal === undefined || signal === null) return null;
    if (typeof signal !== 'object' || typeof signal.aborted !== 'boolean')
        throw invalidArgument('signal must be an AbortSignal');
    return signal;
}

// The rejection of a stage cancelled through its AbortSignal: GMPU_ERROR_CANCELLED, with
// the signal's reason as the cause.
function cancelledBy(signal, what) {
    return new GmpuError('GMPU_ERROR_CANCELLED', `GMPU_ERROR_CANCELLED: ${what}`, { cause: signal.reason });
}

if (typeof Symbol.dispose === 'symbol') {
    Surface.prototype[Symbol.dispose] = function dispose() {
        this.close();
    };
}
if (typeof Symbol.asyncDispose === 'symbol') {
    Surface.prototype[Symbol.asyncDispose] = async function asyncDispose() {
        this.close();
    };
}

function applyOptions(surface, options, extra) {
    if (options === null || typeof options !== 'object') throw invalidArgument('options must be an object');
    for (const [key, value] of Object.entries(options)) {
        if (value === undefined || extra.includes(key)) continue;
        if (key === 'onProgress') {
            if (value !== null && typeof value !== 'function') throw invalidArgument('onProgress must be a function');
            surface.onProgress = value;
        } else if (paramsByName().has(key)) {
            surface.setParam(key, value);
        } else {
            throw invalidArgument(`unknown option '${key}' (options: ${[...paramsByName().keys(), 'onProgress', ...extra].join(', ')})`);
        }
    }
}

// Copies a native mesh into JS arrays and frees it.
function takeMesh(ptr) {
    const n = lib();
    try {
        const vertexCount = Number(n.mesh_vertex_count(ptr));
        const triangleCount = Number(n.mesh_triangle_count(ptr));
        return {
            vertices: copyArray(n.mesh_vertices(ptr), 'double', 3 * vertexCount),
            faces: copyArray(n.mesh_triangles(ptr), 'uint32_t', 3 * triangleCount),
            normals: copyArray(n.mesh_normals(ptr), 'double', 3 * vertexCount),
            confidence: copyArray(n.mesh_confidence(ptr), 'double', vertexCount),
            colors: copyArray(n.mesh_colors(ptr), 'uint8_t', 3 * vertexCount),
        };
    } finally {
        n.mesh_destroy(ptr);
    }
}

// An optional per-vertex array of a mesh object: null when absent, else `type` of `length`.
function vertexArray(value, what, Type, length) {
    if (value === undefined || value === null) return null;
    const data = value instanceof Type ? value : ArrayBuffer.isView(value) || Array.isArray(value) ? Type.from(value) : null;
    if (data === null) throw invalidArgument(`${what} must be a ${Type.name} or an array of numbers; got ${describe(value)}`);
    if (data.length !== length) throw jsError('GMPU_ERROR_INVALID_INPUT', `${what} has ${data.length} values, expected ${length}`);
    return data;
}

// A native mesh from { vertices, faces, normals?, confidence?, colors? } (gmpu_mesh_create_with,
// so what writeMesh and simplifyMesh get keeps every attribute); the caller destroys it.
function nativeMesh(mesh) {
    if (mesh === null || typeof mesh !== 'object') throw invalidArgument('mesh must be an object { vertices, faces }');
    const { data: vertices, count } = toXyz(mesh.vertices, 'mesh.vertices', { allowF32: false });
    const faces = toFaces(mesh.faces, 'mesh.faces');
    const normals = vertexArray(mesh.normals, 'mesh.normals', Float64Array, 3 * count);
    const confidence = vertexArray(mesh.confidence, 'mesh.confidence', Float64Array, count);
    const colors = vertexArray(mesh.colors, 'mesh.colors', Uint8Array, 3 * count);
    const out = [null];
    const some = (a) => (count && a !== null ? a : null);
    check(lib().mesh_create_with(count ? vertices : null, count, faces.length ? faces : null, faces.length / 3,
        some(normals), some(confidence), some(colors), out));
    return out[0];
}

// ---- one call ----------------------------------------------------------------------------

// A path is read here (not by Surface) so that its colours, if any, reach the mesh.
const cloudOf = (points) => (typeof points === 'string' || points instanceof URL ? readPoints(points) : points);
// Coloured points give a coloured mesh (each vertex: its nearest point's colour), as the C CLI does.
const coloured = (mesh, cloud) => (cloud?.colors instanceof Uint8Array ? colorMesh(mesh, cloud) : mesh);

/**
 * Unoriented points in, closed outward-facing mesh out: set points → fit → orient →
 * polygonize with the given parameters. Returns { vertices, faces, normals, confidence,
 * colors }.
 */
export function reconstruct(points, options = {}) {
    if (!isPointSource(points)) throw invalidArgument(`points must be point coordinates, a PointCloud or a path; got ${describe(points)}`);
    const cloud = cloudOf(points);
    const surface = new Surface(cloud, options);
    try {
        return coloured(surface.fit().orient().polygonize(), cloud);
    } finally {
        surface.close();
    }
}

/**
 * reconstruct() without blocking the event loop: fit, orient and polygonize run on a
 * worker thread. options.signal (an AbortSignal) cancels; the promise then rejects with
 * GMPU_ERROR_CANCELLED (cause: the signal's reason). A path is read synchronously first.
 */
export async function reconstructAsync(points, options = {}) {
    if (!isPointSource(points)) throw invalidArgument(`points must be point coordinates, a PointCloud or a path; got ${describe(points)}`);
    if (options === null || typeof options !== 'object') throw invalidArgument('options must be an object');
    const { signal, ...rest } = options;
    signalOf({ signal });
    const cloud = cloudOf(points);
    const surface = new Surface(cloud, rest);
    try {
        await surface.fitAsync({ signal });
        await surface.orientAsync({ signal });
        return coloured(await surface.polygonizeAsync({ signal }), cloud);
    } finally {
        surface.close();
    }
}

// ---- files -------------------------------------------------------------------------------

/**
 * Reads a point cloud (.ply, .xyz, .txt, .off, .obj): { positions, normals | null, colors |
 * null, count } (gmpu_points_read_with). options.maxMemory: the budget in bytes (0 or absent:
 * half the physical memory); options.onProgress(stage 'read', fraction): returning false or
 * throwing cancels (GMPU_ERROR_CANCELLED; a throw is rethrown), as for the stages.
 */
export function readPoints(file, options = {}) {
    const p = toPath(file);
    if (options === null || typeof options !== 'object') throw invalidArgument('options must be an object');
    const { maxMemory = 0, onProgress = null, ...unknown } = options;
    const extra = Object.keys(unknown);
    if (extra.length) throw invalidArgument(`unknown option '${extra[0]}' (options: maxMemory, onProgress)`);
    if (typeof maxMemory !== 'number') throw invalidArgument(`maxMemory must be a number, got ${describe(maxMemory)}`);
    if (onProgress !== null && typeof onProgress !== 'function') throw invalidArgument('onProgress must be a function');
    const n = lib();
    const out = [null];
    let thrown = null;
    const callback = onProgress === null ? null : koffi.register((_user, stage, fraction) => {
        if (thrown !== null) return 1;
        try {
            return onProgress(STAGES[stage] ?? String(stage), fraction) === false ? 1 : 0;
        } catch (err) {
            thrown = { err };
            return 1;
        }
    }, n.progressType);
    let status;
    try {
        status = n.points_read_with(p, maxMemory, callback, null, out);
    } finally {
        if (callback !== null) koffi.unregister(callback);
    }
    if (thrown !== null) throw thrown.err;
    check(status);
    const ptr = out[0];
    try {
        const count = Number(n.points_count(ptr));
        return {
            positions: copyArray(n.points_positions(ptr), 'double', 3 * count),
            normals: copyArray(n.points_normals(ptr), 'double', 3 * count),
            colors: copyArray(n.points_colors(ptr), 'uint8_t', 3 * count),
            count,
        };
    } finally {
        n.points_destroy(ptr);
    }
}

/**
 * Writes a mesh { vertices, faces, normals?, confidence?, colors? } (.ply binary
 * little-endian, .obj, .off, .stl, .glb; from the extension), atomically, with the
 * attributes it has, as the C CLI writes them.
 */
export function writeMesh(file, mesh) {
    const p = toPath(file);
    const made = nativeMesh(mesh);
    try {
        check(lib().mesh_write(made, p));
    } finally {
        lib().mesh_destroy(made);
    }
}

/**
 * A copy of mesh whose every vertex takes the colour of the nearest point of cloud
 * { positions, colors } (as readPoints gives a coloured .ply; gmpu_mesh_color_from_points).
 */
export function colorMesh(mesh, cloud) {
    if (cloud === null || typeof cloud !== 'object') throw invalidArgument('cloud must be an object { positions, colors }');
    const { data: positions, count } = toXyz(cloud.positions, 'cloud.positions', { allowF32: false });
    const colors = vertexArray(cloud.colors, 'cloud.colors', Uint8Array, 3 * count);
    if (colors === null) throw invalidArgument('cloud has no colors');
    const n = lib();
    const points = [null];
    check(n.points_create_with(count ? positions : null, null, count ? colors : null, count, points));
    try {
        const made = nativeMesh(mesh);
        try {
            const out = [null];
            check(n.mesh_color_from_points(made, points[0], out));
            return takeMesh(out[0]);
        } finally {
            n.mesh_destroy(made);
        }
    } finally {
        n.points_destroy(points[0]);
    }
}

/**
 * Decimates a mesh { vertices, faces, confidence?, colors? } (gmpu_mesh_simplify): at most
 * options.targetTriangles triangles (0 or absent: no count target), the surface moved by at
 * most options.targetError × the bounding-box diagonal (default 1: no bound). Topology is
 * kept (closed, manifold, components, genus), so it may stop above the count. Returns a new
 * { vertices, faces, normals, confidence, colors } with recomputed normals (confidence and
 * colors carried when the input has them, else null).
 */
export function simplifyMesh(mesh, options = {}) {
    if (mesh === null || typeof mesh !== 'object') throw invalidArgument('mesh must be an object { vertices, faces }');
    if (options === null || typeof options !== 'object') throw invalidArgument('options must be an object');
    const { targetTriangles = 0, targetError = 1, ...unknown } = options;
    const extra = Object.keys(unknown);
    if (extra.length) throw invalidArgument(`unknown option '${extra[0]}' (options: targetTriangles, targetError)`);
    if (!Number.isSafeInteger(targetTriangles) || targetTriangles < 0)
        throw invalidArgument(`targetTriangles must be a non-negative integer, got ${describe(targetTriangles)}`);
    if (typeof targetError !== 'number') throw invalidArgument(`targetError must be a number, got ${describe(targetError)}`);
    const n = lib();
    const made = nativeMesh(mesh);
    try {
        const out = [null];
        check(n.mesh_simplify(made, targetTriangles, targetError, out));
        return takeMesh(out[0]);
    } finally {
        n.mesh_destroy(made);
    }
}

/** Writes points and optional normals (.ply binary little-endian, or .xyz), atomically. */
export function writePoints(file, cloud) {
    const p = toPath(file);
    if (cloud === null || typeof cloud !== 'object') throw invalidArgument('cloud must be an object { positions, normals? }');
    const { data: positions, count } = toXyz(cloud.positions, 'positions', { allowF32: false });
    let normals = null;
    if (cloud.normals !== undefined && cloud.normals !== null) {
        const nn = toXyz(cloud.normals, 'normals', { allowF32: false });
        if (nn.count !== count)
            throw jsError('GMPU_ERROR_INVALID_INPUT', `${nn.count} normals for ${count} points`);
        normals = nn.data;
    }
    const n = lib();
    const out = [null];
    check(n.points_create(count ? positions : null, count ? normals : null, count, out));
    try {
        check(n.points_write(out[0], p));
    } finally {
        n.points_destroy(out[0]);
    }
}

// ---- library -----------------------------------------------------------------------------

/** Version of the loaded C library and where it was loaded from. */
export function libraryInfo() {
    const n = lib();
    return {
        version: n.version_string(),
        versionNumber: n.version_number(),
        abiVersion: n.abi_version(),
        path: n.path,
    };
}
