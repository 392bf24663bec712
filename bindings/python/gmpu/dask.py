"""Tiled reconstruction on Dask: clouds larger than one process, one mesh.

    >>> from gmpu.dask import reconstruct                     # doctest: +SKIP
    >>> mesh = reconstruct("city.ply", client=client)         # doctest: +SKIP

    python3 -m gmpu.dask INPUT -o OUT [--scheduler ADDRESS | --local-workers N [--in-process]]

How (issue 17):

1. **Tiles.** The cloud's box is covered by one global grid (cubes of side ``cell``, cut in
   blocks of 8³ cubes) and split kd-wise, on block boundaries, into tiles of about
   ``tile_points`` points. A tile task reads only its points — its box plus an overlap
   margin — fits and orients a gmpu surface on them, finds its *band* (the blocks it owns
   within ``band_cells`` cubes of a point) and evaluates f at the corners its band blocks own
   (gmpu_surface_evaluate_grid: corners 8·b .. 8·b + 7, so every corner has one owner).
2. **Global orientation.** Each tile also returns the oriented normals of a fixed subsample
   of its overlap points. Two tiles agree when their normals on the points both hold point
   the same way; a maximum spanning tree of the tile graph on |agreement| fixes one flip per
   tile (a tile's own orientation of an open patch is a guess). Then the outward pass: per
   connected group of tiles, the band corners next to the far region that touches the
   grid's edge must be outside (f < 0); if most are not, the group is flipped.
3. **Far regions.** Blocks outside every tile's band form regions (6-connected); the one
   at the grid's edge is outside, each enclosed one (the inside of a thick solid) takes the
   sign most band corners beside it have. A corner touching a far block takes its region's
   sign (outside wins), as in the one-process polygonizer, so every surface closes.
4. **Seamless union.** A march task gets its own corner values plus the first corner layer
   of its +x/+y/+z neighbour blocks from the tiles that own them, and marches its blocks
   (gmpu_grid_polygonize). Shared corners have one value, so both sides cut a shared face
   identically; vertices are keyed by lattice edge and welded by key into one closed mesh.

Every task is a pure function of its inputs, so a worker lost mid-run is recomputed by Dask
and the mesh is the same.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ._core import Mesh, Surface, read_points
from ._errors import check
from ._library import ffi, lib

__all__ = ["reconstruct", "Grid", "TilePlan", "plan_tiles", "main"]

BLOCK = 8  # cubes per block side: the C ABI's
_OWNED = BLOCK ** 3
# The normals of at most this many overlap points per tile are compared with the neighbours'.
_SHARED_SAMPLE = 20000
# Points read per chunk when a tile scans a file.
_CHUNK = 1 << 19


# ---- input ------------------------------------------------------------------------------

_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def _ply_layout(path: str) -> Optional[Tuple[int, np.dtype, int]]:
    """(data offset, vertex dtype, count) when `path` is a binary little-endian PLY whose
    first element is the vertices with scalar properties only (then it can be memory-mapped);
    None otherwise."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            return None
        fmt, fields, count, element = None, [], None, None
        while True:
            line = f.readline()
            if not line:
                return None
            words = line.decode("ascii", "replace").split()
            if not words:
                continue
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                element = words[1]
                if element == "vertex" and count is None:
                    count = int(words[2])
                elif count is None:
                    return None  # something before the vertices
            elif words[0] == "property" and element == "vertex":
                if words[1] == "list" or words[1] not in _PLY_TYPES:
                    return None
                fields.append((words[2], "<" + _PLY_TYPES[words[1]]))
            elif words[0] == "end_header":
                break
        if fmt != "binary_little_endian" or count is None:
            return None
        names = [n for n, _ in fields]
        if not all(a in names for a in "xyz"):
            return None
        return f.tell(), np.dtype(fields), count


class _Source:
    """The points, as every task sees them: a memory-mapped PLY (each task maps the file and
    keeps only what it needs) or an in-memory array."""

    def __init__(self, path: Optional[str] = None, array: Optional[np.ndarray] = None):
        self.path, self.array = path, array
        self.layout = _ply_layout(path) if path is not None else None
        if path is not None and self.layout is None:
            self.array, self.path = np.ascontiguousarray(read_points(path).positions, dtype=np.float64), None
        self.count = self.layout[2] if self.layout else len(self.array)

    def _mapped(self):
        offset, dtype, count = self.layout
        return np.memmap(self.path, dtype=dtype, mode="r", offset=offset, shape=(count,))

    def chunks(self, step: int = 1):
        """(first index, xyz float64) per chunk; with step > 1 every step-th point only."""
        if self.layout is None:
            for start in range(0, self.count, _CHUNK):
                yield start, self.array[start:start + _CHUNK:step]
            return
        m = self._mapped()
        for start in range(0, self.count, _CHUNK):
            rows = m[start:start + _CHUNK:step]
            yield start, np.stack([rows["x"], rows["y"], rows["z"]], axis=1).astype(np.float64)

    def select(self, lo: np.ndarray, hi: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Indices and positions of the points in the box [lo, hi)."""
        idx, xyz = [], []
        for start, p in self.chunks():
            keep = np.all((p >= lo) & (p < hi), axis=1)
            idx.append(np.flatnonzero(keep) + start)
            xyz.append(p[keep])
        return np.concatenate(idx), np.concatenate(xyz)

    def sample(self, wanted: int) -> np.ndarray:
        step = max(1, self.count // wanted)
        return np.concatenate([p for _, p in self.chunks(step)]) if step > 1 else \
            np.concatenate([p for _, p in self.chunks()])


# ---- the plan: grid and tiles -------------------------------------------------------------


@dataclass
class Grid:
    """The global grid: cubes of side `cell` from `origin`, `cells` cubes a side (multiples
    of 8)."""
    origin: np.ndarray
    cell: float
    cells: np.ndarray

    @property
    def blocks(self) -> np.ndarray:
        return self.cells // BLOCK

    def block_key(self, b: np.ndarray) -> np.ndarray:
        nb = self.blocks
        return b[..., 0] + nb[0] * (b[..., 1] + nb[1] * b[..., 2])

    def block_of_key(self, key: np.ndarray) -> np.ndarray:
        nb = self.blocks
        return np.stack([key % nb[0], key // nb[0] % nb[1], key // (nb[0] * nb[1])], axis=-1)


@dataclass
class TilePlan:
    grid: Grid
    tiles: List[Tuple[np.ndarray, np.ndarray]]  # owned blocks [lo, hi) per tile
    margin: float                                # overlap margin, caller's units
    band_radius: float


def _spacing(sample: np.ndarray, total: int) -> float:
    """Typical distance between neighbouring points of the whole cloud, from a sample (on a
    surface, spacing scales as 1/√density)."""
    from scipy.spatial import cKDTree
    d, _ = cKDTree(sample).query(sample, k=2)
    return float(np.median(d[:, 1])) * np.sqrt(len(sample) / max(total, 1))


def plan_tiles(sample: np.ndarray, total: int, lo: np.ndarray, hi: np.ndarray, *, tile_points: int,
               resolution: int = 0, band_cells: float = 3.0, margin_cells: float = 16.0) -> TilePlan:
    """The grid and a kd split of its blocks (at the sample's median, on block boundaries)
    into 2^k tiles of at most about `tile_points` points each (the sample stands for the
    `total` points of the cloud)."""
    extent = hi - lo
    if resolution > 0:
        cell = float(extent.max()) / resolution
    else:
        cell = 1.5 * _spacing(sample, total)
    band_radius = band_cells * cell
    margin = max(margin_cells * cell, band_radius + 2 * cell)
    pad = band_radius + 2 * BLOCK * cell  # the band never reaches the grid's edge
    origin = lo - pad
    cells = (np.ceil((extent + 2 * pad) / (BLOCK * cell)).astype(np.int64) * BLOCK)
    grid = Grid(origin, cell, cells)
    sample_blocks = np.floor((sample - origin) / (BLOCK * cell)).astype(np.int64)
    tiles = []

    # Every tile split to the same depth: 2^depth tiles, each about total / 2^depth points.
    depth = int(np.ceil(np.log2(max(total / tile_points, 1.0))))

    def split(bl, bh, members, level=0):
        if level >= depth or np.all(bh - bl <= 1):
            tiles.append((bl, bh))
            return
        sizes = bh - bl
        axis = int(np.argmax(sizes))
        cut = int(np.median(sample_blocks[members, axis])) if len(members) else int((bl[axis] + bh[axis]) // 2)
        cut = min(max(cut, bl[axis] + 1), bh[axis] - 1)
        low = members[sample_blocks[members, axis] < cut]
        high = members[sample_blocks[members, axis] >= cut]
        h1 = bh.copy(); h1[axis] = cut
        l2 = bl.copy(); l2[axis] = cut
        split(bl, h1, low, level + 1)
        split(l2, bh, high, level + 1)

    split(np.zeros(3, np.int64), grid.blocks.copy(), np.arange(len(sample)))
    return TilePlan(grid, tiles, margin, band_radius)


# ---- tile tasks -----------------------------------------------------------------------------


def _evaluate_grid(surface: Surface, grid: Grid, blocks: np.ndarray) -> np.ndarray:
    values = np.empty((len(blocks), _OWNED), np.float64)
    b = np.ascontiguousarray(blocks, dtype=np.int64)
    origin = np.ascontiguousarray(grid.origin, dtype=np.float64)

    def body(s):
        check(lib.gmpu_surface_evaluate_grid(s, ffi.from_buffer("double[]", origin), grid.cell,
                                             ffi.from_buffer("int64_t[]", b), len(b),
                                             ffi.from_buffer("double[]", values)),
              "gmpu_surface_evaluate_grid")
    surface._read(body)
    return values


def _band_blocks(points: np.ndarray, grid: Grid, radius: float, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The blocks in [lo, hi) within `radius` of some point (by their boxes)."""
    size = BLOCK * grid.cell
    a = np.floor((points - radius - grid.origin) / size).astype(np.int64)
    b = np.floor((points + radius - grid.origin) / size).astype(np.int64)
    found = []
    span = int((b - a).max()) if len(points) else 0
    for dz in range(span + 1):
        for dy in range(span + 1):
            for dx in range(span + 1):
                c = a + np.array([dx, dy, dz])
                ok = np.all((c <= b) & (c >= lo) & (c < hi), axis=1)
                found.append(grid.block_key(c[ok]))
    keys = np.unique(np.concatenate(found)) if found else np.zeros(0, np.int64)
    return keys


def _tile_surface(source: Any, plan: TilePlan, tile: int, params: Dict[str, Any], reverse: bool = False) -> Dict[str, Any]:
    """Phase 1 of a tile: its points, surface, band and corner values, and the normals of its
    overlap sample. `reverse` (tests) turns the tile's surface over, as if its own
    orientation had guessed wrong."""
    if not isinstance(source, _Source):
        source = _Source(array=source)
    g = plan.grid
    bl, bh = plan.tiles[tile]
    own_lo = g.origin + bl * BLOCK * g.cell
    own_hi = g.origin + bh * BLOCK * g.cell
    idx, xyz = source.select(own_lo - plan.margin, own_hi + plan.margin)
    keys = _band_blocks(xyz, g, plan.band_radius, bl, bh)
    out: Dict[str, Any] = {"tile": tile, "points": len(idx), "keys": keys}
    if len(keys) == 0:
        out.update(values=np.zeros((0, _OWNED), np.float32), faces=np.zeros((0, 6), np.int64),
                   shared=np.zeros(0, np.int64), normals=np.zeros((0, 3), np.float32))
        return out
    with Surface(xyz, **params) as s:
        s.fit()
        s.orient()
        values = _evaluate_grid(s, g, g.block_of_key(keys))
        normals = s.normals
    if reverse:
        values, normals = -values, -normals
    v = values.reshape(-1, BLOCK, BLOCK, BLOCK)  # [block, k, j, i]
    sg = np.sign(v)
    # Sign sums of the corner layer nearest each face (−x, +x, −y, +y, −z, +z): the votes of
    # the far regions beside the block.
    out["faces"] = np.stack([sg[:, :, :, 0].sum((1, 2)), sg[:, :, :, -1].sum((1, 2)),
                             sg[:, :, 0, :].sum((1, 2)), sg[:, :, -1, :].sum((1, 2)),
                             sg[:, 0, :, :].sum((1, 2)), sg[:, -1, :, :].sum((1, 2))], axis=1).astype(np.int64)
    out["values"] = values.astype(np.float32)
    # Overlap points: those some other tile holds too. A subsample fixed by global index, so
    # both tiles pick the same points.
    inner = np.all((xyz >= own_lo + plan.margin) & (xyz < own_hi - plan.margin), axis=1)
    stride = max(1, source.count // (len(plan.tiles) * _SHARED_SAMPLE))
    shared = (~inner) & (idx % stride == 0)
    out["shared"] = idx[shared]
    out["normals"] = normals[shared].astype(np.float32)
    return out


def _summary(result: Dict[str, Any]) -> Dict[str, Any]:
    return {k: v for k, v in result.items() if k != "values"}


def _take(result: Dict[str, Any], keys: np.ndarray, flip: int) -> Tuple[np.ndarray, np.ndarray]:
    """The corner values of some of a tile's blocks, signed by the tile's flip."""
    pos = np.searchsorted(result["keys"], keys)
    return keys, result["values"][pos] * np.float32(flip)


# Corner c (0..8) of a block touches the blocks at offsets TOUCH[c] (−1, 0, +1 → 0, 1, 2).
_TOUCH = np.zeros((BLOCK + 1, 3), np.float32)
_TOUCH[0, 0] = _TOUCH[0, 1] = 1
_TOUCH[1:BLOCK, 1] = 1
_TOUCH[BLOCK, 1] = _TOUCH[BLOCK, 2] = 1


def _forced(far: np.ndarray) -> np.ndarray:
    """Per block corner [n, k, j, i]: −1 when it touches an outside far block, +1 an inside one
    only, 0 none; `far` is [n, dz, dy, dx] the far signs of the 27 blocks around."""
    t = _TOUCH
    neg = np.einsum("kc,jb,ia,ncba->nkji", t, t, t, (far < 0).astype(np.float32)) > 0
    pos = np.einsum("kc,jb,ia,ncba->nkji", t, t, t, (far > 0).astype(np.float32)) > 0
    return np.where(neg, -1, np.where(pos, 1, 0)).astype(np.int8)


def _corner_values(keys: np.ndarray, grid: Grid, avail_keys: np.ndarray, avail_values: np.ndarray,
                   far: np.ndarray) -> np.ndarray:
    """The 9³ corner values of each block of `keys`: its own corners, its +x/+y/+z neighbours'
    first layers (from the available blocks), far-forced corners at ±cell."""
    n = len(keys)
    C = BLOCK + 1
    corners = np.full((n, C, C, C), np.nan, np.float64)
    V = avail_values.reshape(-1, BLOCK, BLOCK, BLOCK)
    b = grid.block_of_key(keys)
    for oz in (0, 1):
        for oy in (0, 1):
            for ox in (0, 1):
                nb = b + np.array([ox, oy, oz])
                inside = np.all(nb < grid.blocks, axis=1)
                nk = grid.block_key(np.where(inside[:, None], nb, 0))
                pos = np.clip(np.searchsorted(avail_keys, nk), 0, len(avail_keys) - 1)
                have = inside & (avail_keys[pos] == nk)
                ks = slice(BLOCK, C) if oz else slice(0, BLOCK)
                js = slice(BLOCK, C) if oy else slice(0, BLOCK)
                is_ = slice(BLOCK, C) if ox else slice(0, BLOCK)
                src = V[pos[have]][:, slice(0, 1) if oz else slice(0, BLOCK),
                                   slice(0, 1) if oy else slice(0, BLOCK), slice(0, 1) if ox else slice(0, BLOCK)]
                view = corners[:, ks, js, is_]  # a view: writing it fills corners
                view[have] = src
    forced = _forced(far)
    corners = np.where(forced != 0, forced * grid.cell, corners)
    if np.isnan(corners).any():
        raise RuntimeError("gmpu.dask: a corner has no value (a band block's neighbour went missing)")
    return corners


def _march(own: Dict[str, Any], flip: int, foreign: Sequence[Tuple[np.ndarray, np.ndarray]], far: np.ndarray,
           grid: Grid) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Phase 2 of a tile: its blocks marched with every corner known. Returns vertices,
    triangles and the vertices' lattice-edge keys."""
    keys = own["keys"]
    if len(keys) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.uint32), np.zeros(0, np.uint64)
    avail_keys = np.concatenate([keys] + [k for k, _ in foreign])
    avail_values = np.concatenate([own["values"] * np.float32(flip)] + [v for _, v in foreign])
    order = np.argsort(avail_keys, kind="stable")
    corners = _corner_values(keys, grid, avail_keys[order], avail_values[order], far)
    blocks = np.ascontiguousarray(grid.block_of_key(keys), dtype=np.int64)
    origin = np.ascontiguousarray(grid.origin, dtype=np.float64)
    cells = np.ascontiguousarray(grid.cells, dtype=np.int64)
    corners = np.ascontiguousarray(corners)
    out = ffi.new("gmpu_mesh **")
    check(lib.gmpu_grid_polygonize(ffi.from_buffer("double[]", origin), grid.cell, ffi.from_buffer("int64_t[]", cells),
                                   ffi.from_buffer("int64_t[]", blocks), len(blocks),
                                   ffi.from_buffer("double[]", corners), out), "gmpu_grid_polygonize")
    m = ffi.gc(out[0], lib.gmpu_mesh_destroy)
    nv, nt = lib.gmpu_mesh_vertex_count(m), lib.gmpu_mesh_triangle_count(m)
    if nv == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.uint32), np.zeros(0, np.uint64)
    vertices = np.frombuffer(ffi.buffer(lib.gmpu_mesh_vertices(m), 24 * nv), np.float64).reshape(nv, 3).copy()
    triangles = np.frombuffer(ffi.buffer(lib.gmpu_mesh_triangles(m), 12 * nt), np.uint32).reshape(nt, 3).copy()
    edge_keys = np.frombuffer(ffi.buffer(lib.gmpu_mesh_grid_keys(m), 8 * nv), np.uint64).copy()
    return vertices, triangles, edge_keys


# ---- the driver's steps -------------------------------------------------------------------


def reconcile_signs(summaries: Sequence[Dict[str, Any]]) -> Tuple[np.ndarray, np.ndarray]:
    """One flip (±1) per tile so that tiles agree on their shared points, and the group
    (connected part of the tile graph) of each tile. Maximum spanning tree on |agreement|."""
    n = len(summaries)
    edges = []
    for a in range(n):
        for b in range(a + 1, n):
            sa, sb = summaries[a]["shared"], summaries[b]["shared"]
            common, ia, ib = np.intersect1d(sa, sb, assume_unique=True, return_indices=True)
            if len(common) == 0:
                continue
            agree = float(np.einsum("ij,ij->", summaries[a]["normals"][ia].astype(np.float64),
                                    summaries[b]["normals"][ib].astype(np.float64)))
            if agree != 0:
                edges.append((abs(agree), a, b, 1 if agree > 0 else -1))
    edges.sort(key=lambda e: -e[0])
    parent = list(range(n))

    def root(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    tree: Dict[int, List[Tuple[int, int]]] = {i: [] for i in range(n)}
    for _, a, b, s in edges:
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[ra] = rb
            tree[a].append((b, s))
            tree[b].append((a, s))
    flip = np.zeros(n, np.int64)
    group = np.zeros(n, np.int64)
    groups = 0
    for start in range(n):
        if flip[start] != 0:
            continue
        flip[start] = 1
        group[start] = groups
        queue = [start]
        while queue:
            t = queue.pop()
            for u, s in tree[t]:
                if flip[u] == 0:
                    flip[u] = flip[t] * s
                    group[u] = groups
                    queue.append(u)
        groups += 1
    return flip, group


_FACE_STEPS = np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]])


def far_signs(grid: Grid, summaries: Sequence[Dict[str, Any]], flip: np.ndarray,
              group: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The outward pass and the far regions' signs. Returns the flips (groups whose band is
    mostly inside next to the outer region turned over), the block grid's region labels and
    each region's sign (index 0: band)."""
    from scipy import ndimage
    nb = grid.blocks
    band = np.zeros(int(np.prod(nb)), bool)
    for s in summaries:
        band[s["keys"]] = True
    labels, count = ndimage.label(~band.reshape(nb[2], nb[1], nb[0]))
    labels = labels.reshape(-1)
    outer = labels[0]
    flip = flip.copy()
    votes = np.zeros(count + 1, np.float64)
    outer_votes = np.zeros(int(group.max()) + 1 if len(group) else 0, np.float64)
    per_tile = []
    for t, s in enumerate(summaries):
        if len(s["keys"]) == 0:
            per_tile.append(None)
            continue
        b = grid.block_of_key(s["keys"])
        lab = np.zeros((len(b), 6), np.int64)
        for f in range(6):
            c = b + _FACE_STEPS[f]
            lab[:, f] = labels[grid.block_key(c)]
        per_tile.append(lab)
        outer_votes[group[t]] += float((s["faces"] * (lab == outer)).sum()) * flip[t]
    for g in range(len(outer_votes)):
        if outer_votes[g] > 0:  # the group's band is mostly inside next to the outside
            flip[group == g] *= -1
    for t, s in enumerate(summaries):
        lab = per_tile[t]
        if lab is None:
            continue
        np.add.at(votes, lab.reshape(-1), (s["faces"] * flip[t]).reshape(-1))
    sign = np.where(votes > 0, 1, -1).astype(np.int8)
    sign[0] = 0
    sign[outer] = -1
    return flip, labels, sign


def _neighbourhood(grid: Grid, keys: np.ndarray, labels: np.ndarray, sign: np.ndarray) -> np.ndarray:
    """Far signs [n, dz, dy, dx] of the 27 blocks around each block (0 for band blocks)."""
    b = grid.block_of_key(keys)
    far = np.zeros((len(keys), 3, 3, 3), np.int8)
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                far[:, dz + 1, dy + 1, dx + 1] = sign[labels[grid.block_key(b + np.array([dx, dy, dz]))]]
    return far


def weld(pieces: Sequence[Tuple[np.ndarray, np.ndarray, np.ndarray]]) -> Tuple[np.ndarray, np.ndarray]:
    """One vertex per lattice edge across the tiles' meshes."""
    pieces = [p for p in pieces if len(p[1])]
    if not pieces:
        return np.zeros((0, 3)), np.zeros((0, 3), np.uint32)
    keys = np.concatenate([p[2] for p in pieces])
    verts = np.concatenate([p[0] for p in pieces])
    offsets = np.cumsum([0] + [len(p[0]) for p in pieces])
    tris = np.concatenate([p[1].astype(np.int64) + offsets[i] for i, p in enumerate(pieces)])
    unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    return verts[first], inverse[tris].astype(np.uint32)


def drop_small_components(vertices: np.ndarray, faces: np.ndarray, min_share: float) -> Tuple[np.ndarray, np.ndarray]:
    """Closed pieces with fewer than `min_share` of the triangles (bubbles of the far field)
    are dropped; unused vertices go with them."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    if len(faces) == 0:
        return vertices, faces
    f = faces.astype(np.int64)
    rows = np.concatenate([f[:, 0], f[:, 1]])
    cols = np.concatenate([f[:, 1], f[:, 2]])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(vertices), len(vertices)))
    _, label = connected_components(graph, directed=False)
    tri_label = label[f[:, 0]]
    sizes = np.bincount(tri_label)
    keep = sizes[tri_label] >= min_share * len(faces)
    f = f[keep]
    used = np.unique(f)
    remap = np.full(len(vertices), -1, np.int64)
    remap[used] = np.arange(len(used))
    return vertices[used], remap[f].astype(np.uint32)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals (outward for counter-clockwise faces)."""
    v = vertices[faces.astype(np.int64)]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    acc = np.zeros_like(vertices)
    for c in range(3):
        np.add.at(acc, faces[:, c].astype(np.int64), n)
    length = np.linalg.norm(acc, axis=1, keepdims=True)
    return acc / np.where(length > 0, length, 1)


# ---- the entry point ----------------------------------------------------------------------


def reconstruct(path_or_array: Any, client: Any = None, *, tile_points: int = 2_000_000, resolution: int = 0,
                band_cells: float = 3.0, margin_cells: float = 16.0, min_component_share: float = 0.001,
                reconcile: bool = True, stats: Optional[Dict[str, Any]] = None, _flip_tiles: Sequence[int] = (),
                **params: Any) -> Mesh:
    """The closed, outward-oriented mesh of a cloud (a PLY/XYZ path — binary little-endian
    PLY is memory-mapped — or an n×3 array), reconstructed in tiles of about `tile_points`
    points on the Dask `client` (None: the current client, else a local one made for the
    call). `resolution`: grid cubes along the longest side (0: 1.5 point spacings a cube);
    `band_cells`: how far from the points the field is evaluated, in cubes; `margin_cells`:
    each tile's overlap with its neighbours, in cubes; closed pieces with fewer than
    `min_component_share` of the triangles are dropped. Other keywords are gmpu.Surface
    parameters for every tile. `stats`, if a dict, receives the plan's figures.
    `reconcile=False` keeps every tile's own orientation (for comparison: an open patch's
    orientation is a guess); `_flip_tiles` (tests) turns those tiles' surfaces over."""
    from distributed import Client, get_client
    own_client = None
    if client is None:
        try:
            client = get_client()
        except ValueError:
            client = own_client = Client(processes=False, n_workers=1, threads_per_worker=os.cpu_count() or 1)
    try:
        t0 = time.perf_counter()
        if isinstance(path_or_array, (str, os.PathLike)):
            source = _Source(path=os.fspath(path_or_array))
        else:
            a = np.ascontiguousarray(np.asarray(path_or_array, dtype=np.float64))
            if a.ndim != 2 or a.shape[1] != 3:
                raise ValueError(f"points: expected an n×3 array, got shape {a.shape}")
            source = _Source(array=a)
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        for _, p in source.chunks():
            if len(p):
                lo, hi = np.minimum(lo, p.min(0)), np.maximum(hi, p.max(0))
        hi = np.nextafter(hi, np.inf)  # boxes are half-open
        plan = plan_tiles(source.sample(200_000), source.count, lo, hi, tile_points=tile_points,
                          resolution=resolution, band_cells=band_cells, margin_cells=margin_cells)
        g = plan.grid
        # Tasks get the points as a shared future (an array) or the path (each maps the file).
        data = client.scatter(source.array, broadcast=False) if source.layout is None else source
        phase1 = [client.submit(_tile_surface, data, plan, t, params, t in _flip_tiles, pure=False)
                  for t in range(len(plan.tiles))]
        summaries = client.gather([client.submit(_summary, f) for f in phase1])
        t1 = time.perf_counter()
        if reconcile:
            flip, group = reconcile_signs(summaries)
        else:  # every tile as it oriented itself, one outward pass for all
            flip, group = np.ones(len(summaries), np.int64), np.zeros(len(summaries), np.int64)
        flip, labels, sign = far_signs(g, summaries, flip, group)
        # Who owns each band block, for the neighbours' corner layers.
        all_keys = np.concatenate([s["keys"] for s in summaries])
        owner = np.concatenate([np.full(len(s["keys"]), t) for t, s in enumerate(summaries)])
        order = np.argsort(all_keys)
        all_keys, owner = all_keys[order], owner[order]
        phase2 = []
        for t, s in enumerate(summaries):
            keys = s["keys"]
            if len(keys) == 0:
                continue
            b = g.block_of_key(keys)
            need = []
            for o in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, 0, 1), (0, 1, 1), (1, 1, 1)):
                nb = b + np.array(o)
                need.append(g.block_key(nb[np.all(nb < g.blocks, axis=1)]))
            need = np.unique(np.concatenate(need))
            pos = np.clip(np.searchsorted(all_keys, need), 0, len(all_keys) - 1)
            found = all_keys[pos] == need
            need, who = need[found], owner[pos[found]]
            foreign = [client.submit(_take, phase1[u], need[who == u], int(flip[u]))
                       for u in np.unique(who) if u != t]
            far = _neighbourhood(g, keys, labels, sign)
            phase2.append(client.submit(_march, phase1[t], int(flip[t]), foreign, far, g))
        pieces = client.gather(phase2)
        del phase1, phase2
        vertices, faces = weld(pieces)
        vertices, faces = drop_small_components(vertices, faces, min_component_share)
        if stats is not None:
            stats.update(tiles=len(plan.tiles), cell=g.cell, grid_cells=g.cells.tolist(), flips=flip.tolist(),
                         groups=int(group.max()) + 1 if len(group) else 0,
                         tile_points=[int(s["points"]) for s in summaries],
                         band_blocks=int(len(all_keys)), phase1_seconds=t1 - t0,
                         seconds=time.perf_counter() - t0)
        return Mesh(vertices, faces, vertex_normals(vertices, faces))
    finally:
        if own_client is not None:
            own_client.close()


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m gmpu.dask",
                                     description="Tiled reconstruction of a large point cloud on Dask.")
    parser.add_argument("input", help="point cloud (.ply memory-mapped when binary little-endian; .xyz, .obj, .off)")
    parser.add_argument("-o", "--output", required=True, help="mesh file (.ply, .obj, .off, .stl, .glb)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--local-workers", type=int, default=2, help="workers of a local cluster (default 2)")
    parser.add_argument("--tile-points", type=int, default=2_000_000)
    parser.add_argument("--resolution", type=int, default=0)
    parser.add_argument("--threads-per-worker", type=int, default=1)
    parser.add_argument("--in-process", action="store_true",
                        help="local workers as threads of this process (starts faster; one process's memory)")
    args = parser.parse_args(argv)
    from distributed import Client, LocalCluster
    if args.scheduler:
        client, cluster = Client(args.scheduler), None
    else:
        cluster = LocalCluster(n_workers=args.local_workers, threads_per_worker=args.threads_per_worker,
                               processes=not args.in_process, dashboard_address=None)
        client = Client(cluster)
    try:
        stats: Dict[str, Any] = {}
        mesh = reconstruct(args.input, client, tile_points=args.tile_points, resolution=args.resolution,
                           stats=stats, threads=args.threads_per_worker)
        mesh.write(args.output)
        print(f"{len(mesh.faces)} triangles, {stats['tiles']} tiles, {stats['seconds']:.1f} s -> {args.output}")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return 0


if __name__ == "__main__":
    # Run from the package's module, not this __main__ copy: tasks must name their functions
    # by an importable module, or Dask pickles them with their globals (the C library).
    from gmpu.dask import main as _main
    sys.exit(_main())
