#!/usr/bin/python3
"""A hostile corpus for gmpu-reconstruct, generated at test time (never committed), and the
check that every file in it ends cleanly.

    hostile_corpus.py generate DIR [--seed N]     # writes DIR/in/* and DIR/manifest.json
    hostile_corpus.py run CLI DIR [--jobs N]      # runs CLI on each, checks, summarises

The corpus: valid clouds (a sphere, a torus, a box, nested spheres) in every format the
reader takes (PLY ascii / binary little / big endian, XYZ, OFF, OBJ), then broken every way
a file met in the wild can be: truncated anywhere, headers that lie about counts or
formats, list properties in the vertex element, NaN / inf / huge / tiny / subnormal values,
garbage numbers, random bytes, bit flips, wrong extensions, 0-3 points, identical,
collinear and coplanar points, UTF-8 byte order marks, a 200k-element header, 2 GB sparse
files, a FIFO, /dev/zero, a directory, a dangling symlink, a missing file.

Each file has an expectation in the manifest:
  error  -> exit 1, exactly one line on stderr ("gmpu-reconstruct: ..."), no output file
  ok     -> exit 0, a closed, consistently wound mesh whose vertices lie on the known shape
  any    -> either of the two above (mutations that may or may not still parse)
Always: no signal, no timeout, no sanitizer report, nothing left beside the output (no
temporary), and stderr empty on success (--quiet). Standard library only.
"""
import argparse
import json
import math
import os
import random
import struct
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

# ---- shapes -------------------------------------------------------------------------------


def sphere(n, rng, c=(0.0, 0.0, 0.0), r=1.0):
    pts = []
    for _ in range(n):
        z = rng.uniform(-1, 1)
        phi = rng.uniform(0, 2 * math.pi)
        s = math.sqrt(max(0.0, 1 - z * z))
        pts.append((c[0] + r * s * math.cos(phi), c[1] + r * s * math.sin(phi), c[2] + r * z))
    return pts


def torus(n, rng, R=1.0, r=0.4):
    pts = []
    while len(pts) < n:
        u, v = rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)
        if rng.uniform(0, R + r) > R + r * math.cos(v):
            continue
        pts.append(((R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v)))
    return pts


def box(n, rng, h=(1.0, 0.6, 0.4)):
    pts = []
    for _ in range(n):
        p = [rng.uniform(-h[k], h[k]) for k in range(3)]
        a = rng.randrange(3)
        p[a] = h[a] if rng.random() < 0.5 else -h[a]
        pts.append(tuple(p))
    return pts


# Shape checks for "ok" files: (kind, params); the runner measures every mesh vertex.
def shape_error(kind, params, v):
    x, y, z = v
    if kind == "sphere":
        cx, cy, cz, r = params
        return abs(math.sqrt(((x - cx) / r) ** 2 + ((y - cy) / r) ** 2 + ((z - cz) / r) ** 2) - 1)
    if kind == "torus":
        R, r, s = params
        x, y, z = x / s, y / s, z / s
        return abs(math.hypot(math.hypot(x, y) - R, z) - r) / r
    if kind == "nested":
        r1, r2 = params
        d = math.sqrt(x * x + y * y + z * z)
        return min(abs(d / r1 - 1), abs(d / r2 - 1))
    raise ValueError(kind)


# ---- writers ------------------------------------------------------------------------------


def ply_bytes(pts, fmt="ascii", normals=None, extra_header="", vertex_props=None, count=None, faces=None):
    n = len(pts) if count is None else count
    props = vertex_props or ["property float x", "property float y", "property float z"]
    if normals is not None:
        props = props + ["property float nx", "property float ny", "property float nz"]
    head = "ply\nformat %s 1.0\n%selement vertex %s\n%s\n" % (fmt, extra_header, n, "\n".join(props))
    if faces is not None:
        head += "element face %d\nproperty list uchar int vertex_indices\n" % len(faces)
    head += "end_header\n"
    if fmt == "ascii":
        lines = []
        for i, p in enumerate(pts):
            vals = list(p) + (list(normals[i]) if normals is not None else [])
            lines.append(" ".join(repr(float(v)) for v in vals))
        for f in faces or []:
            lines.append("3 %d %d %d" % f)
        return head.encode() + ("\n".join(lines) + "\n").encode()
    e = "<" if fmt == "binary_little_endian" else ">"
    body = bytearray()
    for i, p in enumerate(pts):
        vals = list(p) + (list(normals[i]) if normals is not None else [])
        body += struct.pack(e + "%df" % len(vals), *vals)
    for f in faces or []:
        body += struct.pack(e + "B3i", 3, *f)
    return head.encode() + bytes(body)


def ply_double_bytes(pts, fmt="binary_little_endian"):
    e = "<" if fmt == "binary_little_endian" else ">"
    head = ("ply\nformat %s 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
            "property double z\nend_header\n" % (fmt, len(pts))).encode()
    return head + b"".join(struct.pack(e + "3d", *p) for p in pts)


def xyz_bytes(pts, normals=None):
    out = []
    for i, p in enumerate(pts):
        vals = list(p) + (list(normals[i]) if normals is not None else [])
        out.append(" ".join(repr(float(v)) for v in vals))
    return ("\n".join(out) + "\n").encode()


def off_bytes(pts, count=None):
    n = len(pts) if count is None else count
    return ("OFF\n%s 0 0\n" % n + "".join("%r %r %r\n" % tuple(map(float, p)) for p in pts)).encode()


def obj_bytes(pts):
    return ("# hostile\n" + "".join("v %r %r %r\n" % tuple(map(float, p)) for p in pts)).encode()


# ---- generation ---------------------------------------------------------------------------


def generate(out_dir, seed):
    rng = random.Random(seed)
    in_dir = os.path.join(out_dir, "in")
    os.makedirs(in_dir, exist_ok=True)
    manifest = {}

    def add(name, data, expect, shape=None):
        path = os.path.join(in_dir, name)
        with open(path, "wb") as f:
            f.write(data)
        manifest[name] = {"expect": expect, "shape": shape}

    sph = sphere(1500, rng, (0.2, -0.1, 0.3), 1.0)
    sph_shape = ["sphere", [0.2, -0.1, 0.3, 1.0]]
    tor = torus(2500, rng)
    tor_shape = ["torus", [1.0, 0.4, 1.0]]
    bx = box(2500, rng)
    nested = sphere(1500, rng, (0, 0, 0), 1.0) + sphere(900, rng, (0, 0, 0), 0.55)
    normals = [tuple((p[k] - sph_shape[1][k]) for k in range(3)) for p in sph]

    # Valid files in every format: they must reconstruct, on the right shape.
    add("valid_sphere_ascii.ply", ply_bytes(sph), "ok", sph_shape)
    add("valid_sphere_le.ply", ply_bytes(sph, "binary_little_endian"), "ok", sph_shape)
    add("valid_sphere_be.ply", ply_bytes(sph, "binary_big_endian"), "ok", sph_shape)
    add("valid_sphere_normals_le.ply", ply_bytes(sph, "binary_little_endian", normals), "ok", sph_shape)
    add("valid_sphere.xyz", xyz_bytes(sph), "ok", sph_shape)
    add("valid_sphere6.xyz", xyz_bytes(sph, normals), "ok", sph_shape)
    add("valid_sphere.off", off_bytes(sph), "ok", sph_shape)
    add("valid_sphere.obj", obj_bytes(sph), "ok", sph_shape)
    add("valid_torus_le.ply", ply_bytes(tor, "binary_little_endian"), "ok", tor_shape)
    add("valid_box.xyz", xyz_bytes(bx), "ok", None)
    add("valid_nested.ply", ply_bytes(nested, "binary_big_endian"), "ok", ["nested", [1.0, 0.55]])
    add("valid_sphere_crlf.ply", ply_bytes(sph).replace(b"\n", b"\r\n"), "ok", sph_shape)
    add("valid_sphere_faces.ply", ply_bytes(sph[:100], faces=[(0, 1, 2), (3, 4, 5)]) , "any")
    # A list property among the vertex properties (skipped), and extra elements.
    props = ["property float x", "property list uchar int tags", "property float y", "property float z"]
    head = ("ply\nformat ascii 1.0\ncomment tagged\nelement vertex %d\n%s\nelement camera 1\nproperty float f\n"
            "end_header\n" % (len(sph), "\n".join(props)))
    body = "".join("%r %d %s %r %r\n" % (p[0], i % 3, " ".join(str(i + k) for k in range(i % 3)), p[1], p[2])
                   for i, p in enumerate(sph)) + "1.5\n"
    add("valid_listprop.ply", (head + body).encode(), "ok", sph_shape)
    # Scales that normalise.
    for exp in (30, -30, 200, -200):
        s = 10.0 ** exp
        pts = [(x * s, y * s, z * s) for x, y, z in sph]
        add("valid_scale_1e%+d.ply" % exp, ply_double_bytes(pts), "ok",
            ["sphere", [0.2 * s, -0.1 * s, 0.3 * s, s]])
    add("valid_scale_1e30.xyz", xyz_bytes([(x * 1e30, y * 1e30, z * 1e30) for x, y, z in tor]), "ok",
        ["torus", [1.0, 0.4, 1e30]])
    # Few points / sparse: the minimum works or fails cleanly.
    add("sparse_15.xyz", xyz_bytes(sph[:15]), "any")
    add("sparse_40.xyz", xyz_bytes(sph[:40]), "any")
    add("dups_every_point_x5.xyz", xyz_bytes([p for p in sph[:300] for _ in range(5)]), "any")

    # Degenerate geometry: clean DEGENERATE / INVALID_INPUT errors.
    add("empty.xyz", b"", "error")
    add("empty.ply", b"", "error")
    add("empty.off", b"", "error")
    add("empty.obj", b"", "error")
    for k in (1, 2, 3, 14):
        add("points_%d.xyz" % k, xyz_bytes(sph[:k]), "error")
    add("identical.ply", ply_bytes([(1.0, 2.0, 3.0)] * 500), "error")
    add("identical_huge.xyz", xyz_bytes([(1e300, -1e300, 1e300)] * 100), "error")
    line = [(t, 2 * t - 1, -t) for t in (rng.uniform(-5, 5) for _ in range(400))]
    add("collinear.ply", ply_double_bytes(line), "error")
    plane = [(a, b, 0.5 * a - b + 2) for a, b in ((rng.uniform(-1, 1), rng.uniform(-1, 1)) for _ in range(600))]
    add("coplanar.ply", ply_double_bytes(plane), "error")
    add("coplanar.obj", obj_bytes(plane), "error")
    add("too_big_1e305.ply", ply_double_bytes([(x * 1e305, y * 1e305, z * 1e305) for x, y, z in sph]), "error")
    add("too_small_1e-310.ply", ply_double_bytes([(x * 1e-310, y * 1e-310, z * 1e-310) for x, y, z in sph]), "error")

    # Non-finite values anywhere: rejected naming the vertex.
    for name, val in (("nan", float("nan")), ("inf", float("inf")), ("ninf", float("-inf"))):
        bad = list(sph)
        i = rng.randrange(len(bad))
        bad[i] = (bad[i][0], val, bad[i][2])
        add("%s_le.ply" % name, ply_double_bytes(bad), "error")
        add("%s.xyz" % name, xyz_bytes(bad), "error")
        add("%s_be.ply" % name, ply_bytes(bad, "binary_big_endian"), "error")
    # 1e39 in a float property: past float's range (rejected, or kept as a double: fine).
    add("overflow_float.ply", ply_bytes([(1e39, 0.0, 0.0)] + sph[1:], "ascii"), "any")

    # Headers that lie.
    valid_le = ply_bytes(sph, "binary_little_endian")
    for n in (len(sph) + 1, len(sph) * 2, 2 ** 31 - 1, 2 ** 32 + 5, 2 ** 62, 10 ** 30, -1, 0):
        add("lie_count_%s_le.ply" % n, ply_bytes(sph, "binary_little_endian", count=n),
            "error" if n != 0 else "error")
        add("lie_count_%s_ascii.ply" % n, ply_bytes(sph, "ascii", count=n), "any" if n == 0 else "error")
    add("lie_count_fewer_le.ply", ply_bytes(sph, "binary_little_endian", count=len(sph) - 100), "any")
    add("lie_off_count.off", off_bytes(sph, count=len(sph) * 3), "error")
    add("lie_off_huge.off", off_bytes(sph, count=2 ** 40), "error")
    add("lie_faces_le.ply", ply_bytes(sph[:50], "binary_little_endian")[:-1].replace(
        b"end_header", b"element face 1000000\nproperty list uchar int vertex_indices\nend_header"), "error")
    for fmt in ("binary_middle_endian", "ascii2", "", "binary_little_endian 2.0 extra"):
        add("format_%s.ply" % (fmt.replace(" ", "_") or "none"),
            valid_le.replace(b"binary_little_endian", fmt.encode(), 1), "error")
    add("version_2.ply", ply_bytes(sph).replace(b"ascii 1.0", b"ascii 2.0"), "error")
    add("no_end_header.ply", ply_bytes(sph).replace(b"end_header\n", b""), "error")
    add("no_x.ply", ply_bytes(sph, vertex_props=["property float y", "property float z", "property float w"]), "error")
    add("type_int64.ply", ply_bytes(sph, vertex_props=["property int64 x", "property float y", "property float z"]),
        "error")
    add("list_count_runs_off.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
        b"property list uint float junk\nproperty float y\nproperty float z\nend_header\n" +
        struct.pack("<fI", 0.0, 0xFFFFFFF0) + b"\0" * 12, "error")
    add("list_in_vertex_ascii_bad.ply", b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
        b"property list uchar int t\nproperty float y\nproperty float z\nend_header\n0 2 1 2 0 0\n1 250 1 2 3\n", "error")
    add("header_only.ply", b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
        b"property float z\nend_header\n", "error")
    add("magic_only.ply", b"ply\n", "error")
    add("not_ply.ply", b"PK\x03\x04" + bytes(rng.randrange(256) for _ in range(500)), "error")
    add("huge_header_line.ply", b"ply\nformat ascii 1.0\ncomment " + b"x" * 2_000_000 + b"\n", "error")
    add("many_properties.ply", ply_bytes(sph[:50], vertex_props=["property float x", "property float y",
                                                                 "property float z"] +
                                         ["property float p%d" % i for i in range(3000)]), "error")

    # Truncated anywhere (header or body), every format.
    sources = {"le.ply": valid_le, "be.ply": ply_bytes(sph, "binary_big_endian"), "ascii.ply": ply_bytes(sph),
               "xyz": xyz_bytes(sph), "off": off_bytes(sph), "obj": obj_bytes(sph), "d.ply": ply_double_bytes(sph)}
    for ext, data in sources.items():
        head_end = data.find(b"end_header")
        cuts = sorted({5, 20, max(1, head_end - 3), head_end + 5, len(data) // 3, len(data) // 2, len(data) - 7,
                       len(data) - 1} - {0})
        for cut in cuts:
            if 0 < cut < len(data):
                # PLY and OFF declare their counts: a cut is an error (but a text PLY cut in
                # its last number still holds every vertex). XYZ and OBJ cut between (or
                # inside) lines may still parse, with fewer points.
                strict = (ext.endswith("ply") or ext == "off") and not (ext == "ascii.ply" and cut > len(data) - 40)
                add("truncated_%d_%s" % (cut, ext), data[:cut], "error" if strict else "any")

    # Garbage numbers in text formats.
    ascii_ply = ply_bytes(sph)
    garbage = ["1e99999", "-1e99999", "0x1p3", "nan", "inf", "--1", "1,5", "1.2.3", "\u0661\u0662", "1e", ".",
               "+", "9" * 400, "1\x002", "\t\t", "0b101", "1_000", "1e-99999"]
    for k, g in enumerate(garbage):
        lines = xyz_bytes(sph).decode().split("\n")
        i = rng.randrange(len(lines) - 1)
        cols = lines[i].split(" ")
        cols[rng.randrange(3)] = g
        lines[i] = " ".join(cols)
        text = "\n".join(lines).encode("utf-8")
        add("garbage_%02d.xyz" % k, text, "any" if g in ("1e-99999", "\t\t") else "error")
        ply_head = ascii_ply[:ascii_ply.find(b"end_header") + 11]
        add("garbage_%02d.ply" % k, ply_head + text, "any" if g in ("1e-99999", "\t\t") else "error")

    # Bit flips in binary bodies and headers: may still parse (then reconstruct or fail
    # cleanly), or not.
    for k in range(25):
        data = bytearray(rng.choice([valid_le, sources["be.ply"], sources["d.ply"]]))
        for _ in range(rng.randrange(1, 8)):
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        add("bitflip_%02d.ply" % k, bytes(data), "any")
    # Random bytes, with every extension, and random bytes after a valid header.
    for k, ext in enumerate(["ply", "xyz", "txt", "off", "obj", "ply", "xyz", "PLY"]):
        add("random_%d.%s" % (k, ext), bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5000))), "any")
    for k in range(4):
        add("random_body_%d.ply" % k, valid_le[:valid_le.find(b"end_header") + 11] +
            bytes(rng.randrange(256) for _ in range(rng.randrange(12, 40000))), "any")
    # Contents that do not match the extension.
    add("ply_named.xyz", valid_le, "error")
    add("xyz_named.off", xyz_bytes(sph), "error")
    add("off_named.obj", off_bytes(sph), "error")
    add("unknown.stl", b"solid x\nendsolid x\n", "error")
    add("noext", xyz_bytes(sph), "error")

    # A UTF-8 byte order mark before the first line: read like the file without it.
    bom = b"\xef\xbb\xbf"
    add("bom_sphere.obj", bom + obj_bytes(sph), "ok", sph_shape)
    add("bom_sphere.xyz", bom + xyz_bytes(sph), "ok", sph_shape)
    add("bom_sphere.off", bom + off_bytes(sph), "ok", sph_shape)
    add("bom_sphere_ascii.ply", bom + ply_bytes(sph), "ok", sph_shape)
    # 200,000 empty elements before the vertex element: linear header checks, so quick.
    add("many_empty_elements.ply", ply_bytes(sph, "binary_little_endian", extra_header="".join(
        "element e%d 0\n" % i for i in range(200000))), "ok", sph_shape)
    add("many_elements_duplicate.ply", ply_bytes(sph, extra_header="".join(
        "element e%d 0\n" % i for i in range(200000)) + "element e5 0\n"), "error")
    # 2 GB of zeros (sparse: no disk space) in every format: fails on the first bytes.
    for ext in ("ply", "xyz", "obj", "off"):
        p = os.path.join(in_dir, "sparse_2gb." + ext)
        with open(p, "wb") as f:
            f.truncate(2 << 30)
        manifest["sparse_2gb." + ext] = {"expect": "error", "shape": None}
    # Not regular files: a FIFO (would block the reader), a device that never ends.
    p = os.path.join(in_dir, "fifo.ply")
    if os.path.lexists(p):
        os.remove(p)
    os.mkfifo(p)
    manifest["fifo.ply"] = {"expect": "error", "shape": None}
    for name in ("dev_zero.xyz", "dev_zero.ply"):
        p = os.path.join(in_dir, name)
        if os.path.lexists(p):
            os.remove(p)
        os.symlink("/dev/zero", p)
        manifest[name] = {"expect": "error", "shape": None}

    # Not files: a directory, a dangling symlink, a symlink loop; and a missing path.
    os.makedirs(os.path.join(in_dir, "directory.ply"), exist_ok=True)
    manifest["directory.ply"] = {"expect": "error", "shape": None}
    for name, target in (("dangling.ply", "no-such-target.ply"), ("loop.ply", "loop.ply")):
        p = os.path.join(in_dir, name)
        if os.path.lexists(p):
            os.remove(p)
        os.symlink(target, p)
        manifest[name] = {"expect": "error", "shape": None}
    manifest["missing.ply"] = {"expect": "error", "shape": None}

    with open(os.path.join(out_dir, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=0, sort_keys=True)
    print("hostile corpus: %d cases in %s" % (len(manifest), in_dir))


# ---- running ------------------------------------------------------------------------------


def read_off(path):
    with open(path, "rb") as f:
        tokens = f.read().split()
    if not tokens or tokens[0] != b"OFF":
        raise ValueError("not an OFF file")
    nv, nt = int(tokens[1]), int(tokens[2])
    vals = tokens[4:]
    v = [tuple(float(x) for x in vals[3 * i:3 * i + 3]) for i in range(nv)]
    t = []
    base = 3 * nv
    for i in range(nt):
        k, a, b, c = (int(x) for x in vals[base + 4 * i:base + 4 * i + 4])
        if k != 3:
            raise ValueError("a face with %d corners" % k)
        t.append((a, b, c))
    return v, t


def mesh_problem(v, t):
    if not t:
        return "no triangles"
    if any(not math.isfinite(c) for p in v for c in p):
        return "a non-finite vertex"
    edges = set()
    for a, b, c in t:
        for e in ((a, b), (b, c), (c, a)):
            if not (0 <= e[0] < len(v) and 0 <= e[1] < len(v)):
                return "an index out of range"
            if e[0] == e[1]:
                return "a triangle with a repeated vertex"
            if e in edges:
                return "a directed edge used twice (not manifold, or misoriented)"
            edges.add(e)
    for a, b in edges:
        if (b, a) not in edges:
            return "a boundary edge (not closed)"
    # Signed volume, in units of the largest coordinate (1e±200 would overflow a product).
    unit = max(abs(c) for p in v for c in p) or 1.0
    v = [(x / unit, y / unit, z / unit) for x, y, z in v]
    vol = 0.0
    for a, b, c in t:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = v[a], v[b], v[c]
        vol += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    if not vol > 0:
        return "wound inward (signed volume %g)" % vol
    return None


def run_one(cli, in_dir, out_dir, name, case, timeout):
    src = os.path.join(in_dir, name)
    out = os.path.join(out_dir, name.replace("/", "_") + ".off")
    start = time.monotonic()
    try:
        p = subprocess.run([cli, src, "-o", out, "--quiet", "--resolution", "32"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        return name, "FAIL", "timed out after %d s" % timeout, timeout
    took = time.monotonic() - start
    try:
        err = p.stderr.decode("utf-8")
    except UnicodeDecodeError:
        return name, "FAIL", "stderr is not valid UTF-8: %r" % p.stderr[:300], time.monotonic() - start
    lines = err.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    leftovers = [f for f in os.listdir(out_dir) if f.startswith(os.path.basename(out)) and f != os.path.basename(out)]
    if p.returncode < 0:
        return name, "FAIL", "killed by signal %d: %s" % (-p.returncode, err[-2000:]), took
    if "Sanitizer" in err or "runtime error" in err:
        return name, "FAIL", "sanitizer report:\n" + err[-4000:], took
    if leftovers:
        return name, "FAIL", "left %s beside the output" % leftovers, took
    expect = case["expect"]
    if p.returncode == 0:
        if expect == "error":
            return name, "FAIL", "exit 0, expected a clean error", took
        if err:
            return name, "FAIL", "exit 0 but stderr says: " + err[:500], took
        if not os.path.exists(out):
            return name, "FAIL", "exit 0 without an output file", took
        try:
            v, t = read_off(out)
        except (ValueError, IndexError) as e:
            return name, "FAIL", "unreadable output: %s" % e, took
        problem = mesh_problem(v, t)
        if problem:
            return name, "FAIL", "exit 0 with a broken mesh: " + problem, took
        shape = case.get("shape")
        if shape:
            worst = max(shape_error(shape[0], shape[1], x) for x in v)
            if worst > 0.06:
                return name, "FAIL", "mesh is %.3g off the %s it should be" % (worst, shape[0]), took
        os.remove(out)
        return name, "ok", "%d triangles" % len(t), took
    if p.returncode == 1:
        if expect == "ok":
            return name, "FAIL", "expected a mesh, got: " + err.strip(), took
        if len(lines) != 1 or not lines[0].startswith("gmpu-reconstruct: "):
            return name, "FAIL", "exit 1 needs one 'gmpu-reconstruct: ' line on stderr, got:\n" + err[:2000], took
        if any(ord(ch) < 32 and ch != "\t" for ch in lines[0]):
            return name, "FAIL", "control characters in the message: %r" % lines[0][:300], took
        if "GMPU_ERROR_INTERNAL" in err:
            return name, "FAIL", "an internal error: " + err.strip(), took
        if os.path.exists(out):
            return name, "FAIL", "exit 1 but the output exists", took
        return name, "error", lines[0], took
    return name, "FAIL", "exit status %d: %s" % (p.returncode, err[-2000:]), took


def run(cli, corpus, jobs, timeout):
    with open(os.path.join(corpus, "manifest.json")) as f:
        manifest = json.load(f)
    in_dir = os.path.join(corpus, "in")
    out_dir = os.path.join(corpus, "out")
    os.makedirs(out_dir, exist_ok=True)
    start = time.monotonic()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        results = list(pool.map(lambda kv: run_one(cli, in_dir, out_dir, kv[0], kv[1], timeout),
                                sorted(manifest.items())))
    failed = [r for r in results if r[1] == "FAIL"]
    verbose = os.environ.get("GMPU_HOSTILE_VERBOSE")
    for name, result, detail, took in results:
        if result == "FAIL" or verbose:
            print("%-36s %-5s %5.2fs  %s" % (name, result, took, detail))
    slowest = max(results, key=lambda r: r[3])
    print("hostile corpus: %d files, %d reconstructed, %d clean errors, %d FAILED in %.1f s (slowest %s, %.1f s)"
          % (len(results), sum(r[1] == "ok" for r in results), sum(r[1] == "error" for r in results), len(failed),
             time.monotonic() - start, slowest[0], slowest[3]))
    return 1 if failed else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    g = sub.add_parser("generate")
    g.add_argument("dir")
    g.add_argument("--seed", type=int, default=20240601)
    r = sub.add_parser("run")
    r.add_argument("cli")
    r.add_argument("dir")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    r.add_argument("--timeout", type=int, default=120)
    a = ap.parse_args()
    if a.cmd == "generate":
        generate(a.dir, a.seed)
        return 0
    return run(os.path.abspath(a.cli), a.dir, a.jobs, a.timeout)


if __name__ == "__main__":
    sys.exit(main())
