// npm pack / npm publish (prepack): copies this tree's libgmpu.so.1 (`make build` at the
// root) into native/<platform>-<arch>/, so the tarball works in an empty folder with no
// GMPU_LIBRARY. `postpack` (with --remove) deletes the copy again, so that the source tree
// keeps loading build/lib's library, the one that `make build` refreshes.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const packageDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const nativeDir = path.join(packageDir, 'native');

if (process.argv.includes('--remove')) {
    fs.rmSync(nativeDir, { recursive: true, force: true });
    process.exit(0);
}
if (process.platform !== 'linux') {
    console.error(`bundle-library: only linux builds are bundled (this is ${process.platform})`);
    process.exit(1);
}
const built = path.resolve(packageDir, '..', '..', 'build', 'lib', 'libgmpu.so.1');
if (!fs.existsSync(built)) {
    console.error(`bundle-library: ${built} is missing: run \`make build\` at the root of the gmpu tree first`);
    process.exit(1);
}
const target = path.join(nativeDir, `${process.platform}-${process.arch}`);
fs.mkdirSync(target, { recursive: true });
fs.copyFileSync(fs.realpathSync(built), path.join(target, 'libgmpu.so.1'));  // the file, not the symlink
