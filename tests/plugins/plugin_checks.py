"""What the Blender and ParaView headless suites both check, with numpy only (both hosts run
Debian's Python 3.11, which has it): the C CLI's mesh for the same input and parameters, a
PLY reader for it, closedness, and equality of two meshes.

A host stores vertices at its own precision (Blender: float32), so coordinates are compared
within a tolerance relative to the mesh's size; counts and triangles must be identical.
"""
from __future__ import annotations

import os
import subprocess
import tempfile
from typing import Dict, Tuple

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CLOUD = os.path.join(ROOT, "tests", "data", "clouds", "elephant_sparse5k.ply")

# Two parameter sets, both explicit and away from the defaults, so a host that drops a
# parameter makes a different mesh; small enough to run in seconds.
RUNS = (
    {"error": 0.004, "max_depth": 6, "resolution": 40, "noise_scale": 1.75, "sharp_features": False, "threads": 2},
    {"error": 0.003, "max_depth": 7, "resolution": 56, "noise_scale": 0.0, "sharp_features": False, "threads": 1},
)

_CLI_FLAGS = {"error": "--error", "max_depth": "--max-depth", "resolution": "--resolution",
              "noise_scale": "--noise-scale", "threads": "--threads"}

_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
          "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
          "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def build_dir() -> str:
    return os.path.abspath(os.environ.get("GMPU_BUILD", os.path.join(ROOT, "build")))


def library_path() -> str:
    return os.path.join(build_dir(), "lib", "libgmpu.so.1")


def cli_flags(params: Dict) -> list:
    flags = []
    for name, flag in _CLI_FLAGS.items():
        flags += [flag, repr(params[name])]
    if params.get("sharp_features"):
        flags.append("--sharp")
    return flags


def cli_mesh(cloud: str, params: Dict) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices n×3 float64, faces m×3 int64) from build/examples/gmpu-reconstruct."""
    cli = os.path.join(build_dir(), "examples", "gmpu-reconstruct")
    with tempfile.TemporaryDirectory(prefix="gmpu-plugin-") as tmp:
        out = os.path.join(tmp, "mesh.ply")
        subprocess.run([cli, cloud, "-o", out, "--quiet"] + cli_flags(params), check=True)
        return read_mesh_ply(out)


def read_mesh_ply(path: str) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices (x y z) and triangles of a binary little-endian PLY, as gmpu writes them."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header")
    body = data.index(b"\n", end) + 1
    header = data[:body].decode("ascii").split("\n")
    if "format binary_little_endian 1.0" not in header:
        raise ValueError(f"{path}: expected a binary little-endian PLY")
    elements, current = [], None
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            current = (w[1], int(w[2]), [])
            elements.append(current)
        elif w[:1] == ["property"]:
            current[2].append(w[1:])
    offset, vertices, faces = body, None, None
    for name, count, props in elements:
        if name == "vertex":
            dtype = np.dtype([(p[1], "<" + _TYPES[p[0]]) for p in props])
            rec = np.frombuffer(data, dtype, count, offset)
            offset += dtype.itemsize * count
            vertices = np.stack([rec["x"], rec["y"], rec["z"]], axis=1).astype(np.float64)
        elif name == "face":
            (_, count_type, index_type, _), = props
            dtype = np.dtype([("n", "<" + _TYPES[count_type]), ("i", "<" + _TYPES[index_type], 3)])
            rec = np.frombuffer(data, dtype, count, offset)
            if count and not (rec["n"] == 3).all():
                raise ValueError(f"{path}: not a triangle mesh")
            offset += dtype.itemsize * count
            faces = rec["i"].astype(np.int64)
    return vertices, faces


def closed_problem(faces: np.ndarray) -> str:
    """'' if every edge is shared by exactly two triangles, else what is wrong."""
    if len(faces) == 0:
        return "no triangles"
    f = np.asarray(faces, dtype=np.int64)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    bad = int((counts != 2).sum())
    return f"{bad} of {len(counts)} edges are not shared by exactly two triangles" if bad else ""


def difference(vertices, faces, ref_vertices, ref_faces, rel_tol: float) -> str:
    """'' if the meshes are equal (counts, triangles, coordinates within rel_tol × the
    reference's bounding-box diagonal), else the first difference found."""
    v, f = np.asarray(vertices, np.float64), np.asarray(faces, np.int64)
    if v.shape != ref_vertices.shape:
        return f"{len(v)} vertices, the CLI made {len(ref_vertices)}"
    if f.shape != ref_faces.shape:
        return f"{len(f)} triangles, the CLI made {len(ref_faces)}"
    if not np.array_equal(f, ref_faces):
        first = int(np.argmax((f != ref_faces).any(axis=1)))
        return f"triangle {first} is {f[first].tolist()}, the CLI's is {ref_faces[first].tolist()}"
    diagonal = float(np.linalg.norm(ref_vertices.max(axis=0) - ref_vertices.min(axis=0)))
    worst = float(np.abs(v - ref_vertices).max()) if len(v) else 0.0
    if worst > rel_tol * diagonal:
        return f"coordinates differ by up to {worst:.3g} (tolerance {rel_tol * diagonal:.3g})"
    return ""
