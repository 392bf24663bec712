"""Shared fixtures for the gmpu Python binding tests.

Run with `make test-python` (or `/usr/bin/python3 -m pytest tests/python`). The binding is
imported from bindings/python of this checkout and loads build/lib/libgmpu.so.1 unless
GMPU_LIBRARY says otherwise. Test data: $GMPU_TEST_DATA, else tests/data of this checkout.
"""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
BINDINGS = REPO / "bindings" / "python"
if str(BINDINGS) not in sys.path:
    sys.path.insert(0, str(BINDINGS))

import gmpu  # noqa: E402

PYTHON = "/usr/bin/python3"
CLI = REPO / "build" / "examples" / "gmpu-reconstruct"
SAMPLE = REPO / "examples" / "data" / "bunny.ply"


def repository_data_dir() -> Path:
    env = os.environ.get("GMPU_TEST_DATA")
    return Path(env) if env else REPO / "tests" / "data"


@pytest.fixture(scope="session")
def data_dir() -> Path:
    d = repository_data_dir()
    if not (d / "clouds").is_dir():
        pytest.fail(f"test data not found: {d}/clouds (it ships with the repository; GMPU_TEST_DATA overrides it)")
    return d


@pytest.fixture(scope="session")
def clouds(data_dir) -> Path:
    return data_dir / "clouds"


@pytest.fixture(scope="session")
def cli() -> Path:
    if not CLI.exists():
        pytest.fail(f"{CLI} is missing: run `make build` first")
    return CLI


@pytest.fixture(scope="session")
def bunny_gt(clouds):
    """35k bunny points with their ground-truth outward normals (gmpu.Points)."""
    return gmpu.read_points(clouds / "bunny_clean_gt.ply")


@pytest.fixture(scope="session")
def small_cloud(bunny_gt):
    """(positions, gt_normals): every 7th bunny point, 5,000 points, C-ordered float64 copies."""
    return np.ascontiguousarray(bunny_gt.positions[::7]), np.ascontiguousarray(bunny_gt.normals[::7])


@pytest.fixture(scope="session")
def oriented(small_cloud):
    """A fitted and oriented Surface of the small cloud, shared by read-only tests."""
    s = gmpu.Surface(small_cloud[0])
    s.fit()
    s.orient()
    yield s
    s.close()


def run_python(code: str, args=(), env_extra=None, cwd=None, timeout=120, pythonpath=True):
    """Runs code (with sys.argv[1:] = args) in a fresh /usr/bin/python3 that imports gmpu
    from this checkout (pythonpath=False: from wherever the interpreter finds it)."""
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if pythonpath:
        env["PYTHONPATH"] = str(BINDINGS)
    env.update(env_extra or {})
    return subprocess.run([PYTHON, "-c", code, *map(str, args)], env=env, cwd=cwd or REPO, capture_output=True,
                          text=True, timeout=timeout)


def rss_bytes() -> int:
    """Resident set size of this process (/proc/self/statm, pages → bytes)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
