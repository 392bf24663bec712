#!/usr/bin/python3
"""Cross-language test: the same input and parameters give the same mesh in C, Python,
Node.js and Rust.

Each language's example CLI reconstructs the same clouds with the same explicit parameters
and writes a binary PLY; every mesh must equal the C CLI's: same vertex and triangle counts,
identical triangles, coordinates within 1e-9. A language whose example program (or runtime)
is missing FAILS, by name; nothing is skipped.

    /usr/bin/python3 tests/cross/cross_language.py [--build build] [--only c,rust] [--keep DIR]

The programs (run from the repository root):
    C       build/examples/gmpu-reconstruct IN -o OUT FLAGS
    Python  /usr/bin/python3 examples/python/reconstruct.py IN OUT FLAGS   (PYTHONPATH=bindings/python)
    Node    node examples/node/reconstruct.mjs IN -o OUT FLAGS
    Rust    cargo run --offline --example reconstruct (bindings/rust) -- IN OUT FLAGS
Every binding is pointed at the same library, BUILD/lib/libgmpu.so.1 (GMPU_LIBRARY for
Python, Node and the Rust crate; the C CLI has it in its RUNPATH).

Only the standard library is used. Exit status 0 when every language matches, 1 otherwise.
"""
from __future__ import annotations

import argparse
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from typing import Dict, List, Optional, Sequence, Tuple

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
TOLERANCE = 1e-9
# Explicit, non-default values: a binding that drops a flag makes a different mesh.
FLAGS = ["--error", "0.003", "--max-depth", "6", "--resolution", "56", "--threads", "2"]
LANGUAGES = ["c", "python", "node", "rust"]
TIMEOUT = 600  # seconds per program run (the Rust one may compile the crate first)


# ---- PLY -----------------------------------------------------------------------------------

_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


class Mesh:
    def __init__(self, vertices: List[Tuple[float, float, float]], faces: List[Tuple[int, ...]]):
        self.vertices = vertices
        self.faces = faces


def read_ply(path: str) -> Mesh:
    """Vertices (x y z) and faces of a PLY file (binary little/big endian or ascii)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError(f"{path}: not a PLY file")
    body = data.index(b"\n", end) + 1
    header = data[:body].decode("ascii").splitlines()
    fmt = None
    elements: List[Tuple[str, int, List[Tuple]]] = []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            if w[1] == "list":
                elements[-1][2].append(("list", w[4], _TYPES[w[2]], _TYPES[w[3]]))
            else:
                elements[-1][2].append(("scalar", w[2], _TYPES[w[1]]))
    if fmt not in ("binary_little_endian", "binary_big_endian", "ascii"):
        raise ValueError(f"{path}: unsupported PLY format {fmt}")
    vertices: List[Tuple[float, float, float]] = []
    faces: List[Tuple[int, ...]] = []
    if fmt == "ascii":
        tokens = data[body:].split()
        pos = 0
        for name, count, props in elements:
            for _ in range(count):
                rec = {}
                for p in props:
                    if p[0] == "scalar":
                        rec[p[1]] = float(tokens[pos])
                        pos += 1
                    else:
                        n = int(tokens[pos])
                        rec[p[1]] = tuple(int(t) for t in tokens[pos + 1:pos + 1 + n])
                        pos += 1 + n
                if name == "vertex":
                    vertices.append((rec["x"], rec["y"], rec["z"]))
                elif name == "face":
                    faces.append(rec.get("vertex_indices", rec.get("vertex_index")))
        return Mesh(vertices, faces)
    order = "<" if fmt == "binary_little_endian" else ">"
    pos = body
    for name, count, props in elements:
        if all(p[0] == "scalar" for p in props):
            rec = struct.Struct(order + "".join(p[2] for p in props))
            names = [p[1] for p in props]
            block = data[pos:pos + rec.size * count]
            if len(block) != rec.size * count:
                raise ValueError(f"{path}: truncated {name} element")
            if name == "vertex":
                ix, iy, iz = names.index("x"), names.index("y"), names.index("z")
                vertices = [(r[ix], r[iy], r[iz]) for r in rec.iter_unpack(block)]
            pos += rec.size * count
            continue
        for _ in range(count):
            rec = {}
            for p in props:
                if p[0] == "scalar":
                    (rec[p[1]],) = struct.unpack_from(order + p[2], data, pos)
                    pos += struct.calcsize(p[2])
                else:
                    (n,) = struct.unpack_from(order + p[2], data, pos)
                    pos += struct.calcsize(p[2])
                    rec[p[1]] = struct.unpack_from(order + p[3] * n, data, pos)
                    pos += struct.calcsize(p[3]) * n
            if name == "face":
                faces.append(rec.get("vertex_indices", rec.get("vertex_index")))
    if pos != len(data):
        raise ValueError(f"{path}: {len(data) - pos} bytes after the last element")
    return Mesh(vertices, faces)


# ---- comparison ----------------------------------------------------------------------------

def closed_problem(mesh: Mesh) -> Optional[str]:
    """None if every undirected edge is used by exactly two triangles, else what is wrong."""
    if not mesh.faces:
        return "no triangles"
    edges: Dict[Tuple[int, int], int] = {}
    for face in mesh.faces:
        if len(face) != 3:
            return f"a face with {len(face)} vertices"
        for k in range(3):
            a, b = face[k], face[(k + 1) % 3]
            key = (a, b) if a < b else (b, a)
            edges[key] = edges.get(key, 0) + 1
    bad = sum(1 for n in edges.values() if n != 2)
    return f"{bad} edges not used exactly twice" if bad else None


def mesh_difference(ref: Mesh, other: Mesh, tol: float = TOLERANCE) -> Optional[str]:
    """None if the meshes are the same (counts, triangles, coordinates to tol), else why not."""
    return compare(ref, other, tol)[0]


def compare(ref: Mesh, other: Mesh, tol: float = TOLERANCE) -> Tuple[Optional[str], float]:
    """(None or why the meshes differ, largest coordinate difference)."""
    problem = _difference(ref, other, tol)
    if problem is not None:
        return problem, float("nan")
    return None, max((abs(a[k] - b[k]) for a, b in zip(ref.vertices, other.vertices) for k in range(3)),
                     default=0.0)


def _difference(ref: Mesh, other: Mesh, tol: float) -> Optional[str]:
    if len(ref.vertices) != len(other.vertices):
        return f"{len(other.vertices)} vertices, C has {len(ref.vertices)}"
    if len(ref.faces) != len(other.faces):
        return f"{len(other.faces)} triangles, C has {len(ref.faces)}"
    for i, (a, b) in enumerate(zip(ref.faces, other.faces)):
        if tuple(a) != tuple(b):
            return f"triangle {i} is {tuple(b)}, C has {tuple(a)}"
    worst, at = 0.0, -1
    for i, (a, b) in enumerate(zip(ref.vertices, other.vertices)):
        for k in range(3):
            d = abs(a[k] - b[k])
            if d != d:
                return f"vertex {i} has NaN (C has {a})"
            if d > worst:
                worst, at = d, i
    if not worst <= tol:
        return f"vertex {at} differs by {worst:.3g} (> {tol:g})"
    return None


def self_test() -> None:
    """The comparison must be able to fail."""
    ref = Mesh([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)],
               [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
    assert closed_problem(ref) is None
    assert closed_problem(Mesh(ref.vertices, ref.faces[:3])) is not None
    assert mesh_difference(ref, Mesh(list(ref.vertices), list(ref.faces))) is None
    near = list(ref.vertices)
    near[2] = (0.0, 1.0 + 0.5e-9, 0.0)
    assert mesh_difference(ref, Mesh(near, ref.faces)) is None
    for vertices, faces in [
        ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0 + 2e-9, 0.0), (0.0, 0.0, 1.0)], ref.faces),
        ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, float("nan"), 0.0), (0.0, 0.0, 1.0)], ref.faces),
        (ref.vertices[:3], ref.faces),
        (ref.vertices, ref.faces[:3]),
        (ref.vertices, [(0, 1, 2)] + ref.faces[1:]),
    ]:
        assert mesh_difference(ref, Mesh(vertices, faces)) is not None, (vertices, faces)
    # The PLY reader on a file written here, binary and ascii.
    with tempfile.TemporaryDirectory() as d:
        for fmt in ("binary_little_endian", "ascii"):
            path = os.path.join(d, f"t_{fmt}.ply")
            head = (f"ply\nformat {fmt} 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                    "property double z\nproperty double nx\nelement face 4\n"
                    "property list uchar int vertex_indices\nend_header\n").encode()
            if fmt == "ascii":
                body = "".join(f"{x} {y} {z} 0\n" for x, y, z in ref.vertices)
                body += "".join("3 %d %d %d\n" % f for f in ref.faces)
                blob = head + body.encode()
            else:
                blob = head + b"".join(struct.pack("<4d", *v, 0.0) for v in ref.vertices)
                blob += b"".join(struct.pack("<B3i", 3, *f) for f in ref.faces)
            with open(path, "wb") as f:
                f.write(blob)
            back = read_ply(path)
            assert mesh_difference(ref, back, 0.0) is None, fmt


# ---- the programs --------------------------------------------------------------------------

def test_data() -> str:
    d = os.environ.get("GMPU_TEST_DATA") or os.path.join(ROOT, "tests", "data")
    return os.path.abspath(d)


def inputs() -> List[Tuple[str, str]]:
    clouds = [("bunny", os.path.join(ROOT, "examples", "data", "bunny.ply")),
              ("knot_clean", os.path.join(test_data(), "clouds", "knot_clean.ply"))]
    for name, path in clouds:
        if not os.path.isfile(path):
            raise SystemExit(f"cross_language: input {name} not found at {path} "
                             "(tests/data ships with the repository; GMPU_TEST_DATA overrides it)")
    return clouds


def command(lang: str, build: str, src: str, out: str) -> Tuple[Optional[List[str]], Dict[str, str], str]:
    """(argv or None if the program is missing, extra environment, what is missing)."""
    lib = os.path.join(build, "lib", "libgmpu.so.1")
    env = {"GMPU_LIBRARY": lib}
    if lang == "c":
        exe = os.path.join(build, "examples", "gmpu-reconstruct")
        if not os.access(exe, os.X_OK):
            return None, env, f"{exe} (run make build)"
        return [exe, src, "-o", out] + FLAGS, env, ""
    if lang == "python":
        script = os.path.join(ROOT, "examples", "python", "reconstruct.py")
        if not os.path.isfile(script):
            return None, env, script
        env["PYTHONPATH"] = os.path.join(ROOT, "bindings", "python")
        return ["/usr/bin/python3", script, src, out] + FLAGS, env, ""
    if lang == "node":
        script = os.path.join(ROOT, "examples", "node", "reconstruct.mjs")
        node = shutil.which("node")
        if not os.path.isfile(script):
            return None, env, script
        if not node:
            return None, env, "the node executable"
        return [node, script, src, "-o", out] + FLAGS, env, ""
    if lang == "rust":
        manifest = os.path.join(ROOT, "bindings", "rust", "Cargo.toml")
        cargo = shutil.which("cargo")
        if not os.path.isfile(manifest):
            return None, env, manifest
        if not cargo:
            return None, env, "the cargo executable"
        env["GMPU_LIBRARY"] = os.path.join(build, "lib", "libgmpu.so.1")
        return [cargo, "run", "--offline", "--quiet", "--manifest-path", manifest, "--example", "reconstruct",
                "--", src, out] + FLAGS, env, ""
    raise ValueError(lang)


def run(lang: str, build: str, src: str, out: str) -> Tuple[Optional[Mesh], str, float]:
    argv, extra, missing = command(lang, build, src, out)
    if argv is None:
        return None, f"MISSING: {missing} does not exist", 0.0
    env = dict(os.environ)
    env.update(extra)
    t0 = time.monotonic()
    try:
        p = subprocess.run(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {TIMEOUT} s: {' '.join(argv)}", time.monotonic() - t0
    seconds = time.monotonic() - t0
    if p.returncode != 0:
        tail = (p.stderr.decode(errors="replace").strip().splitlines() or [""])[-3:]
        return None, f"exit status {p.returncode}: {' | '.join(tail)}\n    command: {' '.join(argv)}", seconds
    if not os.path.isfile(out):
        return None, f"exit status 0 but no {out}", seconds
    try:
        return read_ply(out), "", seconds
    except (ValueError, KeyError, struct.error) as e:
        return None, f"unreadable output: {e}", seconds


def main(argv: Sequence[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="meson build directory")
    ap.add_argument("--only", default=",".join(LANGUAGES), help="comma-separated subset of " + ",".join(LANGUAGES))
    ap.add_argument("--keep", metavar="DIR", help="write the meshes here and keep them")
    args = ap.parse_args(argv)
    build = os.path.abspath(args.build)
    langs = [l for l in args.only.split(",") if l]
    unknown = [l for l in langs if l not in LANGUAGES]
    if unknown or "c" not in langs:
        ap.error(f"--only needs c (the reference) and known languages, got {args.only}")

    self_test()
    clouds = inputs()
    out_dir = args.keep or tempfile.mkdtemp(prefix="gmpu-cross-")
    os.makedirs(out_dir, exist_ok=True)
    failures: List[str] = []
    print(f"cross-language meshes, flags: {' '.join(FLAGS)}  (tolerance {TOLERANCE:g})")
    try:
        for cloud, src in clouds:
            ref: Optional[Mesh] = None
            for lang in langs:
                out = os.path.join(out_dir, f"{cloud}_{lang}.ply")
                if os.path.exists(out):
                    os.remove(out)
                mesh, problem, seconds = run(lang, build, src, out)
                ok_note = "reference" if lang == "c" else ""
                if mesh is not None and lang == "c":
                    ref = mesh
                    problem = closed_problem(mesh) or ""
                    if problem:
                        problem = f"C mesh is not closed: {problem}"
                elif mesh is not None:
                    if ref is None:
                        problem = "no C mesh to compare with"
                    else:
                        diff, worst = compare(ref, mesh)
                        problem = diff or ""
                        if not problem:
                            ok_note = f"max |dx| {worst:.1g}"
                counts = f"{len(mesh.vertices):7d} v {len(mesh.faces):7d} t" if mesh else " " * 19
                status = "FAIL" if problem else "ok"
                note = problem or ok_note
                print(f"  {cloud:<11} {lang:<7} {counts} {seconds:6.1f} s  {status:<4} {note}".rstrip())
                if problem:
                    failures.append(f"{cloud} / {lang}: {problem}")
                sys.stdout.flush()
    finally:
        if not args.keep:
            shutil.rmtree(out_dir, ignore_errors=True)
    if failures:
        print("\nFAILED: the languages do not all give the C mesh:")
        for f in failures:
            print("  " + f)
        return 1
    print(f"all {len(langs)} languages give the same mesh on {len(clouds)} clouds")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
