"""The high-level API: Surface, Mesh, Points, reconstruct, read_points."""
from __future__ import annotations

import numbers
import os
import threading
import weakref
from typing import Any, Dict, Optional, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _mesh_facts
from ._arrays import _as_real_array, double_ptr, queries_for_c, uint8_ptr, uint32_ptr, view_of_c_memory, xyz_for_c
from ._errors import check
from ._library import ffi, lib
from ._params import PARAM_INFO, PARAMS, param_value
from ._progress import ProgressFn, run_read_with_progress, run_with_progress

__all__ = ["Surface", "Mesh", "Points", "reconstruct", "read_points", "PARAMS", "PARAM_INFO", "STATS"]

PathLike = Union[str, "os.PathLike[str]"]


def _colours(colors: Optional[ArrayLike], count: int) -> Optional[NDArray[np.uint8]]:
    """Red green blue per vertex or point as a C-ordered count×3 uint8 array (None stays None)."""
    if colors is None:
        return None
    c = np.asarray(colors)
    if c.dtype != np.uint8:
        raise ValueError(f"colors: expected dtype uint8 (0..255 red green blue), got {c.dtype}")
    if c.shape != (count, 3):
        raise ValueError(f"colors: expected shape {(count, 3)}, got {c.shape}")
    return np.ascontiguousarray(c)


def _enum_names(ctype: str, prefix: str) -> Dict[str, int]:
    items = ffi.typeof(ctype).relements
    return {name[len(prefix):].lower(): value for name, value in sorted(items.items(), key=lambda kv: kv[1])}


#: Statistic names (keys of Surface.stats) → gmpu_stat values.
STATS: Dict[str, int] = _enum_names("gmpu_stat", "GMPU_STAT_")

_EVAL_CHUNK = 1 << 16  # query points per gmpu_surface_evaluate call

_FLOAT_STATS = {"fit_seconds", "orient_seconds", "polygonize_seconds", "bbox_diagonal", "noise",
                "effective_error"}


def _param_key(name: str) -> int:
    try:
        return PARAMS[name]
    except KeyError:
        raise TypeError(f"unknown gmpu parameter {name!r}; known: {', '.join(PARAMS)}") from None


def _param_number(name: str, value: Any) -> float:
    if isinstance(value, (str, bytes)) or not isinstance(value, (numbers.Real, np.number)):
        raise TypeError(f"gmpu parameter {name!r} must be a number, got {type(value).__name__}")
    return float(value)


def _fspath(path: PathLike) -> bytes:
    return os.fsencode(os.fspath(path))


class _RWLock:
    """Many readers (the C ABI's const calls may run concurrently) or one writer (every other
    call on a surface needs exclusive access). A thread that holds the write lock and asks
    again, i.e. a progress callback calling back into its own surface, which the C ABI
    forbids, gets a RuntimeError instead of a deadlock or undefined behaviour."""

    __slots__ = ("_cond", "_readers", "_writer")

    def __init__(self) -> None:
        self._cond = threading.Condition(threading.Lock())
        self._readers = 0
        self._writer: Optional[int] = None

    def _reentry(self) -> None:
        raise RuntimeError("a gmpu.Surface cannot be used from its own progress callback "
                           "(the C library is in the middle of a stage on it)")

    def acquire_read(self) -> None:
        me = threading.get_ident()
        with self._cond:
            if self._writer == me:
                self._reentry()
            while self._writer is not None:
                self._cond.wait()
            self._readers += 1

    def release_read(self) -> None:
        with self._cond:
            self._readers -= 1
            if not self._readers:
                self._cond.notify_all()

    def acquire_write(self) -> None:
        me = threading.get_ident()
        with self._cond:
            if self._writer == me:
                self._reentry()
            while self._writer is not None or self._readers:
                self._cond.wait()
            self._writer = me

    def release_write(self) -> None:
        with self._cond:
            self._writer = None
            self._cond.notify_all()


class Mesh:
    """A triangle mesh: ``vertices`` (n×3 float64), ``faces`` (m×3 uint32 indices into
    vertices, counter-clockwise seen from outside) and, for meshes made by
    :meth:`Surface.polygonize`, ``normals`` (n×3 float64 unit outward vertex normals).

    A mesh from polygonize holds read-only views of the library's memory (nothing is copied;
    the memory lives as long as the mesh or any of its arrays). ``np.array(mesh.vertices)``
    gives a writable copy; build ``Mesh(vertices, faces)`` from edited arrays.
    """

    def __init__(self, vertices: ArrayLike, faces: ArrayLike, normals: Optional[ArrayLike] = None,
                 confidence: Optional[ArrayLike] = None, colors: Optional[ArrayLike] = None):
        """Builds a mesh from arrays: vertices n×3 (real numbers; kept without copying when
        already C-ordered float64), faces m×3 (integers in [0, n); int32 or uint32 are kept
        without copying), optional per-vertex normals n×3, confidence (n) and colors (n×3
        uint8), all kept by write, simplify and pickling."""
        v = _as_real_array(vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices: expected an n×3 array, got shape {v.shape}")
        v = np.ascontiguousarray(v, dtype=np.float64)
        f = np.asarray(faces)
        if f.size == 0 and f.ndim <= 2:
            f = f.reshape(0, 3)
        if f.dtype.kind not in "iu":
            raise ValueError(f"faces: expected integer indices, got dtype {f.dtype}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"faces: expected an m×3 array, got shape {f.shape}")
        if f.size:
            lo, hi = int(f.min()), int(f.max())
            if lo < 0 or hi >= len(v):
                bad = lo if lo < 0 else hi
                raise ValueError(f"faces: index {bad} is out of range for {len(v)} vertices")
        if f.dtype == np.int32:
            f = np.ascontiguousarray(f).view(np.uint32)
        else:
            f = np.ascontiguousarray(f, dtype=np.uint32)
        n = None
        if normals is not None:
            n = np.ascontiguousarray(_as_real_array(normals, "normals"), dtype=np.float64)
            if n.shape != v.shape:
                raise ValueError(f"normals: expected shape {v.shape} (one per vertex), got {n.shape}")
        c = None
        if confidence is not None:
            c = np.ascontiguousarray(_as_real_array(confidence, "confidence"), dtype=np.float64)
            if c.shape != (len(v),):
                raise ValueError(f"confidence: expected shape {(len(v),)} (one per vertex), got {c.shape}")
        self._vertices, self._faces, self._normals = v, f, n
        self._confidence = c
        self._colors = _colours(colors, len(v))
        self._handle = None  # the gmpu_mesh these arrays view, when made by the library

    @classmethod
    def _from_c(cls, ptr) -> "Mesh":
        """Takes ownership of a gmpu_mesh* (freed when the mesh and its arrays are gone)."""
        handle = ffi.gc(ptr, lib.gmpu_mesh_destroy)
        nv = lib.gmpu_mesh_vertex_count(handle)
        nt = lib.gmpu_mesh_triangle_count(handle)
        self = cls.__new__(cls)
        self._handle = handle
        self._vertices = view_of_c_memory(handle, lib.gmpu_mesh_vertices(handle), (nv, 3), np.float64)
        self._faces = view_of_c_memory(handle, lib.gmpu_mesh_triangles(handle), (nt, 3), np.uint32)
        normals = lib.gmpu_mesh_normals(handle)
        self._normals = None if normals == ffi.NULL else view_of_c_memory(handle, normals, (nv, 3), np.float64)
        confidence = lib.gmpu_mesh_confidence(handle)
        self._confidence = None if confidence == ffi.NULL else view_of_c_memory(handle, confidence, (nv,), np.float64)
        colors = lib.gmpu_mesh_colors(handle)
        self._colors = None if colors == ffi.NULL else view_of_c_memory(handle, colors, (nv, 3), np.uint8)
        return self

    @property
    def vertices(self) -> NDArray[np.float64]:
        """n×3 float64 vertex positions."""
        return self._vertices

    @property
    def faces(self) -> NDArray[np.uint32]:
        """m×3 uint32 vertex indices per triangle (``faces.astype(np.int32)`` if you need signed)."""
        return self._faces

    @property
    def normals(self) -> Optional[NDArray[np.float64]]:
        """n×3 float64 unit outward vertex normals, or None."""
        return self._normals

    @property
    def confidence(self) -> Optional[NDArray[np.float64]]:
        """n float64: each vertex's distance to the nearest input point in sample spacings
        (about 0.5 or less on sampled surface, several over a scan's holes), or None for a
        mesh built from arrays without one."""
        return self._confidence

    @property
    def colors(self) -> Optional[NDArray[np.uint8]]:
        """n×3 uint8 red green blue per vertex, or None (see :meth:`color_from`)."""
        return self._colors

    def color_from(self, points: "Points") -> "Mesh":
        """A copy whose every vertex takes the colour of the nearest of ``points`` (a
        :class:`Points` with colors, as read_points gives a .ply with red green blue)."""
        if not isinstance(points, Points) or points.colors is None:
            raise ValueError("color_from: expected a gmpu.Points with colors")
        out = ffi.new("gmpu_mesh **")

        def call(handle):
            points._with_c_points(lambda pts: check(lib.gmpu_mesh_color_from_points(handle, pts, out),
                                                    "gmpu_mesh_color_from_points"))
        self._with_c_mesh(call)
        return Mesh._from_c(out[0])

    def _with_c_mesh(self, call):
        """call(gmpu_mesh*) on this mesh's library copy (made for the call when built from arrays)."""
        if self._handle is not None:
            return call(self._handle)
        out = ffi.new("gmpu_mesh **")
        v, f = self._vertices, self._faces
        check(lib.gmpu_mesh_create_with(double_ptr(v), len(v), uint32_ptr(f), len(f), double_ptr(self._normals),
                                        double_ptr(self._confidence), uint8_ptr(self._colors), out),
              "gmpu_mesh_create_with")
        mesh = ffi.gc(out[0], lib.gmpu_mesh_destroy)
        try:
            return call(mesh)
        finally:
            ffi.release(mesh)

    def simplify(self, target_triangles: int = 0, target_error: float = 1.0) -> "Mesh":
        """A decimated copy: at most ``target_triangles`` triangles (0: no count target) with
        the surface moved by at most ``target_error`` × the bounding-box diagonal. Keeps the
        topology (closed, manifold, components, genus), so it may stop above the count.
        Normals are recomputed; confidence is carried. Raises gmpu.InvalidArgumentError."""
        if isinstance(target_triangles, bool) or int(target_triangles) != target_triangles or target_triangles < 0:
            raise ValueError(f"target_triangles: expected a non-negative integer, got {target_triangles!r}")
        out = ffi.new("gmpu_mesh **")

        def call(handle):
            check(lib.gmpu_mesh_simplify(handle, int(target_triangles), float(target_error), out),
                  "gmpu_mesh_simplify")
        self._with_c_mesh(call)
        return Mesh._from_c(out[0])

    def trim(self, threshold: float = 1.5) -> "Mesh":
        """A copy cut where the confidence passes ``threshold`` sample spacings, in the regions
        that rise to twice it: the caps polygonize puts over a scan's holes go, leaving
        boundaries (triangles across the cut are clipped). Only meshes made by polygonize
        carry a confidence; others raise
        gmpu.InvalidArgumentError."""
        out = ffi.new("gmpu_mesh **")

        def call(handle):
            check(lib.gmpu_mesh_trim(handle, float(threshold), out), "gmpu_mesh_trim")
        self._with_c_mesh(call)
        return Mesh._from_c(out[0])

    def __repr__(self) -> str:
        return f"<gmpu.Mesh {len(self._vertices)} vertices, {len(self._faces)} faces>"

    def __reduce__(self):
        # Pickled as its arrays (copies: a library mesh's are views of C memory), so a mesh
        # can come back from multiprocessing; it unpickles as a mesh built from arrays.
        def copy(a):
            return None if a is None else np.array(a)
        return (Mesh, (np.array(self._vertices), np.array(self._faces), copy(self._normals), copy(self._confidence),
                       copy(self._colors)))

    @property
    def is_watertight(self) -> bool:
        """Closed and consistently wound: every edge shared by two triangles, crossed once each way."""
        return _mesh_facts.is_watertight(self._faces)

    @property
    def volume(self) -> float:
        """Enclosed volume (divergence theorem); positive when the mesh is wound outward."""
        return _mesh_facts.volume(self._vertices, self._faces)

    @property
    def area(self) -> float:
        """Summed triangle area."""
        return _mesh_facts.area(self._vertices, self._faces)

    @property
    def components(self) -> int:
        """Number of connected pieces (triangles linked through shared vertices)."""
        return _mesh_facts.components(len(self._vertices), self._faces)

    @property
    def genus(self) -> int:
        """Handles of a closed mesh, summed over its pieces (0 for a sphere, 1 for a torus).
        Raises ValueError for a mesh that is not watertight."""
        return _mesh_facts.genus(len(self._vertices), self._faces)

    def to_open3d(self):
        """An ``open3d.geometry.TriangleMesh`` with the same vertices, triangles and vertex
        normals (copies). Raises ImportError when Open3D is not installed."""
        import open3d as o3d  # optional: only this method needs it

        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.array(self._vertices)),
                                      o3d.utility.Vector3iVector(self._faces.astype(np.int32)))
        if self._normals is not None:
            m.vertex_normals = o3d.utility.Vector3dVector(np.array(self._normals))
        if self._colors is not None:
            m.vertex_colors = o3d.utility.Vector3dVector(self._colors / 255.0)
        return m

    def write(self, path: PathLike) -> None:
        """Writes the mesh; the format comes from the extension: .ply (binary), .obj, .off,
        .stl, .glb.

        Atomic: a failure never leaves a partial file. A mesh made by polygonize is written
        straight from the library's copy (byte for byte what gmpu-reconstruct writes); a mesh
        built from arrays goes through gmpu_mesh_create_with: its normals, confidence and
        colors are written too.
        Raises gmpu.UnsupportedError (extension), gmpu.IoError, gmpu.InvalidInputError
        (a non-finite vertex).
        """
        p = _fspath(path)
        self._with_c_mesh(lambda mesh: check(lib.gmpu_mesh_write(mesh, p), "gmpu_mesh_write", os.fspath(path)))


class Points:
    """A point cloud: ``positions`` (n×3 float64) and optional ``normals`` (n×3 float64).

    Acts as an n×3 array of its positions (``np.asarray(points)``), so it can be passed
    wherever points are expected. Normals are never used implicitly: pass
    ``normals=points.normals`` to use them.
    """

    def __init__(self, positions: ArrayLike, normals: Optional[ArrayLike] = None, colors: Optional[ArrayLike] = None):
        p = np.ascontiguousarray(_as_real_array(positions, "positions"), dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"positions: expected an n×3 array, got shape {p.shape}")
        n = None
        if normals is not None:
            n = np.ascontiguousarray(_as_real_array(normals, "normals"), dtype=np.float64)
            if n.shape != p.shape:
                raise ValueError(f"normals: expected shape {p.shape}, got {n.shape}")
        self._positions, self._normals, self._handle = p, n, None
        self._colors = _colours(colors, len(p))

    @classmethod
    def _from_c(cls, ptr) -> "Points":
        handle = ffi.gc(ptr, lib.gmpu_points_destroy)
        count = lib.gmpu_points_count(handle)
        self = cls.__new__(cls)
        self._handle = handle
        self._positions = view_of_c_memory(handle, lib.gmpu_points_positions(handle), (count, 3), np.float64)
        normals = lib.gmpu_points_normals(handle)
        self._normals = None if normals == ffi.NULL else view_of_c_memory(handle, normals, (count, 3), np.float64)
        colors = lib.gmpu_points_colors(handle)
        self._colors = None if colors == ffi.NULL else view_of_c_memory(handle, colors, (count, 3), np.uint8)
        return self

    @property
    def positions(self) -> NDArray[np.float64]:
        """n×3 float64 positions (read-only when read from a file: a view of library memory)."""
        return self._positions

    @property
    def normals(self) -> Optional[NDArray[np.float64]]:
        """n×3 float64 normals, or None when the file had none."""
        return self._normals

    @property
    def colors(self) -> Optional[NDArray[np.uint8]]:
        """n×3 uint8 red green blue, or None (only .ply files with uchar red green blue have them)."""
        return self._colors

    def _with_c_points(self, call):
        """call(gmpu_points*) on this cloud's library copy (made for the call when built from arrays)."""
        if self._handle is not None:
            return call(self._handle)
        out = ffi.new("gmpu_points **")
        check(lib.gmpu_points_create_with(double_ptr(self._positions), double_ptr(self._normals),
                                          uint8_ptr(self._colors), len(self), out), "gmpu_points_create_with")
        pts = ffi.gc(out[0], lib.gmpu_points_destroy)
        try:
            return call(pts)
        finally:
            ffi.release(pts)

    def __len__(self) -> int:
        return len(self._positions)

    def __array__(self, dtype=None):
        return np.asarray(self._positions, dtype=dtype)

    def __repr__(self) -> str:
        return f"<gmpu.Points {len(self)} points{', with normals' if self._normals is not None else ''}>"

    def write(self, path: PathLike) -> None:
        """Writes the points (and normals, if any): .ply (binary) or .xyz (ascii). Atomic."""
        p = _fspath(path)
        if self._handle is not None:
            check(lib.gmpu_points_write(self._handle, p), "gmpu_points_write", os.fspath(path))
            return
        out = ffi.new("gmpu_points **")
        check(lib.gmpu_points_create(double_ptr(self._positions), double_ptr(self._normals), len(self), out),
              "gmpu_points_create")
        pts = ffi.gc(out[0], lib.gmpu_points_destroy)
        try:
            check(lib.gmpu_points_write(pts, p), "gmpu_points_write", os.fspath(path))
        finally:
            ffi.release(pts)


def read_points(path: PathLike, *, max_memory: float = 0, progress: Optional[ProgressFn] = None) -> Points:
    """Reads a point cloud: .ply (ascii or binary; x y z, optional nx ny nz, optional uchar
    red green blue), .xyz / .txt (3 or 6 columns), .off / .obj (vertices only). The arrays
    are views of the library's copy (no second copy).

    max_memory: budget in bytes (0: half the physical memory); a file whose points would need
    more raises gmpu.LimitExceededError before its body is read. progress: f(Stage.READ,
    fraction), with the stages' contract (False or an exception cancels).
    Raises gmpu.IoError, gmpu.ParseError, gmpu.UnsupportedError, gmpu.InvalidInputError
    (no points), gmpu.LimitExceededError, gmpu.CancelledError."""
    out = ffi.new("gmpu_points **")
    p = _fspath(path)
    status = run_read_with_progress(lambda fn: lib.gmpu_points_read_with(p, float(max_memory), fn, ffi.NULL, out),
                                    progress)
    check(status, "gmpu_points_read_with", os.fspath(path))
    return Points._from_c(out[0])


class Surface:
    """An MPU implicit surface reconstructed from unoriented points.

    ::

        with gmpu.Surface(points, error=0.002) as s:
            s.fit()
            s.orient()
            f = s.evaluate(queries)       # > 0 inside, < 0 outside, ≈ signed distance
            mesh = s.polygonize()

    Parameters are the C library's (see ``gmpu.PARAMS``): error, max_depth, min_points,
    support_scale, sharp_features, resolution, level, threads, max_cells, max_triangles,
    noise_scale, max_memory; None keeps the library default.

    The C handle is freed by :meth:`close` (or leaving the ``with`` block); the garbage
    collector frees it otherwise. Methods are thread-safe: evaluate, gradient, normals,
    params and stats run concurrently with each other; the stages and setters wait for
    exclusive access. The GIL is released during every C call.
    """

    def __init__(self, points: Union[ArrayLike, Points, PathLike], *, normals: Optional[ArrayLike] = None,
                 progress: Optional[ProgressFn] = None, **params: Any):
        """Creates the surface, sets parameters, points (an n×3 float32/float64 array-like,
        a gmpu.Points or a file path) and optional outward normals (n×3).
        Raises ValueError (shape/dtype), TypeError (unknown parameter), gmpu.InvalidArgumentError
        (parameter out of range), gmpu.InvalidInputError (NaN/inf, too few points, normals
        count), gmpu.DegenerateInputError (points bound no volume)."""
        self._ptr = None
        self._points = 0
        self._lock = _RWLock()
        #: Default progress callable for fit/orient/polygonize: f(stage, fraction).
        self.progress: Optional[ProgressFn] = progress
        out = ffi.new("gmpu_surface **")
        check(lib.gmpu_surface_create(out), "gmpu_surface_create")
        self._ptr = out[0]
        self._finalizer = weakref.finalize(self, lib.gmpu_surface_destroy, self._ptr)
        try:
            self.set_params(**params)
            if isinstance(points, (str, os.PathLike)):
                points = read_points(points)
            self.set_points(points)
            if normals is not None:
                self.set_normals(normals)
        except BaseException:
            self.close()
            raise

    # -- lifetime --------------------------------------------------------------------------

    def close(self) -> None:
        """Frees the C surface now (waits for calls running in other threads). Idempotent.
        Meshes already made stay valid."""
        self._lock.acquire_write()
        try:
            if self._ptr is not None:
                self._ptr = None
                self._finalizer()  # gmpu_surface_destroy, exactly once
        finally:
            self._lock.release_write()

    @property
    def closed(self) -> bool:
        return self._ptr is None

    def __enter__(self) -> "Surface":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def __repr__(self) -> str:
        if self._ptr is None:
            return "<gmpu.Surface (closed)>"
        return f"<gmpu.Surface {self._points} points>"  # no C call: safe from anywhere

    def _live(self):
        if self._ptr is None:
            raise ValueError("operation on a closed gmpu.Surface")
        return self._ptr

    def _read(self, fn, *args):
        self._lock.acquire_read()
        try:
            return fn(self._live(), *args)
        finally:
            self._lock.release_read()

    def _write(self, fn, *args):
        self._lock.acquire_write()
        try:
            return fn(self._live(), *args)
        finally:
            self._lock.release_write()

    # -- input and parameters ---------------------------------------------------------------

    def set_points(self, points: Union[ArrayLike, Points]) -> None:
        """Replaces the points (discards fit, orientation and normals). float32 and float64
        are passed to the library without conversion, and without copying when each point's
        x y z are adjacent (C order, or rows of a wider array); Fortran order is copied."""
        arr, kind, ptr, count, stride = xyz_for_c(points, "points")
        fn = lib.gmpu_surface_set_points_f64 if kind == "f64" else lib.gmpu_surface_set_points_f32
        name = "gmpu_surface_set_points_" + kind
        self._write(lambda s: check(fn(s, ptr, count, stride), name))
        self._points = count
        del arr  # kept alive until here: the library copies during the call

    def set_normals(self, normals: ArrayLike) -> None:
        """Sets outward normals for the points (same count and order): orient then signs each
        local fit by them instead of belief propagation."""
        arr, kind, ptr, count, stride = xyz_for_c(normals, "normals")
        fn = lib.gmpu_surface_set_normals_f64 if kind == "f64" else lib.gmpu_surface_set_normals_f32
        name = "gmpu_surface_set_normals_" + kind
        self._write(lambda s: check(fn(s, ptr, count, stride), name))
        del arr

    def set_params(self, **params: Any) -> None:
        """Sets parameters by name; None values are skipped. Changing error, max_depth,
        min_points, support_scale, sharp_features or noise_scale discards a previous fit."""
        items = [(_param_key(k), k, _param_number(k, v)) for k, v in params.items() if v is not None]
        if not items:
            return

        def apply(s):
            for key, name, value in items:
                check(lib.gmpu_surface_set_param(s, key, value), f"gmpu_surface_set_param({name})")

        if len(items) > 1:
            # All or nothing: validate on a scratch surface first (ranges are all the library
            # checks), so that a bad value never leaves the real one half-updated.
            out = ffi.new("gmpu_surface **")
            check(lib.gmpu_surface_create(out), "gmpu_surface_create")
            try:
                apply(out[0])
            finally:
                lib.gmpu_surface_destroy(out[0])
        self._write(apply)

    def get_param(self, name: str) -> Union[int, float, bool]:
        """The current value of one parameter."""
        key = _param_key(name)
        value = ffi.new("double *")
        self._read(lambda s: check(lib.gmpu_surface_get_param(s, key, value), "gmpu_surface_get_param"))
        return param_value(name, value[0])

    @property
    def params(self) -> Dict[str, Union[int, float, bool]]:
        """Every parameter's current value, by name."""
        return {name: self.get_param(name) for name in PARAMS}

    @property
    def stats(self) -> Dict[str, Union[int, float]]:
        """Statistics of the latest completed stages (cells, leaves, components, seconds per
        stage, ...), by name; 0 for stages not run yet."""
        value = ffi.new("double *")

        def body(s):
            out = {}
            for name, key in STATS.items():
                check(lib.gmpu_surface_get_stat(s, key, value), "gmpu_surface_get_stat")
                out[name] = float(value[0]) if name in _FLOAT_STATS else int(value[0])
            return out

        return self._read(body)

    @property
    def point_count(self) -> int:
        """Number of input points."""
        return int(self._read(lib.gmpu_surface_point_count))

    def __len__(self) -> int:
        return self.point_count

    # -- stages -----------------------------------------------------------------------------

    def _stage(self, fn, name: str, progress: Optional[ProgressFn], *args) -> None:
        progress = progress if progress is not None else self.progress

        def body(s):
            check(run_with_progress(s, lambda: fn(s, *args), progress), name)

        self._write(body)

    def fit(self, progress: Optional[ProgressFn] = None) -> "Surface":
        """Builds the adaptive octree of local quadric fits. `progress` (default:
        self.progress) is called with (Stage.FIT, fraction); an exception raised in it, or
        Ctrl-C, cancels the stage and propagates. Returns self."""
        self._stage(lib.gmpu_surface_fit, "gmpu_surface_fit", progress)
        return self

    def orient(self, progress: Optional[ProgressFn] = None) -> "Surface":
        """Makes the local fits' signs consistent (belief propagation) and outward.
        Returns self."""
        self._stage(lib.gmpu_surface_orient, "gmpu_surface_orient", progress)
        return self

    def polygonize(self, resolution: Optional[int] = None, level: Optional[int] = None,
                   progress: Optional[ProgressFn] = None) -> Mesh:
        """Extracts the zero set as a closed, outward-wound Mesh. resolution (8..4096 grid
        cubes along the longest side; 0 = automatic) and level (octree level-of-detail cap;
        0 = all) apply to this call only; None uses the surface's parameters."""
        overrides = {k: _param_number(k, v) for k, v in (("resolution", resolution), ("level", level))
                     if v is not None}
        out = ffi.new("gmpu_mesh **")
        progress = progress if progress is not None else self.progress

        def body(s):
            saved = {}
            value = ffi.new("double *")
            try:
                for name, v in overrides.items():
                    check(lib.gmpu_surface_get_param(s, PARAMS[name], value), "gmpu_surface_get_param")
                    saved[name] = value[0]
                    check(lib.gmpu_surface_set_param(s, PARAMS[name], v), f"gmpu_surface_set_param({name})")
                status = run_with_progress(s, lambda: lib.gmpu_surface_polygonize(s, out), progress)
                check(status, "gmpu_surface_polygonize")
            except BaseException:
                if out[0] != ffi.NULL:  # completed, but the callback raised at the very end
                    lib.gmpu_mesh_destroy(out[0])
                    out[0] = ffi.NULL
                raise
            finally:
                for name, v in saved.items():
                    lib.gmpu_surface_set_param(s, PARAMS[name], v)

        self._write(body)
        return Mesh._from_c(out[0])

    # -- queries (thread-safe, concurrent) ------------------------------------------------------

    def _evaluate(self, q: ArrayLike, values: bool, gradients: bool):
        flat, batch = queries_for_c(q)
        n = len(flat)
        vals = np.empty(n, np.float64) if values else None
        grads = np.empty((n, 3), np.float64) if gradients else None
        xyz, vp, gp = double_ptr(flat), double_ptr(vals), double_ptr(grads)

        def body(s):
            if n <= _EVAL_CHUNK or not np.isfinite(flat).all():
                # One call; for a non-finite query it fails before evaluating anything, with
                # the index of the first bad point in the library's message.
                check(lib.gmpu_surface_evaluate(s, xyz, n, vp, gp), "gmpu_surface_evaluate")
                return
            # Large queries go in chunks, so that Ctrl-C is noticed between them (evaluate
            # has no progress callback). Per-call cost is ~2 µs against ~5 µs per point.
            for start in range(0, n, _EVAL_CHUNK):
                count = min(_EVAL_CHUNK, n - start)
                check(lib.gmpu_surface_evaluate(s, xyz + 3 * start, count,
                                                vp + start if values else ffi.NULL,
                                                gp + 3 * start if gradients else ffi.NULL),
                      "gmpu_surface_evaluate")

        self._read(body)
        if vals is not None:
            vals = vals.reshape(batch) if batch else float(vals[0])
        if grads is not None:
            grads = grads.reshape(batch + (3,))
        return vals, grads

    def evaluate(self, q: ArrayLike, *, gradient: bool = False):
        """f at query points q of shape (..., 3) (or one point, shape (3,)): positive inside,
        negative outside, about the signed distance near the surface, in the points' units.
        Returns an array of shape (...) (a float for one point); with gradient=True, the
        tuple (f, ∇f) from one pass. Needs orient(). Raises gmpu.InvalidInputError for a NaN
        or infinite query, gmpu.WrongOrderError before orient()."""
        vals, grads = self._evaluate(q, True, gradient)
        return (vals, grads) if gradient else vals

    def gradient(self, q: ArrayLike) -> NDArray[np.float64]:
        """∇f at query points q of shape (..., 3): shape (..., 3). It points into the solid;
        -∇f/|∇f| is the outward normal."""
        return self._evaluate(q, False, True)[1]

    @property
    def normals(self) -> NDArray[np.float64]:
        """Oriented unit outward normal of every input point (n×3 float64, a fresh array).
        Needs orient()."""

        def body(s):
            n = lib.gmpu_surface_point_count(s)
            out = np.empty((n, 3), np.float64)
            check(lib.gmpu_surface_copy_normals(s, double_ptr(out), n), "gmpu_surface_copy_normals")
            return out

        return self._read(body)

    def normals_at(self, indices: ArrayLike) -> NDArray[np.float64]:
        """Oriented unit outward normals of the input points `indices` (len×3 float64, a fresh
        array): rows of `normals`, without an array of every point's normal. Needs orient();
        an index below 0 or not below the point count raises gmpu.InvalidArgumentError."""
        idx = np.asarray(indices)
        if idx.ndim != 1 or not (idx.dtype.kind in "iu" or idx.size == 0):
            raise TypeError("indices must be a 1-d array of integers")
        idx = np.ascontiguousarray(idx, np.int64)

        def body(s):
            out = np.empty((len(idx), 3), np.float64)
            check(lib.gmpu_surface_copy_normals_at(s, ffi.from_buffer("int64_t[]", idx), len(idx), double_ptr(out)),
                  "gmpu_surface_copy_normals_at")
            return out

        return self._read(body)


def reconstruct(points: Union[ArrayLike, Points, PathLike], *, normals: Optional[ArrayLike] = None,
                error: Optional[float] = None, max_depth: Optional[int] = None,
                resolution: Optional[int] = None, level: Optional[int] = None,
                threads: Optional[int] = None, progress: Optional[ProgressFn] = None,
                **params: Any) -> Mesh:
    """Unoriented points → closed, outward-facing mesh, in one call (fit, orient, polygonize).

    points: n×3 float32/float64 array-like, a gmpu.Points, or a point file's path.
    normals: optional outward normals (n×3); skips belief propagation.
    error: ε, fraction of the bounding-box diagonal (library default 0.002).
    max_depth: deepest octree level (default 10). resolution: polygonization grid (0/None:
    automatic). level: level-of-detail cap (0/None: all). threads: worker threads
    (0/None: all cores). Other gmpu parameters by name (see gmpu.PARAMS).
    progress: f(stage, fraction); raising in it (or Ctrl-C) cancels and propagates.
    Coloured points (a .ply with red green blue) give a coloured mesh: each vertex takes the
    colour of its nearest point, as gmpu-reconstruct does.
    """
    if isinstance(points, (str, os.PathLike)):
        points = read_points(points)
    with Surface(points, normals=normals, progress=progress, error=error, max_depth=max_depth,
                 threads=threads, resolution=resolution, level=level, **params) as s:
        s.fit()
        s.orient()
        mesh = s.polygonize()
    if isinstance(points, Points) and points.colors is not None:
        return mesh.color_from(points)
    return mesh
