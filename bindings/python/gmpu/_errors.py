"""Exceptions: one gmpu.Error subclass per C status, each carrying the C status and message."""
from __future__ import annotations

import errno
import os
from typing import Dict, Optional, Type

from ._library import ffi, lib

__all__ = [
    "Error", "InvalidArgumentError", "InvalidInputError", "DegenerateInputError", "WrongOrderError",
    "OutOfMemoryError", "LimitExceededError", "CancelledError", "IoError", "ParseError",
    "UnsupportedError", "InternalError", "check",
]


class Error(Exception):
    """A gmpu C call failed.

    Attributes:
        status: the C ``gmpu_status`` value (int).
        status_name: its enumerator name, e.g. ``"GMPU_ERROR_INVALID_INPUT"``.
        message: the library's message (``gmpu_last_error()``), which starts with the name.
        function: the C function that failed, e.g. ``"gmpu_surface_set_points_f64"``.
    """

    def __init__(self, message: str, status: int = -1, status_name: str = "", function: str = ""):
        super().__init__(message)
        self.message = message
        self.status = status
        self.status_name = status_name
        self.function = function


class InvalidArgumentError(Error, ValueError):
    """GMPU_ERROR_INVALID_ARGUMENT: a parameter out of range, a bad count or stride."""


class InvalidInputError(Error, ValueError):
    """GMPU_ERROR_INVALID_INPUT: NaN/inf coordinates, too few points, a size mismatch."""


class DegenerateInputError(Error, ValueError):
    """GMPU_ERROR_DEGENERATE_INPUT: identical, collinear or coplanar points bound no solid."""


class WrongOrderError(Error, RuntimeError):
    """GMPU_ERROR_WRONG_ORDER: a stage was called before the one it needs (fit, then orient)."""


class OutOfMemoryError(Error, MemoryError):
    """GMPU_ERROR_OUT_OF_MEMORY."""


class LimitExceededError(Error, RuntimeError):
    """GMPU_ERROR_LIMIT_EXCEEDED: the max_cells, max_triangles or max_memory cap was hit."""


class CancelledError(Error):
    """GMPU_ERROR_CANCELLED without a Python exception to re-raise (rare: the progress
    callback's own exception is re-raised instead whenever there is one)."""


class IoError(Error, OSError):
    """GMPU_ERROR_IO: a file could not be opened, read or written.

    When the system's reason is known, the exception is also the matching builtin
    (``FileNotFoundError``, ``PermissionError``, ``IsADirectoryError``, ``NotADirectoryError``)
    with ``errno``, ``strerror`` and ``filename`` set; ``str()`` stays the library's message.
    """

    def __str__(self) -> str:
        return self.message


class IoFileNotFoundError(IoError, FileNotFoundError):
    """GMPU_ERROR_IO for a missing file or directory (ENOENT)."""


class IoPermissionError(IoError, PermissionError):
    """GMPU_ERROR_IO for a file the process may not read or write (EACCES, EPERM)."""


class IoIsADirectoryError(IoError, IsADirectoryError):
    """GMPU_ERROR_IO for a directory where a file was expected (EISDIR)."""


class IoNotADirectoryError(IoError, NotADirectoryError):
    """GMPU_ERROR_IO for a path through something that is not a directory (ENOTDIR)."""


# The library's IO messages end with the system's reason, strerror's text (the C++
# std::generic_category() message is strerror's on glibc, as os.strerror is).
_IO_ERRNO_CLASSES = [
    (errno.ENOENT, IoFileNotFoundError),
    (errno.EACCES, IoPermissionError),
    (errno.EPERM, IoPermissionError),
    (errno.EISDIR, IoIsADirectoryError),
    (errno.ENOTDIR, IoNotADirectoryError),
]


def _io_error(message: str, status: int, name: str, function: str, filename: Optional[str]) -> IoError:
    for code, cls in _IO_ERRNO_CLASSES:
        reason = os.strerror(code)
        if message.endswith(reason) or f": {reason}" in message:
            e = cls(message, status=status, status_name=name, function=function)
            e.errno, e.strerror = code, reason
            e.filename = filename
            return e
    e = IoError(message, status=status, status_name=name, function=function)
    e.filename = filename
    return e


class ParseError(Error, ValueError):
    """GMPU_ERROR_PARSE: a file's contents are malformed or truncated."""


class UnsupportedError(Error, ValueError):
    """GMPU_ERROR_UNSUPPORTED: unknown file extension or format variant."""


class InternalError(Error, RuntimeError):
    """GMPU_ERROR_INTERNAL: a bug in gmpu; please report it with the message."""


class BusyError(Error, RuntimeError):
    """GMPU_ERROR_BUSY: a call on a surface from its own progress callback (this package
    raises RuntimeError before the call reaches the library)."""


#: C status name → exception class. A status the library gains later maps to Error itself.
ERROR_CLASSES: Dict[str, Type[Error]] = {
    "GMPU_ERROR_INVALID_ARGUMENT": InvalidArgumentError,
    "GMPU_ERROR_INVALID_INPUT": InvalidInputError,
    "GMPU_ERROR_DEGENERATE_INPUT": DegenerateInputError,
    "GMPU_ERROR_WRONG_ORDER": WrongOrderError,
    "GMPU_ERROR_OUT_OF_MEMORY": OutOfMemoryError,
    "GMPU_ERROR_LIMIT_EXCEEDED": LimitExceededError,
    "GMPU_ERROR_CANCELLED": CancelledError,
    "GMPU_ERROR_IO": IoError,
    "GMPU_ERROR_PARSE": ParseError,
    "GMPU_ERROR_UNSUPPORTED": UnsupportedError,
    "GMPU_ERROR_INTERNAL": InternalError,
    "GMPU_ERROR_BUSY": BusyError,
}


def error_from_status(status: int, function: str, filename: Optional[str] = None) -> Error:
    """The exception for a failed call, read on the thread that made it (gmpu_last_error is
    per thread and valid until the next gmpu call there). filename: the file the call read
    or wrote, given to IoError."""
    name = ffi.string(lib.gmpu_status_name(status)).decode()
    message = ffi.string(lib.gmpu_last_error()).decode("utf-8", "replace")
    if not message:
        message = f"{name}: {function} failed"
    if name == "GMPU_ERROR_IO":
        return _io_error(message, int(status), name, function, filename)
    cls = ERROR_CLASSES.get(name, Error)
    return cls(message, status=int(status), status_name=name, function=function)


def check(status: int, function: str, filename: Optional[str] = None) -> None:
    """Raises the matching Error unless status is GMPU_OK."""
    if status != 0:
        raise error_from_status(status, function, filename)
