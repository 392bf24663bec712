#!/usr/bin/env python3
"""How sharp a reconstructed mesh keeps the sharp edges of its ground truth.

The sharp edges of the true mesh are its edges whose dihedral angle exceeds --crease
(degrees). The measure is the area-weighted mean angle (degrees) between the normal of each
output triangle whose centroid lies within --band (a share of the true mesh's bounding-box
diagonal) of a sharp edge and the true normal there: the normal of the true triangle nearest
to the centroid. A mesh that rounds the edge over a few grid cubes scores tens of degrees; a
mesh with the crease in place scores near the smooth-surface error.

    /usr/bin/python3 tests/bench/sharp_edges.py OUT.ply TRUE.off [--band 0.01] [--crease 30]

prints {"sharp_edge_angle": degrees, "triangles_near_edges": n, "sharp_edges": m} as JSON.
Needs numpy and scipy.
"""
import argparse
import json
import sys

import numpy as np
from scipy.spatial import cKDTree

PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
             "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
             "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def read_off(path):
    words = _off_words(path)
    if not words[0].endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    at = 4
    v = np.array(words[at:at + 3 * nv], dtype=float).reshape(nv, 3)
    at += 3 * nv
    faces = []
    for _ in range(nf):
        k = int(words[at])
        poly = [int(w) for w in words[at + 1:at + 1 + k]]
        at += 1 + k
        faces += [(poly[0], poly[i], poly[i + 1]) for i in range(1, k - 1)]  # fan
    return v, np.array(faces, dtype=np.int64)


def _off_words(path):
    words = []
    with open(path) as f:
        for line in f:
            words += line.split("#", 1)[0].split()
    return words


def read_ply(path):
    """Vertices and triangles of a PLY mesh (ascii or binary little-endian)."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        body = f.read()
    fmt = next(l.split()[1] for l in header if l.startswith("format"))
    elements, current = [], None
    for l in header:
        w = l.split()
        if w[0] == "element":
            current = {"name": w[1], "count": int(w[2]), "props": []}
            elements.append(current)
        elif w[0] == "property":
            current["props"].append(w[1:])
    if fmt == "ascii":
        return _ply_ascii(body.decode("ascii").split(), elements)
    if fmt != "binary_little_endian":
        raise ValueError(f"{path}: PLY format {fmt} not read here")
    at, verts, tris = 0, None, None
    for e in elements:
        if e["name"] == "vertex":
            dt = np.dtype([(p[-1], "<" + PLY_TYPES[p[0]]) for p in e["props"]])
            a = np.frombuffer(body, dtype=dt, count=e["count"], offset=at)
            at += dt.itemsize * e["count"]
            verts = np.stack([a["x"], a["y"], a["z"]], axis=1).astype(float)
        elif e["name"] == "face":
            p = e["props"][0]
            count_t, index_t = "<" + PLY_TYPES[p[1]], "<" + PLY_TYPES[p[2]]
            # gmpu writes triangles only: a fixed record of count + 3 indices
            dt = np.dtype([("n", count_t), ("i", index_t, (3,))])
            a = np.frombuffer(body, dtype=dt, count=e["count"], offset=at)
            if len(a) and not (a["n"] == 3).all():
                raise ValueError(f"{path}: non-triangle faces")
            at += dt.itemsize * e["count"]
            tris = a["i"].astype(np.int64)
        else:
            raise ValueError(f"{path}: element {e['name']} not read here")
    return verts, tris


def _ply_ascii(words, elements):
    at, verts, tris = 0, None, []
    for e in elements:
        if e["name"] == "vertex":
            k = len(e["props"])
            a = np.array(words[at:at + k * e["count"]], dtype=float).reshape(e["count"], k)
            at += k * e["count"]
            names = [p[-1] for p in e["props"]]
            verts = a[:, [names.index("x"), names.index("y"), names.index("z")]]
        elif e["name"] == "face":
            for _ in range(e["count"]):
                k = int(words[at])
                poly = [int(w) for w in words[at + 1:at + 1 + k]]
                at += 1 + k
                tris += [(poly[0], poly[i], poly[i + 1]) for i in range(1, k - 1)]
    return verts, np.array(tris, dtype=np.int64)


def read_mesh(path):
    return read_off(path) if str(path).lower().endswith(".off") else read_ply(path)


def face_normals(v, f):
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    area = 0.5 * np.linalg.norm(n, axis=1)
    return n / np.maximum(2 * area, 1e-300)[:, None], area


def sharp_edge_samples(v, f, crease_degrees, spacing):
    """Points along the true mesh's sharp edges, `spacing` apart."""
    n, _ = face_normals(v, f)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    owner = np.tile(np.arange(len(f)), 3)
    key = np.sort(e, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, owner = key[order], owner[order]
    same = (key[1:] == key[:-1]).all(axis=1)
    a, b = owner[:-1][same], owner[1:][same]  # the two faces of each interior edge
    cos = np.clip((n[a] * n[b]).sum(axis=1), -1, 1)
    sharp = key[:-1][same][np.degrees(np.arccos(cos)) > crease_degrees]
    pts = []
    p, q = v[sharp[:, 0]], v[sharp[:, 1]]
    for i in range(len(sharp)):
        k = max(2, int(np.ceil(np.linalg.norm(q[i] - p[i]) / spacing)) + 1)
        t = np.linspace(0, 1, k)[:, None]
        pts.append(p[i] + t * (q[i] - p[i]))
    return (np.concatenate(pts) if pts else np.zeros((0, 3))), len(sharp)


def surface_samples(v, f, count, rng):
    """Area-weighted points on the true mesh with the face each lies on."""
    _, area = face_normals(v, f)
    face = rng.choice(len(f), size=count, p=area / area.sum())
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    a, b, c = v[f[face, 0]], v[f[face, 1]], v[f[face, 2]]
    pts = (1 - s)[:, None] * a + (s * (1 - r2))[:, None] * b + (s * r2)[:, None] * c
    # the true mesh's vertices too, so the nearest-face lookup never misses a small face
    return np.concatenate([pts, (a + b + c) / 3]), np.concatenate([face, face])


def sharp_edge_angle(mesh_path, gt_path, band=0.01, crease=30.0, samples=2_000_000, seed=1):
    gv, gf = read_mesh(gt_path)
    diagonal = float(np.linalg.norm(gv.max(axis=0) - gv.min(axis=0)))
    edge_pts, sharp_count = sharp_edge_samples(gv, gf, crease, 0.1 * band * diagonal)
    ov, of = read_mesh(mesh_path)
    on, oarea = face_normals(ov, of)
    centroid = ov[of].mean(axis=1)
    if not len(edge_pts):
        return {"sharp_edge_angle": None, "triangles_near_edges": 0, "sharp_edges": 0}
    d, _ = cKDTree(edge_pts).query(centroid, distance_upper_bound=band * diagonal)
    near = np.isfinite(d)
    gn, _ = face_normals(gv, gf)
    pts, face = surface_samples(gv, gf, samples, np.random.default_rng(seed))
    _, nearest = cKDTree(pts).query(centroid[near])
    true_n = gn[face[nearest]]
    # |cos|: the geometry is measured here, the orientation elsewhere
    angle = np.degrees(np.arccos(np.clip(np.abs((on[near] * true_n).sum(axis=1)), 0, 1)))
    w = oarea[near]
    return {"sharp_edge_angle": float((angle * w).sum() / max(w.sum(), 1e-300)),
            "triangles_near_edges": int(near.sum()), "sharp_edges": int(sharp_count)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("gt")
    ap.add_argument("--band", type=float, default=0.01)
    ap.add_argument("--crease", type=float, default=30.0)
    a = ap.parse_args()
    print(json.dumps(sharp_edge_angle(a.mesh, a.gt, a.band, a.crease)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
