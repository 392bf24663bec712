#!/usr/bin/env node
// reconstruct.mjs — unoriented point cloud in, watertight oriented mesh out (Node.js).
//
//   node reconstruct.mjs INPUT -o OUTPUT [--normals-out POINTS.ply] [--error E] [--max-depth D]
//                        [--resolution R] [--level L] [--threads T] [--noise-scale S]
//                        [--max-memory BYTES] [--sharp] [--quiet]
//
// The Node twin of the C CLI build/examples/gmpu-reconstruct: the same flags and defaults, so
// the same command line gives the same mesh. INPUT: .ply .xyz .txt .off .obj; OUTPUT: .ply
// .obj .off .stl .glb.
// Exit status 0 on success, 1 on a failure (one line on stderr), 2 on bad usage.
import { parseArgs } from 'node:util';

import { GmpuError, readPoints, Surface, writeMesh, writePoints } from 'gmpu';

const usage = `usage: node reconstruct.mjs INPUT -o OUTPUT [--normals-out POINTS.ply] [--error E]
                          [--max-depth D] [--resolution R] [--level L] [--threads T]
                          [--noise-scale S] [--max-memory BYTES] [--sharp] [--quiet]`;

function parse() {
    const numeric = ['error', 'max-depth', 'resolution', 'level', 'threads', 'noise-scale', 'max-memory'];
    let parsed;
    try {
        parsed = parseArgs({
            allowPositionals: true,
            options: {
                output: { type: 'string', short: 'o' },
                'normals-out': { type: 'string' },
                sharp: { type: 'boolean' },
                quiet: { type: 'boolean', short: 'q' },
                help: { type: 'boolean', short: 'h' },
                ...Object.fromEntries(numeric.map((name) => [name, { type: 'string' }])),
            },
        });
    } catch (err) {
        return { problem: err.message };
    }
    const { values, positionals } = parsed;
    if (values.help) return { help: true };
    if (positionals.length !== 1) return { problem: positionals.length < 1 ? 'missing INPUT' : `unexpected argument '${positionals[1]}'` };
    if (values.output === undefined) return { problem: 'missing -o OUTPUT' };
    const options = {};
    const camel = (name) => name.replace(/-(\w)/g, (_, c) => c.toUpperCase());
    for (const name of numeric) {
        if (values[name] === undefined) continue;
        const v = Number(values[name]);
        if (values[name].trim() === '' || !Number.isFinite(v)) return { problem: `--${name} needs a number, got '${values[name]}'` };
        options[camel(name)] = v;
    }
    if (values.sharp) options.sharpFeatures = true;  // as the C CLI: otherwise the library's default
    return { input: positionals[0], output: values.output, normalsOut: values['normals-out'], quiet: !!values.quiet, options };
}

const args = parse();
if (args.help) {
    console.log(usage);
    process.exit(0);
}
if (args.problem) {
    console.error(`reconstruct.mjs: ${args.problem}\n${usage}`);
    process.exit(2);
}

let lastStage = null;
const onProgress = args.quiet
    ? null
    : (stage) => {
        if (stage !== lastStage) console.error(`gmpu: ${stage}...`);
        lastStage = stage;
    };

let surface = null;
try {
    const cloud = readPoints(args.input);
    surface = new Surface(cloud, { ...args.options, onProgress });
    const mesh = surface.fit().orient().polygonize();
    writeMesh(args.output, mesh);
    if (args.normalsOut) writePoints(args.normalsOut, { positions: cloud.positions, normals: surface.normals() });
    if (!args.quiet) {
        const s = surface.stats();
        console.error(
            `gmpu: ${cloud.count} points, ${s.cells} cells (${s.leaves} leaves, depth ${s.depth}), ` +
                `${s.components} component${s.components === 1 ? '' : 's'}\n` +
                `gmpu: mesh ${mesh.vertices.length / 3} vertices, ${mesh.faces.length / 3} triangles ` +
                `at resolution ${s.resolution} -> ${args.output}`,
        );
    }
} catch (err) {
    if (!(err instanceof GmpuError)) throw err;
    console.error(`reconstruct.mjs: ${err.message}`);
    process.exitCode = 1;
} finally {
    surface?.close();
}
