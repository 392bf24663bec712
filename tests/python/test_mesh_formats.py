"""Binary STL and glTF binary (.glb) written by the library, read back by an independent
reader: Open3D, in its own /usr/bin/python3 process (python3-open3d, which `make test`
installs; the test fails, not skips, without it)."""
import json
import subprocess

import numpy as np
import pytest

import gmpu
from conftest import PYTHON

READ_WITH_OPEN3D = r"""
import json, sys
import numpy as np
import open3d as o3d
out = {}
for path in sys.argv[1:]:
    m = o3d.io.read_triangle_mesh(path)
    out[path] = {
        "vertices": np.asarray(m.vertices).tolist(),
        "triangles": np.asarray(m.triangles).tolist(),
        "vertex_normals": np.asarray(m.vertex_normals).tolist(),
        "vertex_colors": np.asarray(m.vertex_colors).tolist(),
    }
print(json.dumps(out))
"""


def read_with_open3d(*paths):
    r = subprocess.run([PYTHON, "-c", READ_WITH_OPEN3D, *map(str, paths)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    return {p: {k: np.array(v) for k, v in d.items()} for p, d in json.loads(r.stdout.splitlines()[-1]).items()}


@pytest.fixture(scope="module")
def mesh(oriented):
    return oriented.polygonize(resolution=32)


def test_stl_and_glb_read_back_by_open3d(mesh, tmp_path):
    stl, glb = tmp_path / "mesh.stl", tmp_path / "mesh.GLB"  # the extension is case-insensitive
    mesh.write(stl)
    mesh.write(glb)
    got = read_with_open3d(stl, glb)
    v32 = mesh.vertices.astype(np.float32).astype(np.float64)

    # STL: three corners per triangle, in our order (so our winding).
    s = got[str(stl)]
    corners = s["vertices"][s["triangles"]]
    assert corners.shape == (len(mesh.faces), 3, 3)
    assert np.array_equal(corners, v32[mesh.faces])

    # GLB: the shared vertices, the triangles as they are and the outward vertex normals.
    g = got[str(glb)]
    assert np.array_equal(g["vertices"], v32)
    assert np.array_equal(g["triangles"], mesh.faces)
    assert np.allclose(g["vertex_normals"], mesh.normals, atol=1e-6)


def test_glb_layout(mesh, tmp_path):
    """The container itself: header, 4-byte aligned chunks, accessor bounds and counts."""
    path = tmp_path / "mesh.glb"
    mesh.write(path)
    data = path.read_bytes()
    magic, version, length = np.frombuffer(data[:12], "<u4")
    assert data[:4] == b"glTF" and version == 2 and length == len(data)
    json_length = int(np.frombuffer(data[12:16], "<u4")[0])
    assert data[16:20] == b"JSON" and json_length % 4 == 0
    doc = json.loads(data[20:20 + json_length])
    bin_at = 20 + json_length
    assert data[bin_at + 4:bin_at + 8] == b"BIN\0"
    assert int(np.frombuffer(data[bin_at:bin_at + 4], "<u4")[0]) == doc["buffers"][0]["byteLength"]
    position = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    v32 = mesh.vertices.astype(np.float32)
    assert position["count"] == len(mesh.vertices)
    assert np.array_equal(np.float32(position["min"]), v32.min(axis=0))
    assert np.array_equal(np.float32(position["max"]), v32.max(axis=0))


def test_stl_layout_and_face_normals(mesh, tmp_path):
    """Open3D recomputes the normals it reads from STL: these are checked from the bytes."""
    path = tmp_path / "mesh.stl"
    mesh.write(path)
    data = path.read_bytes()
    assert not data.startswith(b"solid")  # readers would take it for ASCII STL
    assert len(data) == 84 + 50 * len(mesh.faces)
    assert int(np.frombuffer(data[80:84], "<u4")[0]) == len(mesh.faces)
    records = np.frombuffer(data[84:], np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attr", "<u2")]))
    a, b, c = (mesh.vertices[mesh.faces[:, k]] for k in range(3))
    outward = np.cross(b - a, c - a)
    outward /= np.linalg.norm(outward, axis=1, keepdims=True)
    assert np.allclose(records["normal"], outward, atol=1e-5)
    assert np.array_equal(records["corners"], mesh.vertices[mesh.faces].astype(np.float32))
    assert not records["attr"].any()


def test_mesh_without_normals_and_empty_mesh(tmp_path):
    tri = gmpu.Mesh([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], np.array([[0, 1, 2]], np.uint32))
    tri.write(tmp_path / "tri.glb")
    got = read_with_open3d(tmp_path / "tri.glb")[str(tmp_path / "tri.glb")]
    assert np.array_equal(got["triangles"], [[0, 1, 2]])
    empty = gmpu.Mesh(np.zeros((0, 3)), np.zeros((0, 3), np.uint32))
    for name in ("empty.glb", "empty.stl"):
        empty.write(tmp_path / name)
    glb = (tmp_path / "empty.glb").read_bytes()
    assert glb[:4] == b"glTF" and json.loads(glb[20:])["scenes"] == [{"nodes": []}]
    assert (tmp_path / "empty.stl").stat().st_size == 84


def test_cli_writes_them_too(cli, tmp_path, small_cloud):
    cloud = tmp_path / "cloud.xyz"
    np.savetxt(cloud, small_cloud[0][::4])
    for name in ("out.stl", "out.glb"):
        r = subprocess.run([str(cli), str(cloud), "-o", str(tmp_path / name), "--quiet", "--resolution", "24"],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
    assert (tmp_path / "out.glb").read_bytes()[:4] == b"glTF"
    assert (tmp_path / "out.stl").stat().st_size > 84
