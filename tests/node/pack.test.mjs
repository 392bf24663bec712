// The package as users get it: `npm pack` makes a tarball with libgmpu inside
// (native/linux-x64/), installed into an empty folder it works with no GMPU_LIBRARY; and
// Surface's [Symbol.dispose] / [Symbol.asyncDispose] close it.
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';

import { packageDir, packageUrl, samplePly, spherePoints, tempDir } from './helpers.mjs';

const gmpu = await import(packageUrl);

function run(cmd, args, options) {
    const r = spawnSync(cmd, args, { encoding: 'utf8', ...options });
    assert.equal(r.status, 0, `${cmd} ${args.join(' ')} failed:\n${r.stdout}${r.stderr}`);
    return r.stdout;
}

test('npm pack: the tarball carries the library and works from an empty folder', { skip: process.platform !== 'linux' }, (t) => {
    const dir = tempDir(t);
    const tarball = path.join(dir, run('npm', ['pack', '--silent', '--pack-destination', dir], { cwd: packageDir }).trim());
    assert.ok(!fs.existsSync(path.join(packageDir, 'native')), 'postpack leaves no copy in the source tree');
    const listing = run('tar', ['tzf', tarball]);
    assert.match(listing, new RegExp(`package/native/linux-${process.arch}/libgmpu\\.so\\.1`));

    const app = path.join(dir, 'app');
    fs.mkdirSync(app);
    fs.writeFileSync(path.join(app, 'package.json'), '{ "name": "app", "private": true, "type": "module" }\n');
    // No network: koffi, the one dependency, is packed from the copy `npm ci` installed here.
    const koffi = path.join(dir, run('npm', ['pack', '--silent', '--pack-destination', dir],
        { cwd: path.join(packageDir, 'node_modules', 'koffi') }).trim());
    run('npm', ['install', '--offline', '--no-audit', '--no-fund', '--loglevel=error', koffi, tarball], { cwd: app });
    fs.writeFileSync(path.join(app, 'main.mjs'), `
import { reconstruct, readPoints, writeMesh, libraryInfo } from 'gmpu';
const mesh = reconstruct(readPoints(process.argv[2]).positions, { resolution: 24 });
writeMesh('out.glb', mesh);
console.log(JSON.stringify({ path: libraryInfo().path, faces: mesh.faces.length / 3 }));
`);
    const env = { ...process.env };
    delete env.GMPU_LIBRARY;
    delete env.LD_LIBRARY_PATH;
    const out = JSON.parse(run(process.execPath, ['main.mjs', samplePly], { cwd: app, env }));
    assert.equal(out.path, path.join(app, 'node_modules', 'gmpu', 'native', `linux-${process.arch}`, 'libgmpu.so.1'));
    assert.ok(out.faces > 0);
    assert.equal(fs.readFileSync(path.join(app, 'out.glb')).subarray(0, 4).toString(), 'glTF');
});

test('Symbol.dispose and Symbol.asyncDispose close the surface', async () => {
    const s = new gmpu.Surface(spherePoints(500).xyz);
    s[Symbol.dispose]();
    assert.ok(s.closed);
    const a = new gmpu.Surface(spherePoints(500).xyz);
    await a[Symbol.asyncDispose]();
    assert.ok(a.closed);
});
