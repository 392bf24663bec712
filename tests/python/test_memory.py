"""Memory does not grow over 100 create/destroy cycles (RSS from /proc/self/statm)."""
import gc
import weakref

import numpy as np

import gmpu

from conftest import rss_bytes

CYCLES = 100


def _one_cycle(pts, path):
    """Everything that allocates on the C side: a surface through every stage, a mesh and
    its arrays, a mesh built from arrays, a point file read."""
    with gmpu.Surface(pts) as s:
        s.fit().orient()
        s.evaluate(pts[:500], gradient=True)
        s.normals
        mesh = s.polygonize(resolution=12)
    v = mesh.vertices
    gmpu.Mesh(np.array(v), np.array(mesh.faces))
    del mesh, v
    cloud = gmpu.read_points(path)
    return cloud.positions.shape


def test_no_growth_over_100_create_destroy_cycles(small_cloud, clouds):
    pts = small_cloud[0][:2500]
    path = clouds / "kitten_scan.ply"
    for _ in range(10):  # warm up allocator arenas, caches, lazily created objects
        _one_cycle(pts, path)
    gc.collect()
    # Footprint of one live surface + mesh + cloud, to know what a leak would look like.
    before = rss_bytes()
    kept = []
    for _ in range(10):
        s = gmpu.Surface(pts).fit().orient()
        kept.append((s, s.polygonize(resolution=12), gmpu.read_points(path)))
    per_cycle = (rss_bytes() - before) / 10
    for s, _, _ in kept:
        s.close()
    del kept, s
    gc.collect()

    gc.disable()  # frees must come from close() and reference counting, not the cycle collector
    try:
        start = rss_bytes()
        for _ in range(CYCLES):
            _one_cycle(pts, path)
        growth = rss_bytes() - start
    finally:
        gc.enable()
    budget = max(4 << 20, 10 * per_cycle)
    print(f"per cycle {per_cycle / 1e6:.2f} MB, growth over {CYCLES} cycles {growth / 1e6:.2f} MB")
    assert CYCLES * per_cycle > 2 * budget, (
        f"a leak of every cycle ({per_cycle / 1e6:.2f} MB each) would not clear the budget: test too weak")
    assert growth < budget, (
        f"RSS grew {growth / 1e6:.1f} MB over {CYCLES} cycles (one cycle holds {per_cycle / 1e6:.2f} MB)")


def test_surfaces_are_collected_without_close(small_cloud):
    # No reference cycle keeps a Surface (and its C handle) alive once it is unreachable.
    s = gmpu.Surface(small_cloud[0][:2000]).fit()
    ref = weakref.ref(s)
    fin = s._finalizer
    gc.disable()
    try:
        del s
        assert ref() is None and not fin.alive  # freed by reference counting alone
    finally:
        gc.enable()


def test_mesh_memory_is_freed_with_its_last_array(small_cloud):
    with gmpu.Surface(small_cloud[0][:2000]) as s:
        s.fit().orient()
        mesh = s.polygonize(resolution=12)
    handle = weakref.ref(mesh._handle)
    faces = mesh.faces
    del mesh
    gc.collect()
    assert faces.max() >= 0  # still readable
    del faces
    gc.collect()
    # The cffi handle (whose destructor calls gmpu_mesh_destroy) is gone with the arrays.
    assert handle() is None
