"""gmpu.dask: tiled reconstruction on a 2-worker LocalCluster (threads in one process:
processes=False, so the suite starts in a second), tiles forced small so that a 50k-point
bunny spans 8 tiles. The welded mesh must be closed and manifold, one piece, of the untiled
mesh's genus, close to it (Chamfer) and outward; a tile whose surface comes out reversed is
put right by the tiles' sign reconciliation and breaks the mesh without it."""
import subprocess
import sys

import numpy as np
import pytest

import gmpu
from conftest import BINDINGS, PYTHON

distributed = pytest.importorskip("distributed")
scipy_spatial = pytest.importorskip("scipy.spatial")
import gmpu.dask as gd  # noqa: E402

TILE_POINTS = 7000  # 50k points → 8 tiles


def read_off(path):
    with open(path) as f:
        words = f.read().split()
    assert words[0] == "OFF"
    nv, nf = int(words[1]), int(words[2])
    v = np.array(words[4:4 + 3 * nv], float).reshape(nv, 3)
    rest = np.array(words[4 + 3 * nv:4 + 3 * nv + 4 * nf], np.int64).reshape(nf, 4)
    return v, rest[:, 1:]


def sample_surface(vertices, faces, n, seed):
    """n points uniformly on the triangles (area-weighted), reproducibly."""
    rng = np.random.default_rng(seed)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    tri = rng.choice(len(faces), n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return a[tri] + u[:, None] * (b[tri] - a[tri]) + v[:, None] * (c[tri] - a[tri])


def edge_problems(faces):
    """(boundary edges, non-manifold edges) of a triangle mesh."""
    f = faces.astype(np.int64)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int((counts == 1).sum()), int((counts > 2).sum())


def components_and_genus(faces, vertex_count):
    """Connected pieces and the genus of a closed mesh (Euler: V − E + F = 2(C − g))."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    f = faces.astype(np.int64)
    graph = coo_matrix((np.ones(2 * len(f)), (np.concatenate([f[:, 0], f[:, 1]]), np.concatenate([f[:, 1], f[:, 2]]))),
                       shape=(vertex_count, vertex_count))
    used = np.unique(f)
    n, label = connected_components(graph, directed=False)
    pieces = len(np.unique(label[used]))
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    edges = len(np.unique(e[:, 0] * vertex_count + e[:, 1]))
    chi = len(used) - edges + len(f)
    return pieces, (2 * pieces - chi) // 2


def chamfer(a, b):
    """Mean of the two one-sided mean nearest-vertex distances."""
    da, _ = scipy_spatial.cKDTree(b).query(a)
    db, _ = scipy_spatial.cKDTree(a).query(b)
    return 0.5 * (da.mean() + db.mean())


@pytest.fixture(scope="module")
def cloud(data_dir):
    v, f = read_off(data_dir / "meshes" / "bunny00.off")
    return sample_surface(v, f, 50_000, seed=17)


@pytest.fixture(scope="module")
def untiled(cloud):
    with gmpu.Surface(cloud) as s:
        s.fit()
        s.orient()
        mesh = s.polygonize()
        return mesh, int(s.stats["resolution"])


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def tiled(cloud, untiled, client):
    stats = {}
    mesh = gd.reconstruct(cloud, client, tile_points=TILE_POINTS, resolution=untiled[1], stats=stats, threads=1)
    return mesh, stats


def test_the_cloud_spans_eight_tiles(tiled):
    assert tiled[1]["tiles"] == 8
    assert all(n > 0 for n in tiled[1]["tile_points"])
    # Where a tile's memory goes: resident size after each stage, and the peak.
    assert tiled[1]["tile_peak_bytes"] > 0 and min(tiled[1]["tile_resident_bytes"].values()) > 0


def test_the_union_is_closed_and_manifold(tiled):
    assert edge_problems(tiled[0].faces) == (0, 0)


def test_topology_is_the_untiled_one(tiled, untiled):
    pieces, genus = components_and_genus(tiled[0].faces, len(tiled[0].vertices))
    assert (pieces, genus) == components_and_genus(untiled[0].faces, len(untiled[0].vertices))
    assert pieces == 1


def test_close_to_the_untiled_mesh_and_outward(tiled, untiled, cloud):
    diagonal = np.linalg.norm(cloud.max(0) - cloud.min(0))
    assert chamfer(tiled[0].vertices, untiled[0].vertices) < 2e-3 * diagonal
    assert tiled[0].volume > 0
    assert abs(tiled[0].volume / untiled[0].volume - 1) < 0.01


def test_a_reversed_tile_is_reconciled(cloud, untiled, client):
    """Tile 3's surface turned over (as an open patch's orientation may come out): the
    reconciliation flips it back; without it the mesh is wrong."""
    mesh = gd.reconstruct(cloud, client, tile_points=TILE_POINTS, resolution=untiled[1], threads=1,
                          _flip_tiles=[3])
    assert edge_problems(mesh.faces) == (0, 0)
    assert components_and_genus(mesh.faces, len(mesh.vertices)) == \
        components_and_genus(untiled[0].faces, len(untiled[0].vertices))
    assert mesh.volume > 0
    assert abs(mesh.volume / untiled[0].volume - 1) < 0.01
    # Marching cubes closes any consistent set of corner values, so the reversed tile
    # does not open the mesh: it turns its part inside out, with handles where it meets
    # the other tiles.
    broken = gd.reconstruct(cloud, client, tile_points=TILE_POINTS, resolution=untiled[1], threads=1,
                            _flip_tiles=[3], reconcile=False)
    assert components_and_genus(broken.faces, len(broken.vertices))[1] != \
        components_and_genus(untiled[0].faces, len(untiled[0].vertices))[1] or \
        abs(broken.volume / untiled[0].volume - 1) > 0.01


def test_an_inward_oriented_tile_is_refitted(cloud, untiled, client):
    """Tile 3 fitted with its normals reversed (as an open patch's own orientation may come
    out): the library's field is then reversed near its points but not away from them (its
    far sign comes from the winding number, 0 outside), so flipping its values cannot put
    it right; the driver refits the tile with the reconciled, outward normals."""
    stats = {}
    mesh = gd.reconstruct(cloud, client, tile_points=TILE_POINTS, resolution=untiled[1], threads=1,
                          _invert_tiles=[3], stats=stats)
    assert stats["refitted_tiles"] == [3]
    assert edge_problems(mesh.faces) == (0, 0)
    assert components_and_genus(mesh.faces, len(mesh.vertices)) == \
        components_and_genus(untiled[0].faces, len(untiled[0].vertices))
    assert abs(mesh.volume / untiled[0].volume - 1) < 0.01
    diagonal = np.linalg.norm(cloud.max(0) - cloud.min(0))
    assert chamfer(mesh.vertices, untiled[0].vertices) < 2e-3 * diagonal


def test_plan_splits_on_block_boundaries(cloud):
    lo, hi = cloud.min(0), cloud.max(0)
    plan = gd.plan_tiles(cloud, len(cloud), lo, hi, tile_points=TILE_POINTS, resolution=128)
    assert len(plan.tiles) == 8
    owned = np.zeros(tuple(plan.grid.blocks[::-1]), int)
    for bl, bh in plan.tiles:
        owned[bl[2]:bh[2], bl[1]:bh[1], bl[0]:bh[0]] += 1
    assert (owned == 1).all()  # every block has exactly one owner


def test_cli_on_a_memory_mapped_ply(tmp_path, data_dir):
    """The command line, on a binary PLY the tiles memory-map (worker threads: processes
    take tens of seconds to start on a loaded machine; the bench runs processes)."""
    out = tmp_path / "bunny.ply"
    env = {"PYTHONPATH": str(BINDINGS)}
    import os
    env.update({k: v for k, v in os.environ.items() if k not in env})
    r = subprocess.run([PYTHON, "-m", "gmpu.dask", str(data_dir / "clouds" / "bunny_clean.ply"), "-o", str(out),
                        "--local-workers", "2", "--in-process", "--tile-points", "10000"], env=env, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    mesh = gmpu.read_points(out)  # the vertices, at least
    assert len(mesh) > 1000
    assert "tiles" in r.stdout


def test_every_tile_reversed_is_turned_outward(cloud, untiled, client):
    """All tiles turned over agree with each other, so only the outward pass (the band next
    to the grid's outer far region must be outside) can put them right."""
    mesh = gd.reconstruct(cloud, client, tile_points=TILE_POINTS, resolution=untiled[1], threads=1,
                          _flip_tiles=range(8))
    assert mesh.volume > 0
    assert components_and_genus(mesh.faces, len(mesh.vertices)) == \
        components_and_genus(untiled[0].faces, len(untiled[0].vertices))


def test_pieces_of_one_tile_take_their_own_flips():
    """A tile whose margin cuts a patch off its main piece may orient the two each its own
    way: piece 1 of tile 0 disagrees with tile 1 where piece 0 agrees, so only flips per
    piece reconcile them."""
    up, down = np.array([[0, 0, 1]] * 2, np.float32), np.array([[0, 0, -1]] * 2, np.float32)
    summaries = [
        {"pieces": 2, "shared": np.array([1, 2, 3, 4]), "shared_pieces": np.array([0, 0, 1, 1]),
         "normals": np.concatenate([up, down])},
        {"pieces": 1, "shared": np.array([1, 2, 3, 4]), "shared_pieces": np.zeros(4, np.int64),
         "normals": np.concatenate([up, up])},
    ]
    flip, group = gd.reconcile_signs(summaries)
    assert len(flip) == 3 and len(set(group)) == 1
    assert flip[0] == flip[2] and flip[1] == -flip[2]


def test_a_piece_split_across_tiles_is_judged_whole():
    """Two halves of one closed piece, each under the share alone, are kept together; a
    bubble is dropped."""
    outlines = [
        {"sizes": np.array([1000, 15]), "keys": np.array([7], np.uint64), "component": np.array([1])},
        {"sizes": np.array([15, 1000, 3]), "keys": np.array([7], np.uint64), "component": np.array([0])},
    ]
    small = gd.small_components(outlines, 0.01)  # share: 20.3 triangles of 2033
    assert small[0].tolist() == [False, False]
    assert small[1].tolist() == [False, False, True]


def _two_pieces():
    """Two tiles' triangles sharing the edge of lattice keys 11, 12 on their common face."""
    a = {"vertices": np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0]]), "triangles": np.array([[0, 1, 2]], np.uint32),
         "keys": np.array([10, 11, 12], np.uint64), "on_box": np.array([False, True, True]),
         "normal_sums": np.array([[0., 0, 1], [0, 0, 1], [0, 0, 1]])}
    b = {"vertices": np.array([[1., 1, 0], [1, 0, 0], [2, 0, 1]]), "triangles": np.array([[1, 0, 2]], np.uint32),
         "keys": np.array([12, 11, 13], np.uint64), "on_box": np.array([True, True, False]),
         "normal_sums": np.array([[1., 0, 0], [1, 0, 0], [1, 0, 0]])}
    return [a, b]


def test_streamed_mesh_is_welded_and_appears_whole(tmp_path):
    mesh = gd.assemble(iter(_two_pieces()), gd._MemorySink())
    assert len(mesh.vertices) == 4 and mesh.faces.tolist() == [[0, 1, 2], [1, 2, 3]]
    assert np.allclose(mesh.normals[1], [2 ** -0.5, 0, 2 ** -0.5])  # summed over both tiles
    out = tmp_path / "m.ply"
    assert gd.assemble(iter(_two_pieces()), gd.PlyStreamSink(str(out))) == {"vertices": 4, "faces": 2}
    assert np.allclose(gmpu.read_points(out).positions, mesh.vertices)
    assert np.allclose(gmpu.read_points(out).normals, mesh.normals, atol=1e-6)

    def failing():
        yield _two_pieces()[0]
        raise RuntimeError("worker lost for good")
    sink = gd.PlyStreamSink(str(tmp_path / "broken.ply"))
    with pytest.raises(RuntimeError):
        try:
            gd.assemble(failing(), sink)
        except BaseException:
            sink.abort()
            raise
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.ply"]  # no half-written file, no parts


def test_sorting_pass_memory_does_not_grow_with_the_margin(cloud):
    """The sorting pass writes each point to every tile whose box plus margin holds it, and
    holds a few copies of its chunk whatever the margin (16 cubes: two blocks each way)."""
    import tempfile
    import tracemalloc
    plan = gd.plan_tiles(cloud, len(cloud), cloud.min(0), np.nextafter(cloud.max(0), np.inf),
                         tile_points=TILE_POINTS, resolution=128, margin_cells=16)
    source = gd._Source(array=cloud)
    with tempfile.TemporaryDirectory() as directory:
        tracemalloc.start()
        written = gd._sort_chunk(source, plan, 0, directory)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        size = gd.BLOCK * plan.grid.cell
        for t, path in written:
            bl, bh = plan.tiles[t]
            lo, hi = plan.grid.origin + bl * size - plan.margin, plan.grid.origin + bh * size + plan.margin
            expected = np.flatnonzero(np.all((cloud >= lo) & (cloud < hi), axis=1))
            assert np.array_equal(np.load(path)["index"], expected)
        assert len(written) == len(plan.tiles)
    assert peak < 200 * len(cloud), peak  # bytes a point

