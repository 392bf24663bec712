"""gmpu: unoriented point cloud → watertight, outward-oriented implicit surface and mesh.

Generalized MPU implicits with belief-propagation orientation, through the C library's
stable ABI (cffi, ABI mode: nothing to compile).

    >>> import gmpu
    >>> cloud = gmpu.read_points("bunny.ply")          # doctest: +SKIP
    >>> mesh = gmpu.reconstruct(cloud)                 # doctest: +SKIP
    >>> mesh.write("bunny_mesh.ply")                   # doctest: +SKIP

Arrays in and out are numpy: points are any n×3 float32/float64 array-like; meshes expose
``vertices`` (n×3 float64) and ``faces`` (m×3 uint32). Failures raise :class:`gmpu.Error`
subclasses carrying the C status name and message (the input-related ones are also
``ValueError``); wrong shapes or dtypes raise ``ValueError``.

The shared library is found through $GMPU_LIBRARY, then next to the installed package,
then the source tree's meson build directory (see gmpu._library).
"""
from ._library import LibraryNotFoundError, library_path, library_version, lib as _lib
from ._errors import (BusyError, CancelledError, DegenerateInputError, Error, InternalError, InvalidArgumentError,
                      InvalidInputError, IoError, LimitExceededError, OutOfMemoryError, ParseError,
                      UnsupportedError, WrongOrderError)
from ._progress import ProgressFn, Stage
from ._params import ParamInfo
from ._core import PARAM_INFO, PARAMS, STATS, Mesh, Points, Surface, read_points, reconstruct

__version__ = library_version
#: ABI version of the loaded library (the SONAME number).
abi_version = int(_lib.gmpu_abi_version())

__all__ = [
    "reconstruct", "Surface", "Mesh", "Points", "read_points", "Stage", "ProgressFn", "PARAMS", "PARAM_INFO", "ParamInfo", "STATS",
    "Error", "InvalidArgumentError", "InvalidInputError", "DegenerateInputError", "WrongOrderError",
    "OutOfMemoryError", "LimitExceededError", "CancelledError", "IoError", "ParseError", "UnsupportedError",
    "InternalError", "BusyError", "LibraryNotFoundError", "library_path", "library_version", "abi_version", "__version__",
]
