// The Node.js section of README.md: its JavaScript block runs as written, with 'gmpu'
// resolved to this checkout's package.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import { assertWatertight, packageUrl, readPly, repoRoot, tempDir } from './helpers.mjs';

export function readmeNodeBlocks() {
    const readme = fs.readFileSync(path.join(repoRoot, 'README.md'), 'utf8');
    const m = readme.match(/<!-- node:begin -->([\s\S]*?)<!-- node:end -->/);
    assert.ok(m, 'README.md has no <!-- node:begin --> ... <!-- node:end --> section');
    return [...m[1].matchAll(/```(js|javascript|mjs)\n([\s\S]*?)```/g)].map((b) => b[2]);
}

test('the README Node.js example runs', (t) => {
    const blocks = readmeNodeBlocks();
    assert.equal(blocks.length, 1, 'exactly one JavaScript block in the Node.js section');
    const code = blocks[0];
    assert.match(code, /from 'gmpu'/, 'the example imports the package by its name');
    const runnable = code.replaceAll("from 'gmpu'", `from ${JSON.stringify(packageUrl)}`);

    // Run it from a scratch directory that sees the repo's examples/ (for the input path).
    const dir = tempDir(t);
    fs.symlinkSync(path.join(repoRoot, 'examples'), path.join(dir, 'examples'));
    fs.writeFileSync(path.join(dir, 'readme.mjs'), runnable);
    const r = spawnSync(process.execPath, ['readme.mjs'], { cwd: dir, encoding: 'utf8' });
    assert.equal(r.status, 0, `README example failed:\n${r.stderr}`);

    assert.match(r.stdout, /^fit done\norient done\npolygonize done\n\d+ vertices, \d+ triangles\n/);
    const [, vertices, triangles] = r.stdout.match(/(\d+) vertices, (\d+) triangles/).map(Number);
    const mesh = readPly(path.join(dir, 'bunny_mesh.ply'));
    assert.equal(mesh.vertices.length / 3, vertices);
    assert.equal(mesh.faces.length / 3, triangles);
    assertWatertight(mesh, 'README mesh');
    assert.match(r.stdout, new RegExp(`\nasync: ${triangles} triangles\n`), 'reconstructAsync gave another mesh');
    const f = r.stdout.match(/f = (-?[\d.]+) inside, (-?[\d.]+) outside/);
    assert.ok(f, r.stdout);
    assert.ok(Number(f[1]) > 0 && Number(f[2]) < 0, `signs of f: ${f[0]}`);
});
