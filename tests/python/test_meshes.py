"""Mesh operations through the Python binding: decimation keeps a closed, manifold mesh of
the same topology within its triangle target; confidence marks unsupported surface and
trim opens the caps over a scan's holes; the CLI's --trim and --target-triangles."""
import subprocess

import numpy as np
import pytest

import gmpu


def sphere(n, seed, keep=lambda p: np.ones(len(p), bool)):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    return p[keep(p)]


def edge_uses(faces):
    """Undirected edge -> number of triangles using it, and the Euler characteristic."""
    f = faces.astype(np.int64)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e[:, 0] * (f.max() + 1) + e[:, 1], return_counts=True)
    chi = len(np.unique(f)) - len(counts) + len(f)
    return counts, chi


def test_simplify_keeps_a_closed_sphere():
    mesh = gmpu.reconstruct(sphere(3000, 1))
    target = len(mesh.faces) // 10
    small = mesh.simplify(target_triangles=target, target_error=0.02)
    assert isinstance(small, gmpu.Mesh)
    assert 0 < len(small.faces) <= target
    counts, chi = edge_uses(small.faces)
    assert np.all(counts == 2) and chi == 2
    assert np.allclose(np.linalg.norm(small.normals, axis=1), 1)
    assert small.confidence is not None and small.confidence.shape == (len(small.vertices),)
    # Every vertex of the simplified mesh is one of the original's (collapses pick endpoints).
    r = np.linalg.norm(small.vertices, axis=1)
    assert np.all(np.abs(r - 1) < 0.05)


def test_simplify_a_mesh_built_from_arrays():
    mesh = gmpu.reconstruct(sphere(2000, 2))
    rebuilt = gmpu.Mesh(np.array(mesh.vertices), np.array(mesh.faces))
    small = rebuilt.simplify(100)
    assert len(small.faces) <= 100
    assert small.confidence is None
    with pytest.raises(gmpu.InvalidArgumentError):
        rebuilt.simplify(100, target_error=-1)
    with pytest.raises(ValueError):
        rebuilt.simplify(-5)
    with pytest.raises(gmpu.InvalidArgumentError, match="confidence"):
        rebuilt.trim(3.0)


def test_trim_opens_the_hole_of_a_capped_sphere():
    pts = sphere(6000, 3, keep=lambda p: p[:, 2] < 0.6)
    mesh = gmpu.reconstruct(pts)
    counts, _ = edge_uses(mesh.faces)
    assert np.all(counts == 2)  # watertight by default
    # The implicit closes the hole by folding inward: no point is near that inner sheet.
    c, r = mesh.confidence, np.linalg.norm(mesh.vertices, axis=1)
    inner = r < 0.8
    scanned = (np.abs(r - 1) < 0.03) & (mesh.vertices[:, 2] < 0.5)
    assert inner.any() and c[inner].min() > 3 and c[scanned].max() < 2.5
    trimmed = mesh.trim(3.0)
    counts, chi = edge_uses(trimmed.faces)
    assert (counts == 1).sum() > 20 and np.all(counts <= 2)
    assert chi == 1  # a disc: one boundary loop
    assert trimmed.vertices[:, 2].max() < 0.85
    assert np.all(np.abs(np.linalg.norm(trimmed.vertices, axis=1) - 1) < 0.1)


def test_cli_trims_and_decimates(cli, tmp_path):
    pts = sphere(6000, 4, keep=lambda p: p[:, 2] < 0.6)
    cloud = tmp_path / "capped.xyz"
    np.savetxt(cloud, pts)
    full, small = tmp_path / "full.ply", tmp_path / "small.ply"
    subprocess.run([str(cli), str(cloud), "-o", str(full), "--quiet"], check=True)
    subprocess.run([str(cli), str(cloud), "-o", str(small), "--quiet", "--trim", "--target-triangles", "500"],
                   check=True)
    header = small.read_bytes().split(b"end_header")[0].decode()
    assert "property float confidence" in header
    faces = int(header.split("element face ")[1].split()[0])
    assert 0 < faces <= 500
    full_faces = int(full.read_bytes().split(b"element face ")[1].split()[0])
    assert full_faces > 10 * faces
    bad = subprocess.run([str(cli), str(cloud), "-o", str(small), "--target-triangles", "0"], capture_output=True,
                         text=True)
    assert bad.returncode == 2 and "--target-triangles" in bad.stderr
    bad = subprocess.run([str(cli), str(cloud), "-o", str(small), "--target-error", "2"], capture_output=True,
                         text=True)
    assert bad.returncode == 1 and "target_error" in bad.stderr
