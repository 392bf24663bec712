"""Per-vertex attributes survive the trip through files: a mesh built from arrays keeps its
normals, confidence and colours when written; PLY point colours reach the reconstructed mesh
(nearest point) and its .ply and .glb files, read back by Open3D (an independent reader);
read_points takes a memory budget and a progress callable."""
import pickle

import numpy as np
import pytest

import gmpu
from test_mesh_formats import read_with_open3d


def fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    r = np.sqrt(1 - z * z)
    a = i * np.pi * (3 - np.sqrt(5))
    return np.column_stack([r * np.cos(a), r * np.sin(a), z])


def write_coloured_ply(path, xyz, rgb):
    """A binary PLY with float x y z and uchar red green blue, as scanners write them."""
    record = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("red", "u1"), ("green", "u1"), ("blue", "u1")])
    rows = np.empty(len(xyz), dtype=record)
    for k, name in enumerate("xyz"):
        rows[name] = xyz[:, k]
    for k, name in enumerate(("red", "green", "blue")):
        rows[name] = rgb[:, k]
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
              % len(xyz))
    path.write_bytes(header.encode() + rows.tobytes())


@pytest.fixture(scope="module")
def coloured_cloud(tmp_path_factory):
    """A sphere whose +x half is red and -x half blue."""
    xyz = fibonacci_sphere(3000)
    rgb = np.where(xyz[:, :1] > 0, [[255, 0, 0]], [[0, 0, 255]]).astype(np.uint8)
    path = tmp_path_factory.mktemp("colours") / "sphere.ply"
    write_coloured_ply(path, xyz, rgb)
    return path, xyz, rgb


def test_mesh_from_arrays_keeps_normals_when_written(oriented, tmp_path):
    made = oriented.polygonize(resolution=24)
    copy = gmpu.Mesh(np.array(made.vertices), np.array(made.faces), normals=np.array(made.normals),
                     confidence=np.array(made.confidence))
    ply, glb = tmp_path / "copy.ply", tmp_path / "copy.glb"
    copy.write(ply)
    copy.write(glb)
    back = gmpu.read_points(ply)
    assert back.normals is not None
    assert np.allclose(back.normals, made.normals, atol=1e-12)
    # Byte for byte what the library's own mesh writes.
    made.write(tmp_path / "made.ply")
    assert ply.read_bytes() == (tmp_path / "made.ply").read_bytes()
    g = read_with_open3d(glb)[str(glb)]
    assert np.allclose(g["vertex_normals"], made.normals, atol=1e-6)


def test_point_colours_reach_the_mesh_and_its_files(coloured_cloud, tmp_path):
    path, xyz, rgb = coloured_cloud
    cloud = gmpu.read_points(path)
    assert cloud.colors is not None and cloud.colors.dtype == np.uint8
    assert np.array_equal(cloud.colors, rgb)
    mesh = gmpu.reconstruct(path, resolution=24)  # a path: its colours are used
    assert mesh.colors is not None and mesh.colors.shape == (len(mesh.vertices), 3)
    x = mesh.vertices[:, 0]
    assert (mesh.colors[x > 0.05] == [255, 0, 0]).all()
    assert (mesh.colors[x < -0.05] == [0, 0, 255]).all()
    # Arrays without colours give a mesh without.
    assert gmpu.reconstruct(np.array(cloud.positions), resolution=24).colors is None

    ply, glb = tmp_path / "mesh.ply", tmp_path / "mesh.glb"
    mesh.write(ply)
    mesh.write(glb)
    assert np.array_equal(gmpu.read_points(ply).colors, mesh.colors)
    got = read_with_open3d(ply, glb)
    for p in (ply, glb):  # 0 and 255 are 0 and 1 in sRGB and linear alike
        assert np.allclose(got[str(p)]["vertex_colors"], mesh.colors / 255.0, atol=1e-6), p

    # Colours survive pickling, simplify and a rebuild from arrays.
    again = pickle.loads(pickle.dumps(mesh))
    assert np.array_equal(again.colors, mesh.colors)
    assert mesh.simplify(target_triangles=len(mesh.faces) // 2).colors is not None
    plain = gmpu.Mesh(np.array(mesh.vertices), np.array(mesh.faces))
    assert np.array_equal(plain.color_from(gmpu.Points(xyz, colors=rgb)).colors, mesh.colors)
    with pytest.raises(ValueError, match="uint8"):
        gmpu.Points(xyz, colors=rgb.astype(np.int64))
    with pytest.raises(ValueError, match="colors"):
        plain.color_from(gmpu.Points(xyz))


def test_read_points_progress_and_budget(coloured_cloud, tmp_path):
    path = coloured_cloud[0]
    seen = []
    cloud = gmpu.read_points(path, progress=lambda stage, f: seen.append((stage, f)))
    assert len(cloud) == 3000
    assert seen and all(stage is gmpu.Stage.READ for stage, _ in seen)
    assert seen[-1][1] == 1.0
    with pytest.raises(gmpu.CancelledError):
        gmpu.read_points(path, progress=lambda stage, f: False)

    def boom(stage, f):
        raise KeyError("from the callable")
    with pytest.raises(KeyError, match="from the callable"):
        gmpu.read_points(path, progress=boom)
    # 30,000 points need about 1.4 MB: over a 1 MB budget, refused before the body is read.
    big = tmp_path / "big.ply"
    write_coloured_ply(big, fibonacci_sphere(30000), np.zeros((30000, 3), np.uint8))
    with pytest.raises(gmpu.LimitExceededError, match="budget"):
        gmpu.read_points(big, max_memory=1e6)
    assert len(gmpu.read_points(big, max_memory=1e7)) == 30000


def test_cli_colours_its_mesh(coloured_cloud, cli, tmp_path):
    import subprocess
    path = coloured_cloud[0]
    out = tmp_path / "cli.ply"
    r = subprocess.run([str(cli), str(path), "-o", str(out), "--resolution", "24", "--quiet"], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    written = gmpu.read_points(out)
    assert written.colors is not None
    # The Python one-call path makes the same file.
    gmpu.reconstruct(path, resolution=24).write(tmp_path / "py.ply")
    assert (tmp_path / "py.ply").read_bytes() == out.read_bytes()
