"""numpy ⇄ C: pass caller memory straight to the library when its layout allows it, copy only
when it must, and wrap library-owned memory as numpy arrays without copying."""
from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ._library import ffi

def _as_real_array(a: Any, name: str) -> np.ndarray:
    """np.asarray(a) checked to hold float32 or float64 numbers (either byte order).

    A numpy array of any other dtype (int64, float16, ...) raises ValueError rather than
    being converted behind the caller's back; nested Python sequences of numbers, which
    have no dtype of their own, are read as float64."""
    if hasattr(a, "positions") and not isinstance(a, np.ndarray):  # a gmpu.Points
        a = a.positions
    given_dtype = isinstance(a, np.ndarray) or hasattr(a, "__array_interface__")
    try:
        arr = np.asarray(a)
    except Exception as e:  # ragged lists and the like
        raise ValueError(f"{name}: cannot be read as an array of numbers ({e})") from None
    if arr.dtype.kind == "f" and arr.dtype.itemsize in (4, 8):
        return arr if arr.dtype.isnative else arr.astype(arr.dtype.newbyteorder("="))
    if given_dtype:
        raise ValueError(f"{name}: expected float32 or float64, got dtype {arr.dtype} "
                         "(convert it with .astype(np.float64))")
    if arr.dtype.kind in "iu":
        return arr.astype(np.float64)
    raise ValueError(f"{name}: expected real numbers (float32 or float64), got dtype {arr.dtype}")


def xyz_for_c(a: Any, name: str = "points") -> Tuple[np.ndarray, str, Any, int, int]:
    """An n×3 array-like as the library's (pointer, count, stride) triple.

    Returns (array_to_keep_alive, "f64" | "f32", pointer, count, stride_in_bytes). The array is
    the caller's own memory whenever x, y, z of each point are adjacent and points are a
    positive, fixed stride apart (C order, row slices such as ``a[::2]`` or ``a[:, :3]`` of a
    wider array); otherwise (Fortran order, negative or overlapping strides, unaligned or
    byte-swapped data, other dtypes) it is a C-ordered copy.
    """
    arr = _as_real_array(a, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name}: expected an n×3 array, got shape {arr.shape}")
    item = arr.dtype.itemsize
    n = arr.shape[0]
    row, col = arr.strides
    usable = arr.flags.aligned and (col == item) and (n <= 1 or row >= 3 * item)
    if not usable:
        arr = np.ascontiguousarray(arr)
        row = 3 * item
    if n <= 1:
        row = 3 * item
    kind = "f64" if item == 8 else "f32"
    if n == 0:
        # The library rejects NULL even with a zero count; give it a valid empty buffer so the
        # error it reports is the meaningful one (too few points).
        arr = np.zeros((1, 3), arr.dtype)
    ptr = _pointer(arr, "double" if kind == "f64" else "float")
    return arr, kind, ptr, n, row


def queries_for_c(q: Any) -> Tuple[np.ndarray, Tuple[int, ...]]:
    """Query points (..., 3) as a packed C-ordered float64 array (n, 3), and the batch shape
    of the results. gmpu_surface_evaluate takes packed doubles only, so anything else is
    copied (float64 C-ordered input never is)."""
    arr = _as_real_array(q, "query points")
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"query points: expected an array of shape (..., 3), got shape {arr.shape}")
    batch = arr.shape[:-1]
    flat = np.ascontiguousarray(arr, dtype=np.float64).reshape(-1, 3)
    return flat, batch


def _pointer(arr: np.ndarray, ctype: str):
    """A ctype* to arr's first element. For a contiguous array it is a cffi buffer view, which
    keeps arr alive (and is the cheapest way in); for a strided one, a plain cast of the
    address, so the caller must keep arr alive during the C call."""
    if arr.flags.c_contiguous:
        return ffi.from_buffer(ctype + "[]", arr)
    return ffi.cast(ctype + " *", arr.__array_interface__["data"][0])


def double_ptr(arr: Optional[np.ndarray]):
    """A double* into a C-contiguous float64 array (NULL for None)."""
    if arr is None:
        return ffi.NULL
    return _pointer(arr, "double")


def uint32_ptr(arr: np.ndarray):
    """A uint32_t* into a C-contiguous uint32 array."""
    return _pointer(arr, "uint32_t")


def uint8_ptr(arr: Optional[np.ndarray]):
    """A uint8_t* into a C-contiguous uint8 array (NULL for None)."""
    if arr is None:
        return ffi.NULL
    return _pointer(arr, "uint8_t")


def view_of_c_memory(owner, ptr, shape: Tuple[int, ...], dtype) -> np.ndarray:
    """A read-only numpy view of library memory at ptr, keeping owner (a cffi cdata whose
    destructor frees that memory) alive for as long as the view or any view of it exists.

    No copy is made: the view's base chain is array → cffi buffer → a cdata whose destructor
    holds the only extra reference to owner.
    """
    dtype = np.dtype(dtype)
    count = int(np.prod(shape))
    if count == 0 or ptr == ffi.NULL:
        out = np.empty(shape, dtype)
    else:
        keep = ffi.gc(ptr, lambda _p, _owner=owner: None)
        out = np.frombuffer(ffi.buffer(keep, count * dtype.itemsize), dtype=dtype).reshape(shape)
    out.flags.writeable = False
    return out
