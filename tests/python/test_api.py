"""The high-level API on real data: stages, evaluate/gradient/normals, meshes, points, params."""
import numpy as np
import pytest

import gmpu


def test_reconstruct_gives_a_closed_outward_mesh(small_cloud):
    pts, _ = small_cloud
    mesh = gmpu.reconstruct(pts, resolution=40)
    assert isinstance(mesh, gmpu.Mesh)
    v, f = mesh.vertices, mesh.faces
    assert v.dtype == np.float64 and v.shape[1] == 3 and len(v) > 1000
    assert f.dtype == np.uint32 and f.shape[1] == 3 and len(f) > 2000
    assert f.max() < len(v)
    # Closed and consistently wound: every directed edge appears once, its reverse once.
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64)
    keys = edges[:, 0] * len(v) + edges[:, 1]
    rev = edges[:, 1] * len(v) + edges[:, 0]
    assert len(np.unique(keys)) == len(keys)
    assert np.array_equal(np.sort(keys), np.sort(rev))
    # Outward: the signed volume (divergence theorem) is positive.
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6 > 0
    # Vertex normals line up with their vertices (a layout error would give ~50 % here).
    tri_n = np.cross(b - a, c - a)
    vn = mesh.normals[f[:, 0]] + mesh.normals[f[:, 1]] + mesh.normals[f[:, 2]]
    assert np.mean(np.einsum("ij,ij->i", tri_n, vn) > 0) > 0.95


def test_surface_stages_and_queries(oriented, small_cloud):
    pts, gt = small_cloud
    assert len(oriented) == oriented.point_count == len(pts)
    # Oriented normals agree with the ground truth for (nearly) every point.
    n = oriented.normals
    assert n.shape == pts.shape and n.dtype == np.float64
    assert np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-5)
    assert np.mean(np.einsum("ij,ij->i", n, gt) > 0) > 0.97
    # f ≈ 0 on the points, > 0 just inside, < 0 just outside.
    diag = oriented.stats["bbox_diagonal"]
    f0 = oriented.evaluate(pts)
    assert f0.shape == (len(pts),)
    assert np.median(np.abs(f0)) < 0.002 * diag
    inside = oriented.evaluate(pts - 0.01 * diag * gt)
    outside = oriented.evaluate(pts + 0.01 * diag * gt)
    assert np.mean(inside > 0) > 0.95 and np.mean(outside < 0) > 0.95
    # Far away: outside.
    assert oriented.evaluate(pts.mean(0) + 5 * diag) < 0


def test_evaluate_shapes_and_gradient(oriented, small_cloud):
    pts, _ = small_cloud
    q = pts[:12].reshape(3, 4, 3)
    f = oriented.evaluate(q)
    assert f.shape == (3, 4)
    assert np.array_equal(f.ravel(), oriented.evaluate(pts[:12]))
    one = oriented.evaluate(pts[0])
    assert isinstance(one, float) and one == f[0, 0]
    g = oriented.gradient(q)
    assert g.shape == (3, 4, 3)
    f2, g2 = oriented.evaluate(q, gradient=True)
    assert np.array_equal(f2, f) and np.array_equal(g2, g)
    assert oriented.evaluate(np.empty((0, 3))).shape == (0,)
    # The gradient is that of f in the caller's units: compare with central differences.
    diag = oriented.stats["bbox_diagonal"]
    h = 1e-5 * diag
    base = pts[::500]
    num = np.stack([(oriented.evaluate(base + h * e) - oriented.evaluate(base - h * e)) / (2 * h)
                    for e in np.eye(3)], axis=1)
    ana = oriented.gradient(base)
    assert np.allclose(ana, num, rtol=1e-3, atol=1e-3 * np.abs(num).max())
    # -∇f is the outward normal at the data.
    n = -ana / np.linalg.norm(ana, axis=1, keepdims=True)
    assert np.mean(np.einsum("ij,ij->i", n, oriented.normals[::500]) > 0.9) > 0.9


def test_units_follow_the_caller(small_cloud):
    # Scaling and moving the input scales f and leaves ∇f's direction; f is a distance.
    pts, _ = small_cloud
    with gmpu.Surface(pts) as a, gmpu.Surface(pts * 1000 + 5) as b:
        a.fit().orient()
        b.fit().orient()
        q = pts[::250] + 0.003
        assert np.allclose(b.evaluate(q * 1000 + 5), 1000 * a.evaluate(q), rtol=1e-6, atol=1e-9 * 1000)
        assert np.allclose(b.gradient(q * 1000 + 5), a.gradient(q), rtol=1e-6, atol=1e-9)


def test_polygonize_overrides_apply_to_one_call(oriented, small_cloud):
    before = oriented.params
    coarse = oriented.polygonize(resolution=16)
    fine = oriented.polygonize(resolution=32)
    assert oriented.params == before
    assert len(fine.faces) > 2 * len(coarse.faces)
    assert oriented.stats["resolution"] == 32
    lod = oriented.polygonize(resolution=16, level=2)
    assert oriented.params == before
    # A level-2 mesh is cruder than the full one on the same grid, but still closed,
    # consistently wound and outward, and about where the bunny is.
    for mesh in (coarse, lod):
        faces = np.asarray(mesh.faces, dtype=np.int64)
        directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
        keys = directed[:, 0] * len(mesh.vertices) + directed[:, 1]
        reverse = directed[:, 1] * len(mesh.vertices) + directed[:, 0]
        assert len(np.unique(keys)) == len(keys)  # no directed edge twice: consistent winding
        assert np.isin(reverse, keys).all()       # every edge has its twin: closed
        v = np.asarray(mesh.vertices)[faces]
        assert np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() > 0  # outward
    pts = small_cloud[0]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    slack = 0.1 * np.linalg.norm(hi - lo)
    assert (np.asarray(lod.vertices) > lo - slack).all() and (np.asarray(lod.vertices) < hi + slack).all()
    assert len(lod.vertices) != len(coarse.vertices) or not np.array_equal(lod.vertices, coarse.vertices)


def test_params_and_stats(small_cloud):
    pts, _ = small_cloud
    with gmpu.Surface(pts, error=0.004, max_depth=8, sharp_features=False, threads=1) as s:
        p = s.params
        assert set(p) == set(gmpu.PARAMS)
        assert p["error"] == 0.004 and p["max_depth"] == 8 and p["sharp_features"] is False and p["threads"] == 1
        assert isinstance(p["max_depth"], int) and isinstance(p["support_scale"], float)
        assert s.stats["cells"] == 0 and s.stats["points"] == len(pts)
        s.fit()
        st = s.stats
        assert set(st) == set(gmpu.STATS)
        assert st["cells"] > st["leaves"] > 0 and st["fit_seconds"] > 0 and st["depth"] <= 8
        assert isinstance(st["cells"], int) and isinstance(st["fit_seconds"], float)
        s.set_params(error=0.003)  # discards the fit
        assert s.stats["cells"] == 0
        with pytest.raises(gmpu.WrongOrderError):
            s.orient()


def test_mesh_from_arrays_and_write_formats(tmp_path, oriented):
    mesh = oriented.polygonize(resolution=16)
    # A mesh from polygonize is a read-only view of library memory (no copy).
    assert not mesh.vertices.flags.writeable and not mesh.faces.flags.writeable
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 1.0
    # Copies are writable and make a new mesh; int32 faces are accepted without copy.
    v = np.array(mesh.vertices)
    f32 = mesh.faces.astype(np.int32)
    m2 = gmpu.Mesh(v, f32)
    assert np.shares_memory(m2.faces, f32) and np.shares_memory(m2.vertices, v)
    assert m2.normals is None
    for ext in ("ply", "obj", "off"):
        mesh.write(tmp_path / f"a.{ext}")
        m2.write(tmp_path / f"b.{ext}")
        back = gmpu.read_points(tmp_path / f"b.{ext}")
        assert np.allclose(back.positions, v, rtol=1e-6, atol=1e-7)
    # Library meshes keep their vertex normals in the file, array-built meshes cannot.
    assert gmpu.read_points(tmp_path / "a.ply").normals is not None
    assert gmpu.read_points(tmp_path / "b.ply").normals is None
    a = gmpu.read_points(tmp_path / "a.ply")
    assert np.array_equal(a.positions, mesh.vertices) and np.allclose(a.normals, mesh.normals, atol=1e-6)


def test_mesh_validation():
    v = np.random.default_rng(0).random((4, 3))
    gmpu.Mesh(v, [[0, 1, 2], [0, 2, 3]])
    gmpu.Mesh(v, np.empty((0, 3), np.int64))
    with pytest.raises(ValueError, match="out of range"):
        gmpu.Mesh(v, [[0, 1, 4]])
    with pytest.raises(ValueError, match="out of range"):
        gmpu.Mesh(v, np.array([[0, 1, -1]], np.int32))
    with pytest.raises(ValueError, match="integer"):
        gmpu.Mesh(v, [[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError, match="m×3"):
        gmpu.Mesh(v, [0, 1, 2])
    with pytest.raises(ValueError, match="n×3"):
        gmpu.Mesh(v[:, :2], [[0, 1, 2]])


def test_mesh_write_reports_c_errors(tmp_path):
    m = gmpu.Mesh([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], [[0, 1, 2]])
    with pytest.raises(gmpu.InvalidInputError, match="vertex 2 is not finite") as e:
        m.write(tmp_path / "x.ply")
    assert e.value.status_name == "GMPU_ERROR_INVALID_INPUT" and e.value.function == "gmpu_mesh_create_with"
    ok = gmpu.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(gmpu.UnsupportedError):
        ok.write(tmp_path / "x.wrl")
    with pytest.raises(gmpu.IoError) as e:
        ok.write(tmp_path / "no" / "such" / "dir.ply")
    assert isinstance(e.value, OSError) and e.value.status_name == "GMPU_ERROR_IO"
    assert not (tmp_path / "x.ply").exists()


def test_points_read_write_roundtrip(tmp_path, clouds):
    p = gmpu.read_points(clouds / "kitten_scan_gt.ply")
    assert len(p) == 5210 and p.normals is not None
    assert not p.positions.flags.writeable  # a view of the library's copy
    assert np.asarray(p).shape == (5210, 3)
    p.write(tmp_path / "k.xyz")
    q = gmpu.read_points(tmp_path / "k.xyz")
    assert np.allclose(q.positions, p.positions, rtol=1e-6) and np.allclose(q.normals, p.normals, atol=1e-6)
    mine = gmpu.Points(np.array(p.positions, dtype=np.float32))
    mine.write(tmp_path / "m.ply")
    r = gmpu.read_points(tmp_path / "m.ply")
    assert r.normals is None and np.allclose(r.positions, p.positions, rtol=1e-6)
    assert "5210 points" in repr(p)


def test_arrays_outlive_their_owners(small_cloud, clouds):
    # Library memory stays valid while any array view of it is alive.
    pts, _ = small_cloud
    with gmpu.Surface(pts) as s:
        s.fit().orient()
        faces = s.polygonize(resolution=16).faces  # the Mesh object is gone at once
    positions = gmpu.read_points(clouds / "kitten_scan.ply").positions
    import gc
    gc.collect()
    junk = [np.ones(1000) for _ in range(1000)]  # reuse freed memory, if any was freed
    assert faces.max() < 100000 and np.isfinite(positions).all() and len(positions) == 5210
    del junk


def test_surface_accepts_points_objects_and_paths(clouds):
    path = clouds / "kitten_scan.ply"
    with gmpu.Surface(path) as a, gmpu.Surface(gmpu.read_points(path)) as b:
        assert len(a) == len(b) == 5210
        a.fit().orient()
        b.fit().orient()
        q = np.asarray(gmpu.read_points(path))[:50]
        assert np.array_equal(a.evaluate(q), b.evaluate(q))


def test_given_normals_sign_the_fits(clouds):
    gt = gmpu.read_points(clouds / "kitten_scan_gt.ply")
    with gmpu.Surface(gt.positions, normals=gt.normals) as s:
        s.fit().orient()
        assert np.mean(np.einsum("ij,ij->i", s.normals, gt.normals) > 0) > 0.97
    with gmpu.Surface(gt.positions, normals=-gt.normals) as s:  # the normals decide the sign
        s.fit().orient()
        assert np.mean(np.einsum("ij,ij->i", s.normals, gt.normals) < 0) > 0.97


def test_context_manager_and_close(small_cloud):
    pts, _ = small_cloud
    with gmpu.Surface(pts[:2000]) as s:
        assert not s.closed
    assert s.closed and "closed" in repr(s)
    s.close()  # idempotent
    for call in (s.fit, lambda: s.evaluate([0, 0, 0]), lambda: s.normals, lambda: s.params, lambda: len(s)):
        with pytest.raises(ValueError, match="closed"):
            call()


def test_stage_enum():
    assert [int(s) for s in gmpu.Stage] == [1, 2, 3, 4]
    assert str(gmpu.Stage.POLYGONIZE) == "polygonize"


def test_large_queries_are_evaluated_in_chunks_with_the_same_results(oriented, small_cloud, monkeypatch):
    import gmpu._core
    pts, _ = small_cloud
    q = pts[:1000] + 0.002
    f, g = oriented.evaluate(q, gradient=True)
    monkeypatch.setattr(gmpu._core, "_EVAL_CHUNK", 7)  # 143 C calls instead of one
    f7, g7 = oriented.evaluate(q, gradient=True)
    assert np.array_equal(f, f7) and np.array_equal(g, g7)
    assert np.array_equal(oriented.gradient(q), g)
    bad = q.copy()
    bad[500, 0] = np.inf
    with pytest.raises(gmpu.InvalidInputError, match="query point 500 "):  # the global index
        oriented.evaluate(bad)


def test_gradient_matches_finite_differences_away_from_the_data(oriented, small_cloud):
    diag = oriented.stats["bbox_diagonal"]
    dirs = np.random.default_rng(3).normal(size=(8, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    q = small_cloud[0].mean(0) + 0.6 * diag * dirs  # outside, beyond the band around the data
    assert (oriented.evaluate(q) < 0).all()
    h = 1e-6 * diag
    num = np.stack([(oriented.evaluate(q + h * e) - oriented.evaluate(q - h * e)) / (2 * h) for e in np.eye(3)], 1)
    assert np.allclose(oriented.gradient(q), num, atol=0.05)
