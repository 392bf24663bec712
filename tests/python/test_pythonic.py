"""What Python users expect of the objects: exceptions that are the matching builtins,
picklable meshes, the facts of a mesh (watertight, volume, area, pieces, genus), Open3D."""
import errno
import multiprocessing
import os
import pickle

import numpy as np
import pytest

import gmpu
from conftest import SAMPLE, run_python


def torus(R=1.0, r=0.3, n=48, m=24, shift=(0.0, 0.0, 0.0)):
    """A closed, outward-wound torus mesh on an n×m grid (genus 1)."""
    u, v = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    x = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1)
    idx = np.arange(n * m).reshape(n, m)
    a, b = idx, np.roll(idx, -1, axis=0)
    c, d = np.roll(b, -1, axis=1), np.roll(a, -1, axis=1)
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return x.reshape(-1, 3) + np.asarray(shift), faces.astype(np.uint32)


# ---- exceptions ------------------------------------------------------------------------------

def test_missing_file_is_a_file_not_found_error(tmp_path):
    missing = tmp_path / "missing.ply"
    with pytest.raises(FileNotFoundError) as e:
        gmpu.read_points(missing)
    assert isinstance(e.value, gmpu.IoError) and isinstance(e.value, OSError)
    assert e.value.errno == errno.ENOENT and e.value.filename == str(missing)
    assert str(e.value).startswith("GMPU_ERROR_IO") and e.value.status_name == "GMPU_ERROR_IO"
    with pytest.raises(FileNotFoundError) as e:
        gmpu.Mesh(*torus()).write(tmp_path / "no" / "dir" / "m.ply")
    assert e.value.errno == errno.ENOENT and e.value.filename == str(tmp_path / "no" / "dir" / "m.ply")


def test_directory_errors_are_their_builtins(tmp_path):
    (tmp_path / "d.ply").mkdir()
    with pytest.raises(gmpu.IoError) as e:
        gmpu.read_points(tmp_path / "d.ply")
    assert e.value.filename == str(tmp_path / "d.ply")
    (tmp_path / "file").write_text("x")
    with pytest.raises(NotADirectoryError) as e:
        gmpu.read_points(tmp_path / "file" / "x.ply")
    assert e.value.errno == errno.ENOTDIR


def test_permission_denied_is_a_permission_error():
    """The tests run as root, who reads anything: the mapping itself, from the library's
    message ending in the system's reason."""
    from gmpu._errors import _io_error
    e = _io_error("GMPU_ERROR_IO: x.ply: cannot open: " + os.strerror(errno.EACCES), 7, "GMPU_ERROR_IO",
                  "gmpu_points_read", "x.ply")
    assert isinstance(e, PermissionError) and isinstance(e, gmpu.IoError)
    assert e.errno == errno.EACCES and e.filename == "x.ply" and str(e).endswith("Permission denied")
    unknown = _io_error("GMPU_ERROR_IO: x.ply: not a regular file", 7, "GMPU_ERROR_IO", "f", "x.ply")
    assert type(unknown) is gmpu.IoError and unknown.errno is None and unknown.filename == "x.ply"


def test_invalid_arguments_are_value_errors():
    with pytest.raises(ValueError):
        gmpu.Surface(np.zeros((100, 3)))
    with pytest.raises(ValueError):
        gmpu.Surface(np.random.default_rng(0).random((100, 3)).astype(np.int64))
    assert issubclass(gmpu.InvalidArgumentError, ValueError) and issubclass(gmpu.ParseError, ValueError)


# ---- pickling --------------------------------------------------------------------------------

def _triangle_count(mesh):
    return len(mesh.faces)


def test_meshes_pickle_and_come_back_from_a_process_pool(oriented):
    mesh = oriented.polygonize(resolution=24)
    back = pickle.loads(pickle.dumps(mesh))
    assert np.array_equal(back.vertices, mesh.vertices) and np.array_equal(back.faces, mesh.faces)
    assert np.array_equal(back.normals, mesh.normals)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.apply(_triangle_count, (mesh,)) == len(mesh.faces)
    v, f = torus()
    plain = pickle.loads(pickle.dumps(gmpu.Mesh(v, f)))
    assert plain.normals is None and np.array_equal(plain.faces, f)


# ---- mesh facts ------------------------------------------------------------------------------

def test_facts_of_analytic_meshes():
    v, f = torus(R=1.0, r=0.3, n=96, m=48)
    t = gmpu.Mesh(v, f)
    assert t.is_watertight and t.components == 1 and t.genus == 1
    assert t.volume == pytest.approx(2 * np.pi ** 2 * 1.0 * 0.3 ** 2, rel=0.01)
    assert t.area == pytest.approx(4 * np.pi ** 2 * 1.0 * 0.3, rel=0.01)
    v2, f2 = torus(shift=(5, 0, 0))
    v1, f1 = torus()
    two = gmpu.Mesh(np.vstack([v1, v2]), np.vstack([f1, f2 + len(v1)]))
    assert two.components == 2 and two.genus == 2
    inside_out = gmpu.Mesh(v, f[:, ::-1])
    assert inside_out.is_watertight and inside_out.volume < 0
    open_mesh = gmpu.Mesh(v, f[1:])
    assert not open_mesh.is_watertight
    with pytest.raises(ValueError, match="not closed"):
        open_mesh.genus
    flipped_one = np.array(f)
    flipped_one[0] = flipped_one[0, ::-1]  # closed but inconsistently wound
    assert not gmpu.Mesh(v, flipped_one).is_watertight


def test_facts_of_a_reconstruction():
    n = 3000
    i = np.arange(n)
    z = 1 - (2 * i + 1) / n
    r = np.sqrt(1 - z * z)
    sphere = np.stack([r * np.cos(2.399963229728653 * i), r * np.sin(2.399963229728653 * i), z], -1)
    mesh = gmpu.reconstruct(sphere, resolution=48)
    assert mesh.is_watertight and mesh.components == 1 and mesh.genus == 0
    assert mesh.volume == pytest.approx(4 / 3 * np.pi, rel=0.03)
    assert mesh.area == pytest.approx(4 * np.pi, rel=0.03)


# ---- Open3D ----------------------------------------------------------------------------------

def test_to_open3d_in_a_process_with_open3d(tmp_path):
    """Open3D is imported in a child /usr/bin/python3 (heavy, and optional for gmpu)."""
    code = ("import numpy as np, gmpu, sys\n"
            "m = gmpu.reconstruct(gmpu.read_points(sys.argv[1]), resolution=24)\n"
            "o = m.to_open3d()\n"
            "assert np.array_equal(np.asarray(o.vertices), m.vertices)\n"
            "assert np.array_equal(np.asarray(o.triangles), m.faces)\n"
            "assert np.array_equal(np.asarray(o.vertex_normals), m.normals)\n"
            "assert o.is_edge_manifold(allow_boundary_edges=False) and m.is_watertight\n"
            "print('ok')")
    r = run_python(code, [SAMPLE], timeout=300)
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr
