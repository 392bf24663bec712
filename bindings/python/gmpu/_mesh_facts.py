"""What a triangle mesh is, computed from its arrays with numpy: closed or not, enclosed
volume, area, connected pieces, genus. Used by gmpu.Mesh's properties."""
from __future__ import annotations

import numpy as np

__all__ = ["is_watertight", "volume", "area", "components", "genus"]


def _edges(faces: np.ndarray) -> np.ndarray:
    """Every triangle's three directed edges (a, b), as an (3m, 2) int64 array."""
    f = faces.astype(np.int64)
    return np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])


def is_watertight(faces: np.ndarray) -> bool:
    """Closed and consistently wound: every edge is shared by exactly two triangles that
    cross it in opposite directions (each directed edge occurs once, its reverse once)."""
    if len(faces) == 0:
        return False
    e = _edges(faces)
    directed, counts = np.unique(e, axis=0, return_counts=True)
    if (counts != 1).any():
        return False
    # Every directed edge's reverse is present: sorted, both lists are the same.
    reverse = np.unique(e[:, ::-1], axis=0)
    return bool(np.array_equal(directed, reverse))


def _corners(vertices: np.ndarray, faces: np.ndarray):
    v = np.asarray(vertices, dtype=np.float64)
    return (v[faces[:, k]] for k in range(3))


def volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The enclosed volume by the divergence theorem (the sum of the signed tetrahedra on the
    origin): positive for an outward-wound closed mesh. Meaningless for an open one."""
    a, b, c = _corners(vertices, faces)
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)


def area(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The summed area of the triangles."""
    a, b, c = _corners(vertices, faces)
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2.0)


def _labels(n: int, faces: np.ndarray) -> np.ndarray:
    """A component label per vertex (the smallest vertex index of its piece): labels are
    lowered along the edges and then by pointer jumping until nothing changes."""
    labels = np.arange(n)
    e = _edges(faces)
    while True:
        before = labels.copy()
        low = np.minimum(labels[e[:, 0]], labels[e[:, 1]])
        np.minimum.at(labels, e[:, 0], low)
        np.minimum.at(labels, e[:, 1], low)
        labels = labels[labels]
        if np.array_equal(labels, before):
            return labels


def components(vertex_count: int, faces: np.ndarray) -> int:
    """Connected pieces: triangles linked through shared vertices (unused vertices are no piece)."""
    if len(faces) == 0:
        return 0
    labels = _labels(vertex_count, faces)
    return int(len(np.unique(labels[np.unique(faces)])))


def genus(vertex_count: int, faces: np.ndarray) -> int:
    """Handles of a closed mesh, summed over its pieces: from V - E + F = 2 (C - g)."""
    if not is_watertight(faces):
        raise ValueError("genus: the mesh is not closed (see is_watertight)")
    used = len(np.unique(faces))
    edges = len(faces) * 3 // 2
    euler = used - edges + len(faces)
    return int((2 * components(vertex_count, faces) - euler) // 2)
