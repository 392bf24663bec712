"""One reconstruction on a worker thread, so Blender's UI keeps drawing while gmpu works.

No bpy here: the job takes a numpy array of points and a dict of gmpu parameters, and hands
back a gmpu.Mesh, an error message, or "cancelled". The main thread polls it (a modal
operator's timer, or a loop in background mode) and is the only one that touches Blender data.
"""
from __future__ import annotations

import threading
from typing import Any, Dict, Optional

from . import decimation

# The three progress-reporting stages, in pipeline order, and their share of the bar.
_STAGES = ("fit", "orient", "polygonize")


class _Cancelled(Exception):
    """Raised in the progress callback: the binding returns "cancel" to the library, which
    stops the running stage within 100 ms, and re-raises this after the C call has returned."""


class ReconstructJob:
    """Runs gmpu.reconstruct(points, **params), then the optional decimation, on its own thread.

    cancel_after: a test hook; when > 0, the job cancels itself at that progress call, the
    same path Esc takes (a background Blender has no keyboard to press Esc on).
    """

    def __init__(self, gmpu_module, points, params: Dict[str, Any], target_triangles: int = 0,
                 cancel_after: int = 0):
        self._gmpu = gmpu_module
        self._points = points
        self._params = dict(params)
        self._target_triangles = target_triangles
        self._cancel_after = cancel_after
        self._cancel = threading.Event()
        self._calls = 0
        self.fraction = 0.0  # overall progress in [0, 1], read by the main thread
        self.stage = ""
        self.mesh = None
        self.error: Optional[str] = None
        self.warning: Optional[str] = None
        self.cancelled = False
        self._thread = threading.Thread(target=self._run, name="gmpu-reconstruct", daemon=True)

    def start(self) -> "ReconstructJob":
        self._thread.start()
        return self

    def cancel(self) -> None:
        """Asks the job to stop; it does at the library's next progress call."""
        self._cancel.set()

    @property
    def done(self) -> bool:
        return not self._thread.is_alive()

    def wait(self, timeout: Optional[float] = None) -> bool:
        self._thread.join(timeout)
        return self.done

    def _progress(self, stage, fraction: float) -> None:
        self._calls += 1
        if self._cancel_after and self._calls >= self._cancel_after:
            self._cancel.set()
        if self._cancel.is_set():
            raise _Cancelled()
        name = str(stage)
        index = _STAGES.index(name) if name in _STAGES else 0
        self.stage = name
        self.fraction = (index + min(max(fraction, 0.0), 1.0)) / len(_STAGES)

    def _run(self) -> None:
        try:
            mesh = self._gmpu.reconstruct(self._points, progress=self._progress, **self._params)
            self.mesh, self.warning = decimation.apply(self._gmpu, mesh, self._target_triangles)
            self.fraction = 1.0
        except _Cancelled:
            self.cancelled = True
        except self._gmpu.CancelledError:
            self.cancelled = True
        except Exception as e:  # any failure becomes a report, never an exception in Blender
            self.error = str(e) or type(e).__name__
