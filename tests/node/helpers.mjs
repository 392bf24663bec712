// Shared helpers for the Node tests: paths, a PLY reader independent of gmpu, mesh checks.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

export const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
export const packageDir = path.join(repoRoot, 'bindings', 'node');
export const packageUrl = pathToFileURL(path.join(packageDir, 'index.js')).href;
export const examplesDir = path.join(repoRoot, 'examples', 'node');
export const samplePly = path.join(repoRoot, 'examples', 'data', 'bunny.ply');
export const cliPath = path.join(repoRoot, 'build', 'examples', 'gmpu-reconstruct');

/** The test data directory: $GMPU_TEST_DATA, or tests/data of this checkout. Fails loudly if absent. */
export function testData() {
    const dir = process.env.GMPU_TEST_DATA || path.resolve(repoRoot, 'tests', 'data');
    assert.ok(
        fs.existsSync(path.join(dir, 'clouds')),
        `test data not found at ${dir} (it ships in tests/data; GMPU_TEST_DATA overrides it)`,
    );
    return dir;
}

/** A fresh temporary directory, removed when the process exits. */
export function tempDir(t) {
    const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'gmpu-node-test-'));
    const cleanup = () => fs.rmSync(dir, { recursive: true, force: true });
    if (t?.after) t.after(cleanup);
    else process.on('exit', cleanup);
    return dir;
}

const PLY_TYPES = {
    char: ['getInt8', 1], int8: ['getInt8', 1],
    uchar: ['getUint8', 1], uint8: ['getUint8', 1],
    short: ['getInt16', 2], int16: ['getInt16', 2],
    ushort: ['getUint16', 2], uint16: ['getUint16', 2],
    int: ['getInt32', 4], int32: ['getInt32', 4],
    uint: ['getUint32', 4], uint32: ['getUint32', 4],
    float: ['getFloat32', 4], float32: ['getFloat32', 4],
    double: ['getFloat64', 8], float64: ['getFloat64', 8],
};

/**
 * Reads a binary little-endian PLY (written independently of gmpu's reader): vertex
 * positions and normals as Float64Array (exact: float32 widened, double as stored),
 * triangles as Uint32Array, and the header.
 */
export function readPly(file) {
    const bytes = fs.readFileSync(file);
    const end = bytes.indexOf('end_header\n');
    assert.ok(end > 0, `${file}: no end_header`);
    const header = bytes.subarray(0, end).toString('latin1').split('\n');
    assert.equal(header[0], 'ply');
    assert.equal(header[1], 'format binary_little_endian 1.0', `${file}: only binary little-endian is read here`);
    const elements = [];
    for (const line of header) {
        const w = line.trim().split(/\s+/);
        if (w[0] === 'element') elements.push({ name: w[1], count: Number(w[2]), props: [] });
        else if (w[0] === 'property' && w[1] === 'list') elements.at(-1).props.push({ list: true, countType: w[2], type: w[3], name: w[4] });
        else if (w[0] === 'property') elements.at(-1).props.push({ type: w[1], name: w[2] });
    }
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    let off = end + 'end_header\n'.length;
    const read = (type) => {
        const [getter, size] = PLY_TYPES[type];
        const v = view[getter](off, true);
        off += size;
        return v;
    };
    const out = { header: header.join('\n'), vertices: null, normals: null, faces: null };
    for (const el of elements) {
        if (el.name === 'vertex') {
            const names = el.props.map((p) => p.name);
            const hasNormals = ['nx', 'ny', 'nz'].every((n) => names.includes(n));
            out.vertices = new Float64Array(3 * el.count);
            if (hasNormals) out.normals = new Float64Array(3 * el.count);
            const pos = ['x', 'y', 'z'], nrm = ['nx', 'ny', 'nz'];
            for (let i = 0; i < el.count; ++i)
                for (const p of el.props) {
                    const v = read(p.type);
                    const k = pos.indexOf(p.name);
                    if (k >= 0) out.vertices[3 * i + k] = v;
                    const j = nrm.indexOf(p.name);
                    if (j >= 0 && hasNormals) out.normals[3 * i + j] = v;
                }
        } else if (el.name === 'face') {
            out.faces = new Uint32Array(3 * el.count);
            for (let i = 0; i < el.count; ++i) {
                const p = el.props[0];
                const n = read(p.countType);
                assert.equal(n, 3, `${file}: face ${i} has ${n} vertices`);
                for (let k = 0; k < 3; ++k) out.faces[3 * i + k] = read(p.type);
            }
        } else {
            for (let i = 0; i < el.count; ++i) for (const p of el.props) read(p.type);
        }
    }
    assert.equal(off, bytes.length, `${file}: trailing bytes after the last element`);
    return out;
}

/**
 * Mesh checks done in JS: every undirected edge is used by exactly two triangles, each
 * directed edge once (consistent winding), no degenerate index triple, and the enclosed
 * signed volume. Returns { edges, boundaryOrNonManifold, inconsistent, volume }.
 */
export function meshTopology(vertices, faces) {
    const nv = vertices.length / 3;
    const undirected = new Map();
    const directed = new Set();
    let inconsistent = 0, degenerate = 0;
    for (let t = 0; t < faces.length; t += 3) {
        const tri = [faces[t], faces[t + 1], faces[t + 2]];
        if (tri[0] === tri[1] || tri[1] === tri[2] || tri[0] === tri[2]) ++degenerate;
        for (let k = 0; k < 3; ++k) {
            const a = tri[k], b = tri[(k + 1) % 3];
            assert.ok(a < nv && b < nv, `triangle ${t / 3} uses vertex out of range`);
            const key = Math.min(a, b) * nv + Math.max(a, b);
            undirected.set(key, (undirected.get(key) ?? 0) + 1);
            const dkey = a * nv + b;
            if (directed.has(dkey)) ++inconsistent;
            directed.add(dkey);
        }
    }
    let bad = 0;
    for (const count of undirected.values()) if (count !== 2) ++bad;
    let volume = 0;
    for (let t = 0; t < faces.length; t += 3) {
        const [a, b, c] = [faces[t] * 3, faces[t + 1] * 3, faces[t + 2] * 3];
        const [ax, ay, az] = [vertices[a], vertices[a + 1], vertices[a + 2]];
        const [bx, by, bz] = [vertices[b], vertices[b + 1], vertices[b + 2]];
        const [cx, cy, cz] = [vertices[c], vertices[c + 1], vertices[c + 2]];
        volume += (ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)) / 6;
    }
    return { edges: undirected.size, boundaryOrNonManifold: bad, inconsistent, degenerate, volume };
}

/** Asserts the mesh is closed, edge-manifold, consistently and outward wound. */
export function assertWatertight(mesh, what = 'mesh') {
    assert.ok(mesh.faces.length > 0, `${what} has no triangles`);
    const topo = meshTopology(mesh.vertices, mesh.faces);
    assert.equal(topo.boundaryOrNonManifold, 0, `${what}: ${topo.boundaryOrNonManifold} edges not used exactly twice`);
    assert.equal(topo.inconsistent, 0, `${what}: ${topo.inconsistent} directed edges used twice (inconsistent winding)`);
    assert.equal(topo.degenerate, 0, `${what}: ${topo.degenerate} triangles repeat a vertex`);
    assert.ok(topo.volume > 0, `${what}: enclosed volume ${topo.volume} is not positive (inside out)`);
    return topo;
}

/** Share of points whose normal has a positive dot product with the reference normal. */
export function orientationAccuracy(normals, reference) {
    assert.equal(normals.length, reference.length);
    let good = 0;
    for (let i = 0; i < normals.length; i += 3) {
        const d = normals[i] * reference[i] + normals[i + 1] * reference[i + 1] + normals[i + 2] * reference[i + 2];
        if (d > 0) ++good;
    }
    return good / (normals.length / 3);
}

/** n points on a sphere (Fibonacci lattice), as a Float64Array, and their outward normals. */
export function spherePoints(n, radius = 1, center = [0, 0, 0]) {
    const xyz = new Float64Array(3 * n), normals = new Float64Array(3 * n);
    const golden = Math.PI * (3 - Math.sqrt(5));
    for (let i = 0; i < n; ++i) {
        const y = 1 - (2 * (i + 0.5)) / n;
        const r = Math.sqrt(1 - y * y);
        const phi = golden * i;
        const nrm = [Math.cos(phi) * r, y, Math.sin(phi) * r];
        for (let k = 0; k < 3; ++k) {
            normals[3 * i + k] = nrm[k];
            xyz[3 * i + k] = center[k] + radius * nrm[k];
        }
    }
    return { xyz, normals };
}

/** Runs the C CLI; throws with its stderr on failure. */
export function runCli(args) {
    assert.ok(fs.existsSync(cliPath), `${cliPath} missing: run \`make build\` first`);
    return execFileSync(cliPath, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}

/** n points on a torus (major radius R, minor r) around the z axis — not a quadric, so fit subdivides. */
export function torusPoints(n, R = 1, r = 0.35) {
    const xyz = new Float64Array(3 * n), normals = new Float64Array(3 * n);
    const golden = Math.PI * (3 - Math.sqrt(5));
    for (let i = 0; i < n; ++i) {
        const u = (2 * Math.PI * (i + 0.5)) / n; // around the axis
        const v = golden * i * 37; // around the tube, scrambled
        const nrm = [Math.cos(v) * Math.cos(u), Math.cos(v) * Math.sin(u), Math.sin(v)];
        const c = [R * Math.cos(u), R * Math.sin(u), 0];
        for (let k = 0; k < 3; ++k) {
            normals[3 * i + k] = nrm[k];
            xyz[3 * i + k] = c[k] + r * nrm[k];
        }
    }
    return { xyz, normals };
}
