"""Progress callbacks, cancellation and Ctrl-C for the long C calls (fit, orient, polygonize).

One C callback serves every surface. Before a long call, the binding pushes the call's state
on a thread-local stack (the library calls back on the thread that made the call, so the top
of that thread's stack is always the running call). The callback forwards (stage, fraction)
to the user's callable. If anything raises in it (the user's exception, or KeyboardInterrupt
delivered by Ctrl-C, since the Python signal handler runs when the callback executes Python
code on the main thread), cffi hands the exception to ``_on_error``, which stores it, and the
callback returns 1: the library stops the stage within 100 ms and returns
GMPU_ERROR_CANCELLED, and the binding re-raises the stored exception.

With no user callable, the callback is still installed on the main thread, so that Ctrl-C
cancels the C work there too. On other threads (which never receive KeyboardInterrupt) no
callback is installed, and the C code runs without ever taking the GIL.
"""
from __future__ import annotations

import enum
import threading
from typing import Callable, List, Optional

from ._library import ffi, lib

__all__ = ["Stage", "ProgressFn", "CallState", "run_with_progress", "run_read_with_progress"]


class Stage(enum.IntEnum):
    """The long stages that report progress (values of the C enum gmpu_stage)."""

    FIT = lib.GMPU_STAGE_FIT
    ORIENT = lib.GMPU_STAGE_ORIENT
    POLYGONIZE = lib.GMPU_STAGE_POLYGONIZE
    READ = lib.GMPU_STAGE_READ  # read_points

    def __str__(self) -> str:
        return self.name.lower()


#: A progress callable: receives the stage and a fraction in [0, 1] (non-decreasing within a
#: stage, 1.0 when it completes). Returning False cancels the stage (gmpu.CancelledError; any
#: other value, None included, goes on), as false does in Node, ControlFlow::Break in Rust and
#: a non-zero return in C. Raising cancels it too, and the exception is re-raised.
ProgressFn = Callable[[Stage, float], object]

_tls = threading.local()


class CallState:
    __slots__ = ("progress", "exc")

    def __init__(self, progress: Optional[ProgressFn]):
        self.progress = progress
        self.exc: Optional[BaseException] = None


def _stack() -> List[CallState]:
    stack = getattr(_tls, "stack", None)
    if stack is None:
        stack = _tls.stack = []
    return stack


def _on_progress(user, stage, fraction):
    stack = getattr(_tls, "stack", None)
    if not stack:
        return 0  # not a call the binding made on this thread: nothing to route to
    state = stack[-1]
    if state.exc is not None:
        return 1
    if state.progress is not None:
        try:
            stage = Stage(stage)
        except ValueError:  # a stage added to the library after this binding
            stage = int(stage)
        if state.progress(stage, fraction) is False:
            return 1
    return 0


def _on_error(exc_type, exc_value, traceback):
    stack = getattr(_tls, "stack", None)
    if stack and stack[-1].exc is None:
        if exc_value is None:
            exc_value = exc_type()
        stack[-1].exc = exc_value.with_traceback(traceback)
    return None  # → the callback returns error=1: cancel


_C_PROGRESS = ffi.callback("gmpu_progress_fn", _on_progress, error=1, onerror=_on_error)


def run_with_progress(surface_ptr, call: Callable[[], int], progress: Optional[ProgressFn]) -> int:
    """Runs call() (a long C call on surface_ptr, made with the GIL released by cffi) with the
    progress callback routed to `progress`, and returns its status. If the callback raised,
    that exception is re-raised here, after the C call has stopped."""
    main = threading.current_thread() is threading.main_thread()
    fn = _C_PROGRESS if (progress is not None or main) else ffi.NULL
    status = lib.gmpu_surface_set_progress(surface_ptr, fn, ffi.NULL)
    if status != 0:  # pragma: no cover - only fails for a NULL surface
        return status
    return _routed(call, progress)


def run_read_with_progress(call: Callable[[object], int], progress: Optional[ProgressFn]) -> int:
    """run_with_progress for gmpu_points_read_with, which takes the callback as an argument:
    call(fn) gets the C callback (NULL when nothing listens) and returns the status."""
    main = threading.current_thread() is threading.main_thread()
    fn = _C_PROGRESS if (progress is not None or main) else ffi.NULL
    return _routed(lambda: call(fn), progress)


def _routed(call: Callable[[], int], progress: Optional[ProgressFn]) -> int:
    state = CallState(progress)
    stack = _stack()
    stack.append(state)
    try:
        status = call()
    finally:
        stack.pop()
    if state.exc is not None:
        exc, state.exc = state.exc, None
        try:
            raise exc
        finally:
            del exc
    return status
