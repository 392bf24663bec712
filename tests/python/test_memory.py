"""Memory does not grow over 100 create/destroy cycles (RSS from /proc/self/statm).

The cycles run in a fresh interpreter: in this long-lived pytest process, memory freed by
earlier tests sits in malloc's free lists and would silently absorb a leak without RSS
moving. Besides RSS, the child reads glibc's mallinfo2 (bytes in use), which also measures
what one cycle holds when kept alive, so the test knows what a leak would look like and
checks that it would have noticed one.
"""
import gc
import json
import weakref

import gmpu

from conftest import run_python

CYCLES = 100

CHILD = r"""
import ctypes, gc, json, os, sys
import numpy as np
import gmpu

class MallInfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks",
                 "keepcost")]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2

def in_use():
    m = libc.mallinfo2()
    return m.uordblks + m.hblkhd

def rss():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")

cycles, cloud_path, kitten_path = int(sys.argv[1]), sys.argv[2], sys.argv[3]
pts = np.ascontiguousarray(gmpu.read_points(cloud_path).positions[::14])  # 2,500 points

def one_cycle():
    # Everything that allocates on the C side: a surface through every stage, a mesh and its
    # arrays, a mesh built from arrays and written, a point file read.
    with gmpu.Surface(pts) as s:
        s.fit().orient()
        s.evaluate(pts[:500], gradient=True)
        s.normals
        mesh = s.polygonize(resolution=12)
    v = mesh.vertices
    gmpu.Mesh(np.array(v), np.array(mesh.faces)).write(sys.argv[4])
    del mesh, v
    return gmpu.read_points(kitten_path).positions.shape

for _ in range(10):  # warm up: allocator arenas, caches, lazily created objects
    one_cycle()
gc.collect()

# What one cycle holds while alive: keep 10 of them.
before = in_use()
kept = []
for _ in range(10):
    s = gmpu.Surface(pts).fit().orient()
    kept.append((s, s.polygonize(resolution=12), gmpu.read_points(kitten_path)))
per_cycle = (in_use() - before) / 10
for s, _, _ in kept:
    s.close()
del kept, s
gc.collect()

gc.disable()  # frees must come from close() and reference counting, not the cycle collector
rss0, use0 = rss(), in_use()
for _ in range(cycles):
    one_cycle()
print(json.dumps({"per_cycle": per_cycle, "rss_growth": rss() - rss0, "in_use_growth": in_use() - use0}))
"""


def test_no_growth_over_100_create_destroy_cycles(clouds, tmp_path):
    r = run_python(CHILD, args=[CYCLES, clouds / "bunny_clean.ply", clouds / "kitten_scan.ply", tmp_path / "m.ply"],
                   timeout=600)
    assert r.returncode == 0, r.stderr
    m = json.loads(r.stdout.strip().splitlines()[-1])
    per_cycle, rss_growth, in_use_growth = m["per_cycle"], m["rss_growth"], m["in_use_growth"]
    report = (f"one cycle holds {per_cycle / 1e6:.2f} MB; over {CYCLES} cycles RSS grew {rss_growth / 1e6:.2f} MB, "
              f"bytes in use {in_use_growth / 1e6:.3f} MB")
    print("\n" + report)
    budget = max(4 << 20, 10 * per_cycle)  # RSS: allocator noise, at most a tenth of a full leak
    assert CYCLES * per_cycle > 2 * budget, "a leak of every cycle would not clear the budget: " + report
    assert rss_growth < budget, report
    assert in_use_growth < max(256 << 10, per_cycle), report  # less than one cycle's worth, in total


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
    assert faces.max() >= 0 and handle() is not None  # the arrays keep the C mesh alive
    del faces
    gc.collect()
    assert handle() is None  # the cffi handle, whose destructor calls gmpu_mesh_destroy, is gone
