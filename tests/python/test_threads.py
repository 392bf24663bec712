"""The GIL is released during C calls; concurrent use of one surface is safe and exact."""
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import gmpu


def _largest_stall(work):
    """Runs work() in a worker thread while this thread counts in pure Python, and returns
    (largest gap between this thread's ticks while work() ran, work()'s duration).

    If work() held the GIL, this thread could not tick during it: the gap would be about the
    whole duration. With the GIL released, gaps stay at scheduler scale (milliseconds).
    The worker is not the main thread, so no progress callback is installed and the C code
    never re-enters Python: nothing else could hand the GIL over while it runs.
    """
    span = {}
    ready = threading.Event()

    def worker():
        ready.wait()
        span["t0"] = time.perf_counter()
        work()
        span["t1"] = time.perf_counter()

    th = threading.Thread(target=worker)
    th.start()
    ticks = []
    ready.set()
    while th.is_alive():
        ticks.append(time.perf_counter())
        for _ in range(200):  # a little pure-Python work between ticks
            pass
    th.join()
    t0, t1 = span["t0"], span["t1"]
    inside = [t0] + [t for t in ticks if t0 <= t <= t1] + [t1]
    return max(b - a for a, b in zip(inside, inside[1:])), t1 - t0


def _big_cloud(bunny_gt, copies=4):
    """Copies of the 35k bunny side by side: enough work for a C call to last a while."""
    pts = bunny_gt.positions
    step = 1.5 * (pts.max(0) - pts.min(0))[0]
    return np.concatenate([pts + [i * step, 0, 0] for i in range(copies)])


def test_gil_is_released_during_fit(bunny_gt):
    with gmpu.Surface(_big_cloud(bunny_gt), error=0.0005, threads=1) as s:
        stall, duration = _largest_stall(s.fit)
        assert s.stats["cells"] > 0
    assert duration > 0.1, "the fit was too short to tell"
    assert stall < 0.5 * duration, f"Python stalled {stall:.3f} s during a {duration:.3f} s fit: GIL held?"


def test_gil_is_released_during_evaluate(bunny_gt, oriented):
    q = _big_cloud(bunny_gt, 2)[:60000] + 1e-3  # one C call (below the chunk size)
    stall, duration = _largest_stall(lambda: oriented.evaluate(q))
    assert duration > 0.1, "the evaluation was too short to tell"
    assert stall < 0.5 * duration, f"Python stalled {stall:.3f} s during a {duration:.3f} s evaluate"


def test_concurrent_evaluate_equals_single_threaded(oriented, small_cloud):
    pts, gt = small_cloud
    rng = np.random.default_rng(7)
    q = pts[rng.integers(0, len(pts), 40000)] + rng.normal(scale=0.01, size=(40000, 3))
    ref_f, ref_g = oriented.evaluate(q, gradient=True)
    chunks = np.array_split(np.arange(len(q)), 16)
    start = threading.Barrier(4)

    def job(idx):
        if idx is chunks[0] or idx is chunks[1] or idx is chunks[2] or idx is chunks[3]:
            start.wait()  # the first four start together
        return oriented.evaluate(q[idx], gradient=True)

    with ThreadPoolExecutor(max_workers=4) as ex:
        results = list(ex.map(job, chunks))
    f = np.concatenate([r[0] for r in results])
    g = np.concatenate([r[1] for r in results])
    assert np.array_equal(f, ref_f) and np.array_equal(g, ref_g)
    # Same queries from all threads at once, too.
    with ThreadPoolExecutor(max_workers=4) as ex:
        same = list(ex.map(lambda _: oriented.evaluate(q[:5000]), range(8)))
    for r in same:
        assert np.array_equal(r, ref_f[:5000])
    normals = [None] * 4
    threads = [threading.Thread(target=lambda i=i: normals.__setitem__(i, oriented.normals)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for n in normals[1:]:
        assert np.array_equal(n, normals[0])


def test_separate_surfaces_fit_in_parallel_threads(small_cloud):
    pts, _ = small_cloud

    def build(i):
        with gmpu.Surface(pts[i::3]) as s:
            s.fit().orient()
            return s.evaluate(pts[:100])

    with ThreadPoolExecutor(max_workers=3) as ex:
        parallel = list(ex.map(build, range(3)))
    serial = [build(i) for i in range(3)]
    for a, b in zip(parallel, serial):
        assert np.array_equal(a, b)


def test_writers_wait_for_running_readers(small_cloud):
    # close() (and any stage) waits for evaluations running in other threads, instead of
    # freeing the surface under them.
    pts, _ = small_cloud
    s = gmpu.Surface(pts).fit().orient()
    q = np.repeat(pts, 4, axis=0)
    started, results, errors = threading.Event(), [], []

    def reader():
        started.set()
        try:
            for _ in range(3):
                results.append(s.evaluate(q))
        except ValueError as e:  # closed before this evaluation started: fine
            errors.append(e)

    th = threading.Thread(target=reader)
    th.start()
    started.wait()
    s.close()
    th.join()
    assert s.closed
    assert results or errors
    for r in results:
        assert np.isfinite(r).all()
    for e in errors:
        assert "closed" in str(e)


def test_stage_from_a_worker_thread_has_no_callback_but_works(small_cloud):
    calls = []
    out = {}

    def run():
        with gmpu.Surface(small_cloud[0]) as s:
            s.fit(progress=lambda st, f: calls.append(threading.get_ident()))
            s.orient()
            out["mesh"] = s.polygonize(resolution=16)

    th = threading.Thread(target=run)
    th.start()
    th.join()
    assert len(out["mesh"].faces) > 0
    assert calls and set(calls) == {th.ident}  # the library calls back on the calling thread


def test_refused_worker_threads_cost_speed_not_the_interpreter():
    """Under a process limit that refuses most worker threads (a container's pids cap,
    `ulimit -u`), reconstruct(threads=16) used to kill the interpreter (std::terminate); it
    must give the mesh of threads=1. Root ignores RLIMIT_NPROC, so a root run drops to nobody
    in the child first (which owns no other task: a limit of 3 leaves room for 2 threads)."""
    import hashlib
    import os
    from pathlib import Path
    import resource
    import subprocess
    import sys

    import pytest
    from conftest import BINDINGS

    rng = np.random.default_rng(3)
    pts = rng.normal(size=(4000, 3))
    pts /= np.linalg.norm(pts, axis=1)[:, None]
    pts[:, 0] *= 1.0 + 0.3 * np.sin(4 * pts[:, 2])
    mesh = gmpu.reconstruct(pts, threads=1, resolution=32)
    expected = hashlib.sha256(mesh.vertices.tobytes() + mesh.faces.tobytes()).hexdigest()
    script = (
        "import hashlib, sys, numpy as np, gmpu\n"
        "pts = np.frombuffer(sys.stdin.buffer.read(), dtype=np.float64).reshape(-1, 3)\n"
        "m = gmpu.reconstruct(pts, threads=16, resolution=32)\n"
        "print(hashlib.sha256(m.vertices.tobytes() + m.faces.tobytes()).hexdigest())\n")

    def limit(nproc):
        def apply():
            if os.geteuid() == 0:
                os.setgid(65534)
                os.setuid(65534)
            resource.setrlimit(resource.RLIMIT_NPROC, (nproc, nproc))
        return apply

    env = dict(os.environ, PYTHONPATH=str(BINDINGS), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    if os.geteuid() == 0:
        # nobody may not be able to read the checkout (a clone under `mktemp -d` is 0700):
        # give the child a world-readable copy of the binding and of the library it loads.
        import shutil
        import tempfile
        from gmpu import _library
        readable = Path(tempfile.mkdtemp())
        readable.chmod(0o755)
        shutil.copytree(BINDINGS / "gmpu", readable / "gmpu", ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copy(os.path.realpath(_library.library_path), readable / "libgmpu.so.1")
        for path in readable.rglob("*"):
            path.chmod(0o755 if path.is_dir() else 0o644)
        env.update(PYTHONPATH=str(readable), GMPU_LIBRARY=str(readable / "libgmpu.so.1"))
    for nproc in (1, 3):
        try:
            run = subprocess.run([sys.executable, "-c", script], env=env, preexec_fn=limit(nproc),
                                 input=pts.tobytes(), capture_output=True, timeout=300)
        except PermissionError:  # pragma: no cover - a sandbox that forbids setuid
            pytest.skip("cannot drop privileges for the process limit")
        assert run.returncode == 0, f"RLIMIT_NPROC {nproc}: exit {run.returncode}: {run.stderr[-2000:]!r}"
        assert run.stdout.decode().strip() == expected, f"RLIMIT_NPROC {nproc}: another mesh"
