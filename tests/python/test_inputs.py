"""numpy input handling (dtypes, orders, strides, copies) and every error path."""
import numpy as np
import pytest

import gmpu
from gmpu._arrays import queries_for_c, xyz_for_c


# ---- layouts: what is passed through, what is copied -----------------------------------------

@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_c_order_and_row_strides_are_passed_without_copy(dtype):
    a = np.random.default_rng(1).random((100, 3)).astype(dtype)
    arr, kind, _, n, stride = xyz_for_c(a)
    assert arr is a and n == 100 and stride == 3 * a.itemsize and kind == ("f64" if dtype == np.float64 else "f32")
    every_other = a[::2]
    arr, _, _, n, stride = xyz_for_c(every_other)
    assert arr is every_other and n == 50 and stride == 6 * a.itemsize
    wide = np.random.default_rng(2).random((100, 6)).astype(dtype)  # x y z nx ny nz records
    arr, _, _, n, stride = xyz_for_c(wide[:, :3])
    assert np.shares_memory(arr, wide) and stride == 6 * a.itemsize
    normals_view = wide[:, 3:]
    arr, _, ptr, _, _ = xyz_for_c(normals_view)
    assert np.shares_memory(arr, wide)


def test_other_layouts_and_dtypes_are_copied():
    a = np.random.default_rng(1).random((100, 3))
    for bad in (np.asfortranarray(a), a[::-1], a.astype(">f8")):
        arr, _, _, _, stride = xyz_for_c(bad)
        assert not np.shares_memory(arr, bad) and arr.flags.c_contiguous and stride == 24
        assert np.array_equal(arr, a if bad.strides[0] > 0 else a[::-1])
    arr, kind, _, _, _ = xyz_for_c(a.tolist())
    assert kind == "f64" and np.array_equal(arr, a)


def test_arrays_of_other_dtypes_raise():
    """The documented dtypes only: an int64 or float16 array is refused, not converted."""
    a = np.random.default_rng(1).random((100, 3))
    for dtype in (np.int64, np.int32, np.float16, np.longdouble, np.complex128):
        with pytest.raises(ValueError, match="float32 or float64"):
            xyz_for_c((a * 100).astype(dtype))
        with pytest.raises(ValueError, match="float32 or float64"):
            gmpu.Surface((a * 100).astype(dtype))
    # Nested lists have no dtype: their numbers (ints too) are read as float64.
    arr, kind, _, _, _ = xyz_for_c((a * 100).astype(int).tolist())
    assert kind == "f64"


def test_queries_copy_only_when_needed():
    q = np.random.default_rng(3).random((4, 5, 3))
    flat, batch = queries_for_c(q)
    assert batch == (4, 5) and np.shares_memory(flat, q)
    flat, _ = queries_for_c(q.astype(np.float32))
    assert flat.dtype == np.float64
    flat, _ = queries_for_c(np.asfortranarray(q[0]))
    assert flat.flags.c_contiguous


def test_every_layout_gives_the_same_surface(small_cloud):
    pts, _ = small_cloud
    pts = pts[:3000]
    q = pts[::100] + 1e-3
    layouts = {
        "C f64": pts,
        "F f64": np.asfortranarray(pts),
        "strided f64": np.hstack([pts, np.zeros_like(pts)])[:, :3],
        "list": pts.tolist(),
    }
    results = {}
    for name, arr in layouts.items():
        with gmpu.Surface(arr) as s:
            s.fit().orient()
            results[name] = s.evaluate(q)
    for name, r in results.items():
        assert np.array_equal(r, results["C f64"]), name
    # float32 goes through gmpu_surface_set_points_f32: the same points rounded to float.
    p32 = pts.astype(np.float32)
    with gmpu.Surface(p32) as a, gmpu.Surface(np.asfortranarray(p32)) as b, \
            gmpu.Surface(p32.astype(np.float64)) as c:
        for s in (a, b, c):
            s.fit().orient()
        assert np.array_equal(a.evaluate(q), b.evaluate(q))
        assert np.array_equal(a.evaluate(q), c.evaluate(q))


# ---- shape, dtype and value errors ------------------------------------------------------

@pytest.mark.parametrize("bad, match", [
    (np.zeros((10, 2)), "n×3"),
    (np.zeros((10, 3, 1)), "n×3"),
    (np.zeros(30), "n×3"),
    (np.zeros((10, 3), np.complex128), "dtype"),
    (np.array([["a", "b", "c"]] * 20), "dtype"),
    (np.zeros((20, 3), bool), "dtype"),
    ([[1, 2, 3], [4, 5]], "array"),
    (None, "dtype"),
])
def test_shape_and_dtype_errors_are_value_errors(bad, match):
    with pytest.raises(ValueError, match=match) as e:
        gmpu.Surface(bad)
    assert not isinstance(e.value, gmpu.Error)  # raised before reaching C


def test_nan_carries_the_c_status_and_message(small_cloud):
    pts = small_cloud[0].copy()
    pts[123, 1] = np.nan
    with pytest.raises(gmpu.InvalidInputError) as e:
        gmpu.Surface(pts)
    err = e.value
    assert isinstance(err, gmpu.Error) and isinstance(err, ValueError)
    assert err.status == 2 and err.status_name == "GMPU_ERROR_INVALID_INPUT"
    assert err.function == "gmpu_surface_set_points_f64"
    assert str(err).startswith("GMPU_ERROR_INVALID_INPUT:") and "123" in str(err)
    pts32 = small_cloud[0].astype(np.float32)
    pts32[7, 0] = np.inf
    with pytest.raises(gmpu.InvalidInputError, match="7") as e:
        gmpu.Surface(pts32)
    assert e.value.function == "gmpu_surface_set_points_f32"


def test_too_few_and_degenerate_points():
    with pytest.raises(gmpu.InvalidInputError, match="GMPU_ERROR_INVALID_INPUT"):
        gmpu.Surface(np.random.default_rng(0).random((5, 3)))
    with pytest.raises(gmpu.InvalidInputError):
        gmpu.Surface(np.empty((0, 3)))
    plane = np.random.default_rng(0).random((200, 3))
    plane[:, 2] = 1.0
    with pytest.raises(gmpu.DegenerateInputError) as e:
        gmpu.Surface(plane)
    assert e.value.status_name == "GMPU_ERROR_DEGENERATE_INPUT"


def test_normals_errors(small_cloud):
    pts, gt = small_cloud
    with pytest.raises(gmpu.InvalidInputError, match="normals given for"):
        gmpu.Surface(pts, normals=gt[:-1])
    bad = gt.copy()
    bad[9] = 0
    with pytest.raises(gmpu.InvalidInputError, match="normal 9 is zero"):
        gmpu.Surface(pts, normals=bad)
    with pytest.raises(ValueError, match="n×3"):
        gmpu.Surface(pts, normals=gt[:, :2])


def test_parameter_errors(small_cloud):
    pts, _ = small_cloud
    with pytest.raises(TypeError, match="unknown gmpu parameter 'eror'"):
        gmpu.Surface(pts, eror=0.1)
    with pytest.raises(gmpu.InvalidArgumentError, match="GMPU_PARAM_ERROR") as e:
        gmpu.Surface(pts, error=2.0)
    assert isinstance(e.value, ValueError) and e.value.status_name == "GMPU_ERROR_INVALID_ARGUMENT"
    with pytest.raises(gmpu.InvalidArgumentError, match="GMPU_PARAM_MAX_DEPTH"):
        gmpu.Surface(pts, max_depth=2.5)
    with pytest.raises(gmpu.InvalidArgumentError):
        gmpu.Surface(pts, resolution=float("nan"))
    with pytest.raises(gmpu.InvalidArgumentError, match="RESOLUTION"):
        gmpu.reconstruct(pts, resolution=4)
    with pytest.raises(TypeError, match="number"):
        gmpu.Surface(pts, error="fine")


def test_wrong_order_and_query_errors(small_cloud, oriented):
    pts, _ = small_cloud
    with gmpu.Surface(pts) as s:
        with pytest.raises(gmpu.WrongOrderError, match="gmpu_surface_orient needs gmpu_surface_fit") as e:
            s.orient()
        assert isinstance(e.value, RuntimeError)
        with pytest.raises(gmpu.WrongOrderError):
            s.evaluate(pts[:3])
        with pytest.raises(gmpu.WrongOrderError):
            s.polygonize()
        with pytest.raises(gmpu.WrongOrderError):
            s.normals
    q = pts[:10].copy()
    q[4, 2] = np.nan
    with pytest.raises(gmpu.InvalidInputError, match="query point 4"):
        oriented.evaluate(q)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        oriented.evaluate(pts[:, :2])
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        oriented.evaluate(1.0)


def test_limits(small_cloud):
    pts, _ = small_cloud
    with gmpu.Surface(pts, max_cells=10) as s:
        with pytest.raises(gmpu.LimitExceededError, match="GMPU_ERROR_LIMIT_EXCEEDED"):
            s.fit()
    with gmpu.Surface(pts, max_triangles=100) as s:
        s.fit().orient()
        with pytest.raises(gmpu.LimitExceededError):
            s.polygonize(resolution=32)
        s.set_params(max_triangles=10**8)
        assert len(s.polygonize(resolution=16).faces) > 100


def test_memory_budget(small_cloud):
    pts, _ = small_cloud
    import os
    half = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2
    with gmpu.Surface(pts) as s:
        assert s.params["max_memory"] == half
        s.set_params(max_memory=10**6)
        with pytest.raises(gmpu.LimitExceededError, match="GMPU_PARAM_MAX_MEMORY = 1e[+]06 bytes"):
            s.fit()
        s.set_params(max_memory=half)
        s.fit().orient()
        s.set_params(max_memory=10**8)
        with pytest.raises(gmpu.LimitExceededError, match="resolution 4096 needs about"):
            s.polygonize(resolution=4096)
        s.set_params(max_memory=half)
        assert len(s.polygonize(resolution=16).faces) > 100


def test_outliers_are_set_aside_and_counted(small_cloud):
    pts, _ = small_cloud
    far = np.vstack([pts, pts.mean(axis=0) + 1000 * np.ptp(pts, axis=0), pts.mean(axis=0) - 1000 * np.ptp(pts, axis=0)])
    with gmpu.Surface(pts) as clean, gmpu.Surface(far) as s:
        assert clean.stats["outliers"] == 0
        mesh_clean = clean.fit().orient().polygonize(resolution=32)
        mesh = s.fit().orient().polygonize(resolution=32)
        assert s.stats["outliers"] == 2 and s.stats["points"] == len(far)
        assert np.array_equal(mesh.vertices, mesh_clean.vertices)
        assert s.normals.shape == (len(far), 3)


def test_file_errors(tmp_path):
    with pytest.raises(gmpu.IoError, match="GMPU_ERROR_IO") as e:
        gmpu.read_points(tmp_path / "missing.ply")
    assert isinstance(e.value, OSError)
    (tmp_path / "bad.ply").write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n")
    with pytest.raises(gmpu.ParseError, match="GMPU_ERROR_PARSE"):
        gmpu.read_points(tmp_path / "bad.ply")
    (tmp_path / "p.las").write_bytes(b"\0" * 10)
    with pytest.raises(gmpu.UnsupportedError):
        gmpu.read_points(tmp_path / "p.las")
    with pytest.raises(gmpu.IoError):
        gmpu.reconstruct(tmp_path / "missing.xyz")
    assert not list(tmp_path.glob("*.tmp*"))


def test_set_params_is_all_or_nothing(oriented):
    before = oriented.params
    cells = oriented.stats["cells"]
    with pytest.raises(gmpu.InvalidArgumentError, match="GMPU_PARAM_MAX_DEPTH"):
        oriented.set_params(error=0.01, max_depth=99)
    assert oriented.params == before and oriented.stats["cells"] == cells  # the fit was kept


def test_normals_at_are_rows_of_normals(oriented, small_cloud):
    n = len(small_cloud[0])
    idx = np.array([n - 1, 0, 17, 17, n // 2], np.int64)
    assert np.array_equal(oriented.normals_at(idx), oriented.normals[idx])
    assert np.array_equal(oriented.normals_at(idx.astype(np.uint32)), oriented.normals[idx])
    assert oriented.normals_at([]).shape == (0, 3)
    with pytest.raises(gmpu.InvalidArgumentError, match=rf"indices\[1\] = {n} is not a point"):
        oriented.normals_at([3, n])
    with pytest.raises(gmpu.InvalidArgumentError, match=r"indices\[0\] = -1"):
        oriented.normals_at([-1])
    with pytest.raises(TypeError, match="integers"):
        oriented.normals_at([0.5])
