"""Tiled reconstruction on Dask: clouds larger than one process, one mesh.

    >>> from gmpu.dask import reconstruct                     # doctest: +SKIP
    >>> mesh = reconstruct("city.ply", client=client)         # doctest: +SKIP

    python3 -m gmpu.dask INPUT -o OUT [--scheduler ADDRESS | --local-workers N [--in-process]]

How (issue 17):

1. **Tiles.** The cloud's box is covered by one global grid (cubes of side ``cell``, cut in
   blocks of 8³ cubes) and split kd-wise, on block boundaries, into tiles of about
   ``tile_points`` points. A file's points are sorted once, by chunk tasks, into per-tile
   files (each tile's box plus an overlap margin of ``margin_cells`` cubes, at least the
   band plus two cubes); a tile task reads its own, fits and orients a gmpu surface on them,
   finds its *band* (the blocks it owns within ``band_cells`` cubes of a point) and
   evaluates f at the corners its band blocks own (gmpu_surface_evaluate_grid: corners
   8·b .. 8·b + 7, so every corner has one owner). The tile's points fall in *pieces*
   (occupied cubes, 26-connected): the margin may cut a patch off the tile's main piece,
   and orientation may turn it its own way, so every band corner is tagged with the piece
   of the nearest occupied cube.
2. **Global orientation.** Each tile also returns the oriented normals of a fixed subsample
   of its overlap points. Two pieces (of two tiles) agree when their normals on the points
   both hold point the same way; a maximum spanning tree of the piece graph on |agreement|
   fixes one flip per piece (a tile's own orientation of an open patch is a guess). Then
   the outward pass: per connected group of pieces, the band corners next to the far region
   that touches the grid's edge must be outside (f < 0); if most are not, the group is
   flipped.
3. **Far regions.** Blocks outside every tile's band form regions (6-connected); the one
   at the grid's edge is outside, each enclosed one (the inside of a thick solid) takes the
   sign most band corners beside it have. A corner touching a far block takes its region's
   sign (outside wins), as in the one-process polygonizer, so every surface closes.
4. **Seamless union.** A march task gets its own corner values plus the first corner layer
   of its +x/+y/+z neighbour blocks from the tiles that own them, and marches its blocks
   (gmpu_grid_polygonize). Shared corners have one value, so both sides cut a shared face
   identically; vertices are keyed by lattice edge and welded by key into one closed mesh.
5. **Assembly.** Closed pieces of the mesh under ``min_component_share`` of the triangles
   (bubbles of the far field) are found across tiles (joined by their tile-face vertices)
   and dropped on the workers; the driver then takes the tiles' meshes one at a time, in
   tile order, remembering only the vertices on tile faces, and streams them to a PLY
   (``output=``) that is renamed into place when complete.

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


class _TileFiles:
    """A tile's points as the sorting pass left them: files of (global index, x, y, z)."""

    def __init__(self, paths: Sequence[str], count: int):
        self.paths, self.count = list(paths), count

    def select(self, lo: np.ndarray, hi: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Indices and float64 positions of the tile's points in [lo, hi), filled one file at
        a time into arrays of the final size (no concatenated copy of the whole)."""
        sizes = [np.load(p, mmap_mode="r").shape[0] for p in self.paths]
        idx, xyz = np.empty(sum(sizes), np.int64), np.empty((sum(sizes), 3))
        at = 0
        for path, size in zip(self.paths, sizes):
            rows = np.load(path)
            idx[at:at + size] = rows["index"]
            for d, name in enumerate("xyz"):
                xyz[at:at + size, d] = rows[name]
            at += size
            del rows
        keep = np.all((xyz >= lo) & (xyz < hi), axis=1)
        if not keep.all():
            idx, xyz = idx[keep], xyz[keep]
        return idx, xyz


def _sort_chunk(source: "_Source", plan: "TilePlan", start: int, directory: str) -> List[Tuple[int, str]]:
    """One pass of the points [start, start + chunk): each point written to the file of every
    tile whose box plus margin holds it (tile t, chunk c: t<t>_<c>.npy). Returns (tile,
    file) per file written. Each tile then reads only its own points, instead of every tile
    scanning the whole cloud. One box test per tile: memory stays a few copies of the chunk
    whatever the margin (candidate pairs per neighbouring block would grow with its cube)."""
    g, m = plan.grid, plan.margin
    if source.layout:
        rows = source._mapped()[start:start + _CHUNK]
        xyz = np.stack([rows["x"], rows["y"], rows["z"]], axis=1)
        del rows
    else:
        xyz = source.array[start:start + _CHUNK]
    p = xyz.astype(np.float64)
    size = BLOCK * g.cell
    lo = np.array([bl for bl, _ in plan.tiles]) * size + g.origin - m
    hi = np.array([bh for _, bh in plan.tiles]) * size + g.origin + m
    dtype = np.dtype([("index", "<i8"), ("x", xyz.dtype), ("y", xyz.dtype), ("z", xyz.dtype)])
    written = []
    for t in range(len(plan.tiles)):
        point = np.flatnonzero(np.all((p >= lo[t]) & (p < hi[t]), axis=1))
        if len(point) == 0:
            continue
        out = np.empty(len(point), dtype)
        out["index"] = start + point
        for d, name in enumerate("xyz"):
            out[name] = xyz[point, d]
        path = os.path.join(directory, f"t{t}_{start}.npy")
        with open(path + ".part", "wb") as f:  # renamed whole: a rerun after a lost worker rewrites it
            np.save(f, out)
        os.replace(path + ".part", path)
        written.append((t, path))
    return written


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
    """The blocks in [lo, hi) within `radius` of some point (by their boxes). Points a chunk
    at a time, each chunk's blocks made unique at once: the candidates never outnumber a
    chunk's points by more than the blocks a ball touches."""
    size = BLOCK * grid.cell
    found = [np.zeros(0, np.int64)]
    for start in range(0, len(points), _CHUNK):
        p = points[start:start + _CHUNK]
        a = np.floor((p - radius - grid.origin) / size).astype(np.int64)
        b = np.floor((p + radius - grid.origin) / size).astype(np.int64)
        span = int((b - a).max())
        chunk = []
        for dz in range(span + 1):
            for dy in range(span + 1):
                for dx in range(span + 1):
                    c = a + np.array([dx, dy, dz])
                    ok = np.all((c <= b) & (c >= lo) & (c < hi), axis=1)
                    chunk.append(np.unique(grid.block_key(c[ok])))
        found.append(np.unique(np.concatenate(chunk)))
    return np.unique(np.concatenate(found))


def _pieces(xyz: np.ndarray, grid: Grid, which: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tile's points in pieces: occupied grid cubes joined across faces, edges and corners
    (26-connected). Returns the occupied cubes' centres, their piece, and the piece of the
    points `which` (indices). A tile sees patches its margin cuts off from the rest, and
    orientation may turn each one its own way: each piece gets its own flip in the
    reconciliation."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    n = grid.cells + 3  # cube keys with room for the ±1 neighbours
    key = np.zeros(len(xyz), np.int64)
    for start in range(0, len(xyz), _CHUNK):  # a chunk and an axis at a time: no integer copy of the points
        k = key[start:start + _CHUNK]
        for d in (2, 1, 0):
            k *= n[d]
            k += np.floor((xyz[start:start + _CHUNK, d] - grid.origin[d]) / grid.cell).astype(np.int64) + 1
    cubes = np.unique(key)
    which_cube = np.searchsorted(cubes, key[which])
    del key
    rows, cols = [np.arange(len(cubes))], [np.arange(len(cubes))]
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if (dz, dy, dx) <= (0, 0, 0):
                    continue  # each pair once
                other = cubes + dx + n[0] * (dy + n[1] * dz)
                pos = np.clip(np.searchsorted(cubes, other), 0, len(cubes) - 1)
                hit = cubes[pos] == other
                rows.append(np.flatnonzero(hit))
                cols.append(pos[hit])
    r, c = np.concatenate(rows), np.concatenate(cols)
    _, label = connected_components(coo_matrix((np.ones(len(r), np.int8), (r, c)), shape=(len(cubes),) * 2),
                                    directed=False)
    x = cubes % n[0] - 1
    y = cubes // n[0] % n[1] - 1
    z = cubes // (n[0] * n[1]) - 1
    centres = grid.origin + (np.stack([x, y, z], axis=1) + 0.5) * grid.cell
    return centres, label.astype(np.int64), label[which_cube].astype(np.int64)


def _corner_pieces(centres: np.ndarray, cube_piece: np.ndarray, grid: Grid, blocks: np.ndarray) -> np.ndarray:
    """Per owned corner of the blocks [block, 512], the piece of the nearest occupied cube."""
    from scipy.spatial import cKDTree
    ijk = np.stack(np.meshgrid(np.arange(BLOCK), np.arange(BLOCK), np.arange(BLOCK), indexing="ij"),
                   axis=-1).reshape(-1, 3)[:, ::-1]  # x fastest: [k, j, i] → (i, j, k)
    corners = grid.origin + (blocks[:, None, :] * BLOCK + ijk[None]) * grid.cell
    # Approximate nearest (within 1.5× the nearest distance): pieces are at least a cube apart.
    _, nearest = cKDTree(centres).query(corners.reshape(-1, 3), eps=0.5)
    return cube_piece[nearest].reshape(len(blocks), _OWNED)


def _memory() -> Tuple[int, int]:
    """(resident bytes now, peak resident bytes so far) of this process; 0 where the system
    does not say."""
    try:
        import resource
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * (1 if sys.platform == "darwin" else 1024)
    except ImportError:
        peak = 0
    try:
        with open("/proc/self/statm") as f:
            now = int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        now = 0
    return now, peak


def _tile_surface(source: Any, plan: TilePlan, tile: int, params: Dict[str, Any], reverse: bool = False,
                  piece_signs: Optional[np.ndarray] = None) -> Dict[str, Any]:
    """Phase 1 of a tile: its points, surface, band and corner values, the piece of each
    corner, and the normals of its overlap sample. `reverse` (tests) turns the tile's surface
    over, as if its own orientation had guessed wrong.

    `piece_signs` (±1 per piece): the tile's own oriented normals times its piece's sign are
    given to a second surface as known normals, and that surface's field is the tile's. The
    driver refits so every tile whose pieces the reconciliation turned over: the library
    takes the sign of its field away from the points from the winding number of the oriented
    points (0 outside, 1 inside), so an inward-oriented patch has a field whose sign near
    the points is reversed but whose sign farther out is not, and no flip puts both right."""
    if not isinstance(source, (_Source, _TileFiles)):
        source = _Source(array=source)
    clock = time.perf_counter()
    times: Dict[str, float] = {}
    memory: Dict[str, Tuple[int, int]] = {}

    def lap(name):
        nonlocal clock
        now = time.perf_counter()
        times[name] = now - clock
        memory[name] = _memory()
        clock = now

    g = plan.grid
    bl, bh = plan.tiles[tile]
    own_lo = g.origin + bl * BLOCK * g.cell
    own_hi = g.origin + bh * BLOCK * g.cell
    idx, xyz = source.select(own_lo - plan.margin, own_hi + plan.margin)
    lap("read")
    keys = _band_blocks(xyz, g, plan.band_radius, bl, bh)
    out: Dict[str, Any] = {"tile": tile, "points": len(idx), "keys": keys, "times": times, "memory": memory}
    if len(keys) == 0:
        out.update(values=np.zeros((0, _OWNED), np.float32), labels=np.zeros((0, _OWNED), np.int32), pieces=0,
                   faces=np.zeros((0, 4), np.int64), shared=np.zeros(0, np.int64),
                   shared_pieces=np.zeros(0, np.int64), normals=np.zeros((0, 3), np.float32))
        return out
    # Overlap points: those some other tile holds too. A subsample fixed by global index, so
    # both tiles pick the same points.
    inner = np.all((xyz >= own_lo + plan.margin) & (xyz < own_hi - plan.margin), axis=1)
    stride = max(1, source.count // (len(plan.tiles) * _SHARED_SAMPLE))
    shared = np.flatnonzero((~inner) & (idx % stride == 0))
    out["shared"] = idx[shared]
    del idx, inner
    if piece_signs is None:
        centres, cube_piece, out["shared_pieces"] = _pieces(xyz, g, shared)
    else:
        centres, cube_piece, point_piece = _pieces(xyz, g, np.arange(len(xyz)))
        out["shared_pieces"] = point_piece[shared]
    pieces = int(cube_piece.max()) + 1
    lap("pieces")
    s = Surface(xyz, **params)
    if piece_signs is None:
        del xyz  # the surface holds its own copy: only it while fitting
    try:
        s.fit()
        lap("fit")
        s.orient()
        lap("orient")
        if piece_signs is not None:
            known = s.normals
            signs = np.asarray(piece_signs, np.float64)
            known *= signs[point_piece][:, None] if signs.ndim else signs
            del point_piece
            s.close()
            s = Surface(xyz, normals=known, **params)
            del known, xyz
            s.fit()
            s.orient()  # known normals: no belief propagation
            lap("refit")
        blocks = g.block_of_key(keys)
        values = _evaluate_grid(s, g, blocks)
        lap("evaluate")
        normals = s.normals_at(shared)
    finally:
        s.close()
    if reverse:
        values, normals = -values, -normals
    labels = _corner_pieces(centres, cube_piece, g, blocks) if pieces > 1 else np.zeros(values.shape, np.int32)
    v = values.reshape(-1, BLOCK, BLOCK, BLOCK)  # [block, k, j, i]
    lab = labels.reshape(-1, BLOCK, BLOCK, BLOCK)
    sg = np.sign(v).astype(np.int64)
    # Sign sums of the corner layer nearest each face (−x, +x, −y, +y, −z, +z), per piece:
    # the votes of the far regions beside the block. Rows (block, face, piece, sum).
    layers = [(sg[:, :, :, 0], lab[:, :, :, 0]), (sg[:, :, :, -1], lab[:, :, :, -1]),
              (sg[:, :, 0, :], lab[:, :, 0, :]), (sg[:, :, -1, :], lab[:, :, -1, :]),
              (sg[:, 0, :, :], lab[:, 0, :, :]), (sg[:, -1, :, :], lab[:, -1, :, :])]
    rows = []
    for f, (sign, piece) in enumerate(layers):
        block = np.broadcast_to(np.arange(len(keys))[:, None, None], piece.shape)
        code = block.reshape(-1) * pieces + piece.reshape(-1)
        sums = np.bincount(code, weights=sign.reshape(-1), minlength=len(keys) * pieces)
        hit = np.unique(code)
        rows.append(np.stack([hit // pieces, np.full(len(hit), f), hit % pieces, sums[hit].astype(np.int64)], axis=1))
    out["faces"] = np.concatenate(rows)
    out["values"] = values.astype(np.float32)
    # None: every corner in piece 0.
    out["labels"] = labels.astype(np.int16 if pieces < 1 << 15 else np.int32) if pieces > 1 else None
    out["pieces"] = pieces
    out["normals"] = normals.astype(np.float32)
    lap("votes")
    return out


def _summary(result: Dict[str, Any]) -> Dict[str, Any]:
    return {k: v for k, v in result.items() if k not in ("values", "labels")}


def _signed(result: Dict[str, Any], pos: Any, flips: np.ndarray) -> np.ndarray:
    """The corner values of some of a tile's blocks, each corner signed by its piece's flip."""
    if result["labels"] is None:
        return result["values"][pos] * np.float32(flips[0])
    return result["values"][pos] * flips.astype(np.float32)[result["labels"][pos]]


def _take(result: Dict[str, Any], keys: np.ndarray, flips: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    return keys, _signed(result, np.searchsorted(result["keys"], keys), flips)


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


def _march(own: Dict[str, Any], flips: np.ndarray, foreign: Sequence[Tuple[np.ndarray, np.ndarray]], far: np.ndarray,
           grid: Grid, box: Tuple[np.ndarray, np.ndarray]) -> Dict[str, Any]:
    """Phase 2 of a tile: its blocks marched with every corner known. Returns vertices,
    triangles and the vertices' lattice-edge keys."""
    keys = own["keys"]
    if len(keys) == 0:
        return _piece(np.zeros((0, 3)), np.zeros((0, 3), np.uint32), np.zeros(0, np.uint64), grid, box)
    avail_keys = np.concatenate([keys] + [k for k, _ in foreign])
    avail_values = np.concatenate([_signed(own, slice(None), flips)] + [v for _, v in foreign])
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
        return _piece(np.zeros((0, 3)), np.zeros((0, 3), np.uint32), np.zeros(0, np.uint64), grid, box)
    vertices = np.frombuffer(ffi.buffer(lib.gmpu_mesh_vertices(m), 24 * nv), np.float64).reshape(nv, 3).copy()
    triangles = np.frombuffer(ffi.buffer(lib.gmpu_mesh_triangles(m), 12 * nt), np.uint32).reshape(nt, 3).copy()
    edge_keys = np.frombuffer(ffi.buffer(lib.gmpu_mesh_grid_keys(m), 8 * nv), np.uint64).copy()
    return _piece(vertices, triangles, edge_keys, grid, box)


def _piece(vertices: np.ndarray, triangles: np.ndarray, keys: np.ndarray, grid: Grid,
           box: Tuple[np.ndarray, np.ndarray]) -> Dict[str, Any]:
    """A tile's mesh as the assembly takes it: which vertices lie on the faces of the tile's
    box (the only ones another tile can also make: welded by key), their area-weighted
    normal sums (summed across tiles for the face vertices) and its connected pieces."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    corner = (keys // np.uint64(8)).astype(np.int64)
    steps = (keys % np.uint64(8)).astype(np.int64) + 1  # the edge's axes, one bit each
    n0, n1 = grid.cells[0] + 1, grid.cells[1] + 1
    at = [corner % n0, corner // n0 % n1, corner // (n0 * n1)]
    lo, hi = box[0] * BLOCK, box[1] * BLOCK
    on_box = np.zeros(len(keys), bool)
    for d in range(3):
        flat = (steps >> d & 1) == 0  # the edge does not leave the plane across axis d
        on_box |= flat & ((at[d] == lo[d]) | (at[d] == hi[d]))
    t = triangles.astype(np.int64)
    v = vertices[t] if len(t) else np.zeros((0, 3, 3))
    area = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    sums = np.zeros_like(vertices)
    for d in range(3):
        for c in range(3):
            sums[:, d] += np.bincount(t[:, c], weights=area[:, d], minlength=len(vertices))
    component = np.zeros(len(t), np.int64)
    vertex_component = np.zeros(len(vertices), np.int64)
    sizes = np.zeros(0, np.int64)
    if len(t):
        edges = (np.concatenate([t[:, 0], t[:, 1]]), np.concatenate([t[:, 1], t[:, 2]]))
        graph = coo_matrix((np.ones(2 * len(t)), edges), shape=(len(vertices),) * 2)
        count, vertex_component = connected_components(graph, directed=False)
        component = vertex_component[t[:, 0]]
        sizes = np.bincount(component, minlength=count)
    return {"vertices": vertices, "triangles": triangles, "keys": keys, "on_box": on_box, "normal_sums": sums,
            "component": component, "sizes": sizes, "vertex_component": vertex_component}


def _outline(piece: Dict[str, Any]) -> Dict[str, np.ndarray]:
    """What the driver needs to find the mesh's connected pieces across tiles: triangles per
    connected piece of this tile's mesh, and the keys (and pieces) of its tile-face vertices."""
    return {"sizes": piece["sizes"], "keys": piece["keys"][piece["on_box"]],
            "component": piece["vertex_component"][piece["on_box"]]}


def small_components(outlines: Sequence[Dict[str, np.ndarray]], min_share: float) -> List[np.ndarray]:
    """Per tile piece, which of its connected pieces belong to a connected piece of the whole
    mesh with fewer than `min_share` of the triangles (bubbles of the far field): joined
    across tiles where they share a tile-face vertex."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    offsets = np.cumsum([0] + [len(o["sizes"]) for o in outlines])
    n = int(offsets[-1])
    keys = np.concatenate([o["keys"] for o in outlines]) if outlines else np.zeros(0, np.uint64)
    node = np.concatenate([offsets[i] + o["component"] for i, o in enumerate(outlines)]) if outlines else \
        np.zeros(0, np.int64)
    order = np.argsort(keys, kind="stable")
    keys, node = keys[order], node[order]
    same = np.flatnonzero(keys[1:] == keys[:-1])
    graph = coo_matrix((np.ones(len(same)), (node[same], node[same + 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    sizes = np.concatenate([o["sizes"] for o in outlines]) if outlines else np.zeros(0, np.int64)
    total = np.bincount(label, weights=sizes, minlength=label.max() + 1 if n else 0)
    small = total[label] < min_share * sizes.sum()
    return [small[offsets[i]:offsets[i + 1]] for i in range(len(outlines))]


def _pruned(piece: Dict[str, Any], small: np.ndarray) -> Dict[str, Any]:
    """The piece without its `small` connected pieces and the vertices only they used."""
    if not small.any():
        return piece
    keep = ~small[piece["component"]]
    t = piece["triangles"][keep].astype(np.int64)
    used = np.unique(t)
    remap = np.full(len(piece["vertices"]), -1, np.int64)
    remap[used] = np.arange(len(used))
    out = {k: piece[k][used] for k in ("vertices", "keys", "on_box", "normal_sums")}
    out["triangles"] = remap[t].astype(np.uint32)
    return out


# ---- the driver's steps -------------------------------------------------------------------


def piece_offsets(summaries: Sequence[Dict[str, Any]]) -> np.ndarray:
    """Node numbers: tile t's piece p is node offsets[t] + p (the last entry: the node count)."""
    return np.cumsum([0] + [int(s["pieces"]) for s in summaries])


def reconcile_signs(summaries: Sequence[Dict[str, Any]]) -> Tuple[np.ndarray, np.ndarray]:
    """One flip (±1) per tile piece so that the pieces agree on the overlap points they
    share, and the group (connected part of the piece graph) of each piece. Maximum
    spanning tree on |agreement|."""
    offsets = piece_offsets(summaries)
    n = int(offsets[-1])
    ids = np.concatenate([s["shared"] for s in summaries])
    node = np.concatenate([offsets[t] + s["shared_pieces"] for t, s in enumerate(summaries)])
    tile = np.concatenate([np.full(len(s["shared"]), t) for t, s in enumerate(summaries)])
    normals = np.concatenate([s["normals"] for s in summaries]).astype(np.float64)
    order = np.lexsort((tile, ids))
    ids, node, tile, normals = ids[order], node[order], tile[order], normals[order]
    # A point held by several tiles: each holder paired with the next one.
    same = np.flatnonzero((ids[1:] == ids[:-1]) & (tile[1:] != tile[:-1]))
    a, b = node[same], node[same + 1]
    dot = np.einsum("ij,ij->i", normals[same], normals[same + 1])
    pair, inverse = np.unique(np.minimum(a, b) * n + np.maximum(a, b), return_inverse=True)
    agree = np.bincount(inverse, weights=dot, minlength=len(pair)) if len(pair) else np.zeros(0)
    edges = sorted(((abs(w), int(k // n), int(k % n), 1 if w > 0 else -1) for k, w in zip(pair, agree) if w != 0),
                   key=lambda e: -e[0])
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
    """The outward pass and the far regions' signs. Returns the flips per piece (groups
    whose band is mostly inside next to the outer region turned over), the block grid's
    region labels and each region's sign (index 0: band)."""
    from scipy import ndimage
    nb = grid.blocks
    band = np.zeros(int(np.prod(nb)), bool)
    for s in summaries:
        band[s["keys"]] = True
    labels, count = ndimage.label(~band.reshape(nb[2], nb[1], nb[0]))
    labels = labels.reshape(-1)
    outer = labels[0]
    offsets = piece_offsets(summaries)
    flip = flip.copy()
    # Per face-vote row (block, face, piece, sum): the far region beside it and its node.
    rows = []
    for t, s in enumerate(summaries):
        f = s["faces"]
        if len(f) == 0:
            continue
        beside = grid.block_of_key(s["keys"][f[:, 0]]) + _FACE_STEPS[f[:, 1]]
        rows.append((labels[grid.block_key(beside)], offsets[t] + f[:, 2], f[:, 3].astype(np.float64)))
    region = np.concatenate([r for r, _, _ in rows]) if rows else np.zeros(0, np.int64)
    node = np.concatenate([n for _, n, _ in rows]) if rows else np.zeros(0, np.int64)
    votes = np.concatenate([v for _, _, v in rows]) if rows else np.zeros(0)
    groups = int(group.max()) + 1 if len(group) else 0
    outer_votes = np.bincount(group[node], weights=votes * flip[node] * (region == outer), minlength=groups)
    for g in np.flatnonzero(outer_votes > 0):  # the group's band is mostly inside next to the outside
        flip[group == g] *= -1
    region_votes = np.bincount(region, weights=votes * flip[node], minlength=count + 1)
    sign = np.where(region_votes > 0, 1, -1).astype(np.int8)
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


class _MemorySink:
    """The welded mesh kept in memory (gmpu.Mesh)."""

    def __init__(self):
        self.vertices, self.normals, self.faces = [], [], []

    def add(self, vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> None:
        self.vertices.append(vertices)
        self.normals.append(normals)
        self.faces.append(faces)

    def finish(self, index: np.ndarray, normals: np.ndarray) -> Mesh:
        v = np.concatenate(self.vertices) if self.vertices else np.zeros((0, 3))
        n = np.concatenate(self.normals) if self.normals else np.zeros((0, 3))
        f = np.concatenate(self.faces) if self.faces else np.zeros((0, 3), np.uint32)
        n[index] = normals
        return Mesh(v, f, n)

    def abort(self) -> None:
        pass


_VERTEX = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")])
_FACE = np.dtype([("n", "u1"), ("i", "<i4", (3,))])


class PlyStreamSink:
    """The welded mesh written to a binary PLY as the tiles' pieces arrive: vertices and
    faces go to two scratch files beside the output; `finish` fixes the normals of the
    vertices on tile faces (summed across tiles), writes the header and renames the whole
    into place, so the output is either absent or complete."""

    def __init__(self, path: str):
        self.path = os.fspath(path)
        self.parts = [self.path + ".vertices.part", self.path + ".faces.part", self.path + ".part"]
        self.vfile, self.ffile = open(self.parts[0], "wb"), open(self.parts[1], "wb")
        self.vertex_count = self.face_count = 0

    def add(self, vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> None:
        rec = np.empty(len(vertices), _VERTEX)
        for name, col in zip(("x", "y", "z"), vertices.T):
            rec[name] = col
        for name, col in zip(("nx", "ny", "nz"), normals.T):
            rec[name] = col
        self.vfile.write(rec.tobytes())
        fr = np.empty(len(faces), _FACE)
        fr["n"] = 3
        fr["i"] = faces
        self.ffile.write(fr.tobytes())
        self.vertex_count += len(vertices)
        self.face_count += len(faces)

    def finish(self, index: np.ndarray, normals: np.ndarray) -> Dict[str, int]:
        self.vfile.close()
        self.ffile.close()
        if len(index):
            rec = np.memmap(self.parts[0], dtype=_VERTEX, mode="r+")
            for name, col in zip(("nx", "ny", "nz"), normals.T):
                rec[name][index] = col
            rec.flush()
            del rec
        header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {self.vertex_count}\n"
                  "property float x\nproperty float y\nproperty float z\n"
                  "property float nx\nproperty float ny\nproperty float nz\n"
                  f"element face {self.face_count}\nproperty list uchar int vertex_indices\nend_header\n")
        import shutil
        with open(self.parts[2], "wb") as out:
            out.write(header.encode("ascii"))
            for part in self.parts[:2]:
                with open(part, "rb") as f:
                    shutil.copyfileobj(f, out, 1 << 24)
                os.remove(part)
        os.replace(self.parts[2], self.path)
        return {"vertices": self.vertex_count, "faces": self.face_count}

    def abort(self) -> None:
        for f in (self.vfile, self.ffile):
            f.close()
        for part in self.parts:
            if os.path.exists(part):
                os.remove(part)


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(length > 0, length, 1)


def assemble(pieces: Any, sink: Any) -> Any:
    """Welds the tiles' pieces, in the given order, into `sink` one piece at a time. Only
    the vertices on tile faces are remembered (lattice-edge key → index and normal sum): the
    others are final when their piece arrives."""
    seen: Dict[int, int] = {}
    face_index: List[int] = []
    face_sums: List[np.ndarray] = []
    count = 0
    for piece in pieces:
        nv = len(piece["vertices"])
        if nv == 0:
            continue
        index = np.empty(nv, np.int64)
        new = ~piece["on_box"]
        for i in np.flatnonzero(piece["on_box"]):
            key = int(piece["keys"][i])
            slot = seen.get(key)
            if slot is None:
                seen[key] = len(face_index)
                face_index.append(-1)
                face_sums.append(piece["normal_sums"][i].copy())
                new[i] = True
            else:
                face_sums[slot] += piece["normal_sums"][i]
                index[i] = face_index[slot]
        fresh = np.flatnonzero(new)
        index[fresh] = count + np.arange(len(fresh))
        for i in np.flatnonzero(piece["on_box"] & new):
            face_index[seen[int(piece["keys"][i])]] = int(index[i])
        count += len(fresh)
        sink.add(piece["vertices"][fresh], _unit(piece["normal_sums"][fresh]),
                 index[piece["triangles"].astype(np.int64)].astype(np.uint32))
    sums = np.array(face_sums).reshape(-1, 3)
    return sink.finish(np.array(face_index, np.int64), _unit(sums))


# ---- the entry point ----------------------------------------------------------------------


def reconstruct(path_or_array: Any, client: Any = None, *, tile_points: int = 2_000_000, resolution: int = 0,
                band_cells: float = 3.0, margin_cells: float = 16.0, min_component_share: float = 0.001,
                reconcile: bool = True, stats: Optional[Dict[str, Any]] = None, output: Optional[str] = None,
                scratch: Optional[str] = None,
                _flip_tiles: Sequence[int] = (), _invert_tiles: Sequence[int] = (), **params: Any) -> Any:
    """The closed, outward-oriented mesh of a cloud (a PLY/XYZ path — binary little-endian
    PLY is memory-mapped — or an n×3 array), reconstructed in tiles of about `tile_points`
    points on the Dask `client` (None: the current client, else a local one made for the
    call). `resolution`: grid cubes along the longest side (0: 1.5 point spacings a cube);
    `band_cells`: how far from the points the field is evaluated, in cubes; `margin_cells`:
    each tile's overlap with its neighbours, in cubes; closed pieces with fewer than
    `min_component_share` of the triangles are dropped. `output`: a .ply
    path the mesh is streamed to (the driver holds one tile's piece at a time; the file
    appears complete or not at all), and the call returns its vertex and face counts
    instead of the mesh. `scratch`: where the sorting pass of a file's points leaves each
    tile's points (default: the temporary directory; on a cluster, a directory every
    worker sees), removed at the end. Other keywords are gmpu.Surface
    parameters for every tile. `stats`, if a dict, receives the plan's figures.
    `reconcile=False` keeps every tile's own orientation (for comparison: an open patch's
    orientation is a guess); `_flip_tiles` (tests) turns those tiles' surfaces over (values
    and normals alike), `_invert_tiles` (tests) fits those tiles with their normals reversed."""
    from distributed import Client, get_client
    own_client = scratch_dir = None
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
        if source.layout is None:  # an array: a shared future
            data = client.scatter(source.array, broadcast=False)
            tile_data = [data] * len(plan.tiles)
        else:  # a file: one sorting pass, then each tile reads its own points
            import tempfile
            scratch_dir = tempfile.mkdtemp(prefix="gmpu-dask-", dir=scratch)
            files: Dict[int, List[str]] = {t: [] for t in range(len(plan.tiles))}
            for written in client.gather([client.submit(_sort_chunk, source, plan, start, scratch_dir, pure=False)
                                          for start in range(0, source.count, _CHUNK)]):
                for t, path in written:
                    files[t].append(path)
            tile_data = [_TileFiles(files[t], source.count) for t in range(len(plan.tiles))]
        inverted = {t: -1.0 for t in _invert_tiles}
        phase1 = [client.submit(_tile_surface, tile_data[t], plan, t, params, t in _flip_tiles, inverted.get(t),
                                pure=False) for t in range(len(plan.tiles))]
        summaries = client.gather([client.submit(_summary, f) for f in phase1])
        t1 = time.perf_counter()
        if reconcile:
            flip, group = reconcile_signs(summaries)
        else:  # every tile as it oriented itself, one outward pass for all
            nodes = int(piece_offsets(summaries)[-1])
            flip, group = np.ones(nodes, np.int64), np.zeros(nodes, np.int64)
        flip, labels, sign = far_signs(g, summaries, flip, group)
        offsets = piece_offsets(summaries)
        # A tile with a piece turned over is refitted with outward normals (_tile_surface says
        # why a flip of its values is not enough); its pieces then need no flip.
        refit = [t for t in range(len(plan.tiles)) if reconcile and (flip[offsets[t]:offsets[t + 1]] < 0).any()]
        for t in refit:
            own = flip[offsets[t]:offsets[t + 1]] * (-1.0 if t in _flip_tiles else 1.0) * inverted.get(t, 1.0)
            phase1[t] = client.submit(_tile_surface, tile_data[t], plan, t, params, False, own, pure=False)
        for t, summary in zip(refit, client.gather([client.submit(_summary, phase1[t]) for t in refit])):
            summaries[t] = summary
            flip[offsets[t]:offsets[t + 1]] = 1
        if refit:
            flip, labels, sign = far_signs(g, summaries, flip, group)
        if stats is not None:
            stats["refitted_tiles"] = refit
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
            foreign = [client.submit(_take, phase1[u], need[who == u], flip[offsets[u]:offsets[u + 1]])
                       for u in np.unique(who) if u != t]
            far = _neighbourhood(g, keys, labels, sign)
            phase2.append(client.submit(_march, phase1[t], flip[offsets[t]:offsets[t + 1]], foreign, far, g,
                                        plan.tiles[t]))
        del phase1
        small = small_components(client.gather([client.submit(_outline, f) for f in phase2]), min_component_share)
        pruned = [client.submit(_pruned, f, sm) for f, sm in zip(phase2, small)]
        del phase2

        def arriving():  # in tile order (the same mesh every run), one piece held at a time
            for i in range(len(pruned)):
                piece = pruned[i].result()
                pruned[i] = None
                yield piece
        sink = PlyStreamSink(output) if output is not None else _MemorySink()
        try:
            result = assemble(arriving(), sink)
        except BaseException:
            sink.abort()
            raise
        if stats is not None:
            stats.update(tiles=len(plan.tiles), cell=g.cell, grid_cells=g.cells.tolist(), flips=flip.tolist(),
                         groups=int(group.max()) + 1 if len(group) else 0,
                         tile_points=[int(s["points"]) for s in summaries],
                         band_blocks=int(len(all_keys)), phase1_seconds=t1 - t0, pieces=int(offsets[-1]),
                         tile_seconds={k: round(sum(s["times"].get(k, 0.0) for s in summaries), 3)
                                       for k in ("read", "fit", "orient", "evaluate", "pieces", "votes")},
                         # Per stage, the largest resident size a tile's process had at its end.
                         tile_resident_bytes={k: max((s["memory"][k][0] for s in summaries if k in s["memory"]),
                                                     default=0)
                                              for k in ("read", "pieces", "fit", "orient", "evaluate", "votes")},
                         tile_peak_bytes=max((max(p for _, p in s["memory"].values()) for s in summaries
                                              if s["memory"]), default=0),
                         seconds=time.perf_counter() - t0)
        return result
    finally:
        if scratch_dir is not None:
            import shutil
            shutil.rmtree(scratch_dir, ignore_errors=True)
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
        streamed = args.output.lower().endswith(".ply")
        result = reconstruct(args.input, client, tile_points=args.tile_points, resolution=args.resolution,
                             stats=stats, threads=args.threads_per_worker, output=args.output if streamed else None)
        if not streamed:
            result.write(args.output)
        triangles = result["faces"] if streamed else len(result.faces)
        print(f"{triangles} triangles, {stats['tiles']} tiles, {stats['seconds']:.1f} s -> {args.output}")
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
