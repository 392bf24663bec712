"""Imports the gmpu Python binding bundled in the add-on, loading libgmpu from the place the
user chose.

The zip carries the binding (pure Python: cffi + numpy, both in Debian's Blender) as the
subpackage gmpu_reconstruct.gmpu, but not the shared library, which is built for the machine.
The library is looked up as the binding always does, with one addition in front: the add-on
preference "Library path", when set, is handed to the binding as $GMPU_LIBRARY for the
duration of the import only (the process environment is restored right after). Otherwise
$GMPU_LIBRARY from Blender's environment, then the system's library search path.

The import is lazy (first run of the operator), so a missing library is an error report,
not a failure to enable the add-on; a failed import leaves nothing cached, so fixing the
preference and running again works without restarting Blender.
"""
from __future__ import annotations

import importlib
import os
from typing import Tuple

ENV = "GMPU_LIBRARY"
_SUBPACKAGE = __package__ + ".gmpu"


def load(library_path: str = ""):
    """The gmpu module. Raises ImportError with the binding's list of places tried."""
    wanted = os.path.abspath(bpy_path(library_path)) if library_path else ""
    module = _loaded()
    if module is not None:
        if wanted and not _same_library(module.library_path, wanted):
            raise ImportError(f"gmpu already loaded {module.library_path} in this Blender session; "
                              f"restart Blender to use {wanted}")
        return module
    saved = os.environ.get(ENV)
    if wanted:
        os.environ[ENV] = wanted
    try:
        return importlib.import_module(_SUBPACKAGE)
    except ModuleNotFoundError as e:
        if e.name and e.name.startswith(_SUBPACKAGE):
            raise ImportError("the gmpu Python package is not bundled in this add-on; install the add-on "
                              "from the zip `make plugins` builds (build/plugins/)") from e
        raise
    finally:
        if wanted:
            if saved is None:
                os.environ.pop(ENV, None)
            else:
                os.environ[ENV] = saved


def _loaded():
    import sys

    return sys.modules.get(_SUBPACKAGE)


def _same_library(loaded: str, wanted: str) -> bool:
    if os.path.isdir(wanted):
        return os.path.dirname(loaded) == wanted.rstrip(os.sep)
    return os.path.realpath(loaded) == os.path.realpath(wanted)


def bpy_path(path: str) -> str:
    """Blender's relative paths ("//lib") are relative to the .blend file."""
    if path.startswith("//"):
        try:
            import bpy

            return bpy.path.abspath(path)
        except ImportError:  # pragma: no cover - only outside Blender
            pass
    return os.path.expanduser(path)


def describe() -> Tuple[str, str]:
    """(library path, version) once loaded, or ("", "") before the first run."""
    module = _loaded()
    if module is None:
        return "", ""
    return module.library_path, module.library_version
