"""Progress callbacks, cancellation by exception, Ctrl-C (real SIGINT, in a child process)."""
import json

import numpy as np
import pytest

import gmpu

from conftest import run_python


class Stop(Exception):
    pass


def test_progress_reports_every_stage_in_order(small_cloud):
    calls = []
    mesh = gmpu.reconstruct(small_cloud[0], resolution=48, progress=lambda st, f: calls.append((st, f)))
    assert len(mesh.faces) > 0
    stages = [st for st, _ in calls]
    assert all(isinstance(st, gmpu.Stage) for st in stages)
    assert stages == sorted(stages) and set(stages) == set(gmpu.Stage) - {gmpu.Stage.READ}
    for stage in set(gmpu.Stage) - {gmpu.Stage.READ}:
        fr = [f for st, f in calls if st == stage]
        assert fr[0] == 0.0 and fr[-1] == 1.0
        assert all(0.0 <= a <= b <= 1.0 for a, b in zip(fr, fr[1:]))


def test_surface_progress_attribute_and_per_call_override(small_cloud):
    default, override = [], []
    with gmpu.Surface(small_cloud[0], progress=lambda st, f: default.append(st)) as s:
        s.fit()
        s.orient(progress=lambda st, f: override.append(st))
        s.progress = None
        s.polygonize(resolution=16)
    assert set(default) == {gmpu.Stage.FIT} and set(override) == {gmpu.Stage.ORIENT}


def test_exception_in_callback_cancels_fit_and_propagates(small_cloud):
    seen = []
    boom = Stop("user says stop")

    def progress(stage, fraction):
        seen.append(fraction)
        if len(seen) == 2:
            raise boom

    with gmpu.Surface(small_cloud[0]) as s:
        with pytest.raises(Stop) as e:
            s.fit(progress=progress)
        assert e.value is boom
        assert len(seen) == 2  # never called again once it raised
        # The C stage was cancelled, not completed: no fit was kept.
        assert s.stats["cells"] == 0 and s.stats["fit_seconds"] == 0
        with pytest.raises(gmpu.WrongOrderError):
            s.orient()
        # The surface is still usable.
        s.fit().orient()
        assert s.stats["cells"] > 0


def test_returning_false_cancels_and_none_goes_on(small_cloud):
    """The progress contract of every binding: False cancels (CancelledError), the surface
    keeps what it had; any other return value, None included, goes on."""
    seen = []

    def progress(stage, fraction):
        seen.append(fraction)
        return False if len(seen) == 2 else None

    with gmpu.Surface(small_cloud[0]) as s:
        with pytest.raises(gmpu.CancelledError) as e:
            s.fit(progress=progress)
        assert e.value.status_name == "GMPU_ERROR_CANCELLED" and len(seen) == 2
        assert s.stats["cells"] == 0
        s.fit(progress=lambda st, f: 0).orient(progress=lambda st, f: True)  # only False cancels
        assert s.stats["cells"] > 0


def test_exception_cancels_polygonize_midway_and_keeps_the_orientation(small_cloud):
    fractions = []

    def progress(stage, fraction):
        fractions.append(fraction)
        if stage == gmpu.Stage.POLYGONIZE and fraction > 0:
            raise KeyError("stop here")

    with gmpu.Surface(small_cloud[0]) as s:
        s.fit().orient()
        f = s.evaluate(small_cloud[0][:10])
        with pytest.raises(KeyError, match="stop here"):
            s.polygonize(resolution=128, progress=progress)
        assert 0 < fractions[-1] < 1
        assert s.stats["polygonize_seconds"] == 0  # never completed
        assert np.array_equal(s.evaluate(small_cloud[0][:10]), f)
        assert len(s.polygonize(resolution=16).faces) > 0


def test_exception_at_the_last_report_still_propagates(small_cloud):
    def progress(stage, fraction):
        if fraction == 1.0:
            raise Stop("at the end")

    with gmpu.Surface(small_cloud[0]) as s:
        s.fit().orient()
        with pytest.raises(Stop):
            s.polygonize(resolution=16, progress=progress)
        assert len(s.polygonize(resolution=16).faces) > 0


def test_callback_may_not_reenter_its_own_surface(small_cloud):
    with gmpu.Surface(small_cloud[0]) as s:
        with pytest.raises(RuntimeError, match="own progress callback"):
            s.fit(progress=lambda st, f: s.params)
        assert s.stats["cells"] == 0


def test_callbacks_of_nested_surfaces_are_routed_to_their_own_call(small_cloud):
    pts = small_cloud[0]
    outer_calls, inner_calls = [], []
    inner = gmpu.Surface(pts[::2])

    def outer_progress(stage, fraction):
        outer_calls.append(fraction)
        if len(outer_calls) == 1:
            inner.fit(progress=lambda st, f: inner_calls.append(f))  # another handle: allowed

    with gmpu.Surface(pts) as outer, inner:
        outer.fit(progress=outer_progress)
        assert inner_calls[-1] == 1.0 and outer_calls[-1] == 1.0
        assert inner.stats["cells"] > 0 and outer.stats["cells"] > 0


# A child process that sends itself a real SIGINT while its main thread is inside the C
# polygonize call, and reports what happened. A helper thread watches the main thread's
# Python stack to know when the C call is running (its frame is the binding's call lambda).
CTRL_C_CHILD = r"""
import json, os, signal, sys, threading, time, traceback
import gmpu

# Python's own Ctrl-C handler, whatever the disposition inherited: a job started in the
# background (nohup make test &) inherits SIGINT ignored, and Python then installs none.
signal.signal(signal.SIGINT, signal.default_int_handler)
mode = sys.argv[1]
pts = gmpu.read_points(sys.argv[2])
s = gmpu.Surface(pts).fit().orient()
fractions = []
progress = (lambda st, f: fractions.append(f)) if mode == "callback" else None
main = threading.main_thread().ident

def interrupter():
    while True:
        frame = sys._current_frames().get(main)
        names = []
        while frame is not None:
            names.append(frame.f_code.co_name)
            frame = frame.f_back
        if names and names[0] == "<lambda>" and "run_with_progress" in names:
            time.sleep(0.02)  # inside the C call, which then runs for seconds
            os.kill(os.getpid(), signal.SIGINT)
            return
        time.sleep(0.005)

threading.Thread(target=interrupter, daemon=True).start()
try:
    s.polygonize(resolution=400, progress=progress)
    outcome, frames = "completed", []
except KeyboardInterrupt as e:
    outcome, frames = "interrupted", [f.name for f in traceback.extract_tb(e.__traceback__)]
stats = s.stats
after = len(s.polygonize(resolution=16).faces)  # still usable
print(json.dumps({"outcome": outcome, "frames": frames, "polygonize_seconds": stats["polygonize_seconds"],
                  "fractions": fractions[-3:], "faces_after": after}))
"""


@pytest.mark.parametrize("mode", ["callback", "no-callback"])
def test_ctrl_c_cancels_the_c_work_and_raises_keyboard_interrupt(mode, small_cloud, clouds):
    r = run_python(CTRL_C_CHILD, args=[mode, str(clouds / "bunny_clean.ply")], timeout=300)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["outcome"] == "interrupted", out
    # Raised inside the progress callback, i.e. while C was running, which then stopped:
    assert "_on_progress" in out["frames"], out
    assert out["polygonize_seconds"] == 0, out
    assert out["faces_after"] > 0
    if mode == "callback":
        assert out["fractions"] and out["fractions"][-1] < 1.0, out
