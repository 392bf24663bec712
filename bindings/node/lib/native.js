// Loads libgmpu with koffi and declares the C ABI of include/gmpu/gmpu.h.
//
// Lookup order: $GMPU_LIBRARY if set (and then only that file), else the copy inside the
// package (native/<platform>-<arch>/, put there by `npm pack`), else the meson build
// directory of the source tree this package sits in (../../build/lib), else the system's
// dynamic loader (libgmpu.so.1 on its search path). The library is loaded on first use, so
// importing the package never fails; the first call does, with the list of places tried.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import koffi from 'koffi';

/** The ABI this package was written against (GMPU_ABI_VERSION, the SONAME's number). */
export const ABI_VERSION = 1;

const packageRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');

function sonames() {
    if (process.platform === 'darwin') return [`libgmpu.${ABI_VERSION}.dylib`];
    if (process.platform === 'win32') return ['gmpu.dll', `libgmpu-${ABI_VERSION}.dll`];
    return [`libgmpu.so.${ABI_VERSION}`];
}

/** Where the library is looked for, in order: [{ path, source }]. */
export function candidates(env = process.env) {
    if (env.GMPU_LIBRARY) return [{ path: env.GMPU_LIBRARY, source: 'GMPU_LIBRARY' }];
    const list = [];
    for (const name of sonames())
        list.push({ path: path.join(packageRoot, 'native', `${process.platform}-${process.arch}`, name), source: 'inside the package' });
    for (const name of sonames())
        list.push({ path: path.resolve(packageRoot, '..', '..', 'build', 'lib', name), source: 'meson build directory' });
    for (const name of sonames()) list.push({ path: name, source: 'system library path' });
    return list;
}

let native = null;

// Thrown when no usable library was found; index.js turns it into a GmpuError.
export class LibraryError extends Error {
    constructor(code, message) {
        super(message);
        this.code = code;
    }
}

function open() {
    const tried = [];
    for (const c of candidates()) {
        if (path.isAbsolute(c.path) && !fs.existsSync(c.path)) {
            tried.push(`  ${c.path} (${c.source}): no such file`);
            continue;
        }
        try {
            return { lib: koffi.load(c.path), path: c.path };
        } catch (err) {
            tried.push(`  ${c.path} (${c.source}): ${String(err.message).split('\n')[0]}`);
        }
    }
    throw new LibraryError(
        'GMPU_LIBRARY_NOT_FOUND',
        'GMPU_LIBRARY_NOT_FOUND: cannot load the gmpu C library (build it with `make build`, or set ' +
            'GMPU_LIBRARY to the path of libgmpu.so.1). Looked in:\n' + tried.join('\n'),
    );
}

function declare(lib) {
    // Handles are plain pointers (BigInt in koffi 3); anonymous types keep this module
    // loadable twice in one process (named koffi types are process-global).
    const progressProto = koffi.proto('int', ['void *', 'int', 'double']);
    const f = (ret, name, args) => lib.func(name, ret, args);
    const outPtr = koffi.out(koffi.pointer('void *'));
    const paramInfo = koffi.struct({
        name: 'const char *',
        type: 'int',
        default_value: 'double',
        min: 'double',
        max: 'double',
        min_exclusive: 'int',
        max_exclusive: 'int',
        refits: 'int',
        doc: 'const char *',
    });
    return {
        progressType: koffi.pointer(progressProto),

        status_name: f('const char *', 'gmpu_status_name', ['int']),
        last_error: f('const char *', 'gmpu_last_error', []),
        version_number: f('uint32_t', 'gmpu_version_number', []),
        version_string: f('const char *', 'gmpu_version_string', []),
        abi_version: f('uint32_t', 'gmpu_abi_version', []),

        TYPE_INT: 1, // gmpu_value_type
        param_count: f('int', 'gmpu_param_count', []),
        param_info: f('int', 'gmpu_param_info', ['int', koffi.out(koffi.pointer(paramInfo))]),
        param_key: f('int', 'gmpu_param_key', ['const char *']),
        stat_count: f('int', 'gmpu_stat_count', []),
        stat_name: f('const char *', 'gmpu_stat_name', ['int']),

        surface_create: f('int', 'gmpu_surface_create', [outPtr]),
        surface_destroy: f('void', 'gmpu_surface_destroy', ['void *']),
        surface_last_error: f('const char *', 'gmpu_surface_last_error', ['void *']),
        surface_set_param: f('int', 'gmpu_surface_set_param', ['void *', 'int', 'double']),
        surface_get_param: f('int', 'gmpu_surface_get_param', ['void *', 'int', koffi.out(koffi.pointer('double'))]),
        surface_get_stat: f('int', 'gmpu_surface_get_stat', ['void *', 'int', koffi.out(koffi.pointer('double'))]),
        surface_set_progress: f('int', 'gmpu_surface_set_progress', ['void *', koffi.pointer(progressProto), 'void *']),
        surface_set_points_f64: f('int', 'gmpu_surface_set_points_f64', ['void *', 'double *', 'size_t', 'size_t']),
        surface_set_points_f32: f('int', 'gmpu_surface_set_points_f32', ['void *', 'float *', 'size_t', 'size_t']),
        surface_set_normals_f64: f('int', 'gmpu_surface_set_normals_f64', ['void *', 'double *', 'size_t', 'size_t']),
        surface_set_normals_f32: f('int', 'gmpu_surface_set_normals_f32', ['void *', 'float *', 'size_t', 'size_t']),
        surface_point_count: f('size_t', 'gmpu_surface_point_count', ['void *']),
        surface_fit: f('int', 'gmpu_surface_fit', ['void *']),
        surface_orient: f('int', 'gmpu_surface_orient', ['void *']),
        // Output arrays are typed arrays passed by pointer (koffi hands C their memory).
        surface_evaluate: f('int', 'gmpu_surface_evaluate', ['void *', 'double *', 'size_t', 'void *', 'void *']),
        surface_copy_normals: f('int', 'gmpu_surface_copy_normals', ['void *', 'void *', 'size_t']),
        surface_copy_normals_at: f('int', 'gmpu_surface_copy_normals_at', ['void *', 'int64_t *', 'size_t', 'void *']),
        surface_polygonize: f('int', 'gmpu_surface_polygonize', ['void *', outPtr]),

        mesh_create: f('int', 'gmpu_mesh_create', ['double *', 'size_t', 'uint32_t *', 'size_t', outPtr]),
        mesh_create_with: f('int', 'gmpu_mesh_create_with',
            ['double *', 'size_t', 'uint32_t *', 'size_t', 'double *', 'double *', 'uint8_t *', outPtr]),
        mesh_colors: f('void *', 'gmpu_mesh_colors', ['void *']),
        mesh_color_from_points: f('int', 'gmpu_mesh_color_from_points', ['void *', 'void *', outPtr]),
        mesh_destroy: f('void', 'gmpu_mesh_destroy', ['void *']),
        mesh_vertex_count: f('size_t', 'gmpu_mesh_vertex_count', ['void *']),
        mesh_triangle_count: f('size_t', 'gmpu_mesh_triangle_count', ['void *']),
        mesh_vertices: f('void *', 'gmpu_mesh_vertices', ['void *']),
        mesh_normals: f('void *', 'gmpu_mesh_normals', ['void *']),
        mesh_triangles: f('void *', 'gmpu_mesh_triangles', ['void *']),
        mesh_write: f('int', 'gmpu_mesh_write', ['void *', 'const char *']),
        mesh_confidence: f('void *', 'gmpu_mesh_confidence', ['void *']),
        mesh_simplify: f('int', 'gmpu_mesh_simplify', ['void *', 'size_t', 'double', outPtr]),
        mesh_trim: f('int', 'gmpu_mesh_trim', ['void *', 'double', outPtr]),
        surface_evaluate_grid: f('int', 'gmpu_surface_evaluate_grid',
            ['void *', 'double *', 'double', 'int64_t *', 'size_t', 'void *']),
        grid_polygonize: f('int', 'gmpu_grid_polygonize',
            ['double *', 'double', 'int64_t *', 'int64_t *', 'size_t', 'double *', outPtr]),
        mesh_grid_keys: f('void *', 'gmpu_mesh_grid_keys', ['void *']),

        points_read: f('int', 'gmpu_points_read', ['const char *', outPtr]),
        points_read_with: f('int', 'gmpu_points_read_with',
            ['const char *', 'double', koffi.pointer(progressProto), 'void *', outPtr]),
        points_create: f('int', 'gmpu_points_create', ['double *', 'double *', 'size_t', outPtr]),
        points_create_with: f('int', 'gmpu_points_create_with', ['double *', 'double *', 'uint8_t *', 'size_t', outPtr]),
        points_destroy: f('void', 'gmpu_points_destroy', ['void *']),
        points_count: f('size_t', 'gmpu_points_count', ['void *']),
        points_positions: f('void *', 'gmpu_points_positions', ['void *']),
        points_normals: f('void *', 'gmpu_points_normals', ['void *']),
        points_colors: f('void *', 'gmpu_points_colors', ['void *']),
        points_write: f('int', 'gmpu_points_write', ['void *', 'const char *']),
    };
}

/** The declared functions (loading the library on first use). */
export function getNative() {
    if (native) return native;
    const { lib, path: where } = open();
    let fns;
    try {
        fns = declare(lib);
    } catch (err) {
        throw new LibraryError('GMPU_LIBRARY_NOT_FOUND', `GMPU_LIBRARY_NOT_FOUND: ${where} is not a usable libgmpu: ${err.message}`);
    }
    const abi = fns.abi_version();
    if (abi !== ABI_VERSION)
        throw new LibraryError('GMPU_LIBRARY_NOT_FOUND', `GMPU_LIBRARY_NOT_FOUND: ${where} has ABI version ${abi}; this package needs ${ABI_VERSION}`);
    native = { ...fns, path: where };
    return native;
}

/** Copies count values of a C array (T = 'double' | 'uint32_t' | 'uint8_t') into a new typed array. */
export function copyArray(ptr, type, count) {
    if (count === 0) return type === 'double' ? new Float64Array(0) : type === 'uint8_t' ? new Uint8Array(0) : new Uint32Array(0);
    if (ptr === null || ptr === 0n) return null;
    return koffi.decode(ptr, type, count);
}

export { koffi };
