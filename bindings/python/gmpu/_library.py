"""Finds and loads libgmpu with cffi in ABI mode (dlopen; nothing is compiled).

Lookup order, first hit wins:

1. ``$GMPU_LIBRARY``: a path to the library file (or to a directory holding it). When set, it
   is the only place tried, so a typo never silently falls back to another copy.
2. Next to the installed package: the library that ``meson install`` put beside this package
   (its location is recorded in ``_install.py`` at install time), or a ``libgmpu.so.1``
   inside the package directory itself.
3. The meson build directory of the source tree this package sits in (``build/lib``), for
   ``PYTHONPATH=bindings/python`` in a checkout.
4. The system's dynamic loader search path (``ldconfig`` cache, ``LD_LIBRARY_PATH``).

If all fail, :class:`LibraryNotFoundError` lists every place and why it failed.
"""
from __future__ import annotations

import os
from typing import List, Tuple

from cffi import FFI

from ._cdef import CDEF

__all__ = ["ffi", "lib", "library_path", "LibraryNotFoundError", "find_library"]

LIBRARY_NAME = "libgmpu.so.1"  # the SONAME: ABI 1

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
SOURCE_ROOT = os.path.abspath(os.path.join(PACKAGE_DIR, "..", "..", ".."))

ffi = FFI()
ffi.cdef(CDEF)


class LibraryNotFoundError(ImportError):
    """libgmpu could not be found or loaded; the message lists every place tried."""


def _installed_candidates(package_dir: str) -> List[Tuple[str, str]]:
    out = [("inside the package directory", os.path.join(package_dir, LIBRARY_NAME))]
    try:
        from . import _install  # written by meson install; absent in a source checkout
    except ImportError:
        return out
    # The library's place relative to the package, as configured, works both at the final
    # prefix and in a `meson install --destdir` staging tree; the absolute path is the fallback
    # for a package that was copied elsewhere after installation.
    rel = os.path.relpath(_install.LIBDIR, _install.PACKAGE_DIR)
    out.append(("next to the installed package", os.path.normpath(os.path.join(package_dir, rel, LIBRARY_NAME))))
    out.append(("installed library directory", os.path.join(_install.LIBDIR, LIBRARY_NAME)))
    return out


def find_library(environ=os.environ, package_dir: str = PACKAGE_DIR,
                 source_root: str = SOURCE_ROOT) -> Tuple[List[Tuple[str, str]], bool]:
    """The ordered (description, path) candidates, and whether $GMPU_LIBRARY pinned them.

    Pure: touches only the file system, never loads anything (tests call it directly).
    """
    env = environ.get("GMPU_LIBRARY")
    if env:
        path = os.path.join(env, LIBRARY_NAME) if os.path.isdir(env) else env
        return [("$GMPU_LIBRARY", path)], True
    cands = [("$GMPU_LIBRARY", None)]
    cands += _installed_candidates(package_dir)
    if os.path.isfile(os.path.join(source_root, "include", "gmpu", "gmpu.h")):
        cands.append(("meson build directory", os.path.join(source_root, "build", "lib", LIBRARY_NAME)))
    else:
        cands.append(("meson build directory", None))  # not in a source checkout
    cands.append(("system library search path", LIBRARY_NAME))
    return cands, False


def _load():
    candidates, pinned = find_library()
    tried = []
    seen = set()
    for what, path in candidates:
        if path is None:
            tried.append(f"  {what}: " + ("not set" if what == "$GMPU_LIBRARY" else "not in a source checkout"))
            continue
        if path in seen:
            continue
        seen.add(path)
        is_file_path = os.sep in path
        if is_file_path and not os.path.exists(path):
            tried.append(f"  {what}: {path}: no such file")
            continue
        try:
            handle = ffi.dlopen(path)
        except OSError as e:
            tried.append(f"  {what}: {path}: {e}")
            continue
        return handle, (os.path.abspath(path) if is_file_path else path)
    hint = ("unset GMPU_LIBRARY or point it at libgmpu.so.1" if pinned else
            "build it with `make build` in the source tree, install it with `meson install`, "
            "or set GMPU_LIBRARY to its path")
    raise LibraryNotFoundError(f"cannot load {LIBRARY_NAME}; looked in:\n" + "\n".join(tried) + f"\n({hint})")


lib, library_path = _load()

if lib.gmpu_abi_version() != lib.GMPU_ABI_VERSION:
    raise LibraryNotFoundError(
        f"{library_path} has ABI version {lib.gmpu_abi_version()}, but this binding was generated "
        f"for ABI {lib.GMPU_ABI_VERSION} (include/gmpu/gmpu.h): they do not match")

#: Version string of the loaded library ("0.1.0").
library_version: str = ffi.string(lib.gmpu_version_string()).decode()

if lib.gmpu_version_number() < lib.GMPU_VERSION_NUMBER:  # pragma: no cover - needs an old library
    import warnings

    warnings.warn(f"{library_path} is version {library_version}, older than the header this binding "
                  f"was generated from ({lib.GMPU_VERSION_NUMBER}); newer functions may be missing",
                  RuntimeWarning, stacklevel=2)
