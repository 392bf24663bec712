"""tests/bench/outer_orientation.py: the winding number it sets embedded points apart with,
and the split itself on two boxes that run into each other."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "bench"))
import outer_orientation  # noqa: E402

TETRA_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TETRA_T = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])  # outward


def test_winding_number_is_one_inside_zero_outside():
    w = outer_orientation.winding_numbers(TETRA_V, TETRA_T, np.array([[0.1, 0.1, 0.1], [2.0, 2.0, 2.0], [-0.5, 0.2, 0.2]]))
    assert w == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)
    # Inward triangles turn the sign: the formula follows the winding, not just the solid angle.
    w = outer_orientation.winding_numbers(TETRA_V, TETRA_T[:, ::-1], np.array([[0.1, 0.1, 0.1]]))
    assert w == pytest.approx([-1.0], abs=1e-9)


def test_points_inside_the_other_box_are_embedded(tmp_path):
    o3d = pytest.importorskip("open3d")
    a = o3d.geometry.TriangleMesh.create_box(2.0, 2.0, 2.0)
    b = o3d.geometry.TriangleMesh.create_box(2.0, 2.0, 2.0)
    b.translate((1.0, 0.0, 0.0))  # half of b lies inside a, and half of a inside b
    mesh = a + b
    o3d.io.write_triangle_mesh(str(tmp_path / "boxes.off"), mesh)
    # Points on a's face x = 2 (inside b for 0 < y, z < 2) and on a's face x = 0 (outside b).
    rng = np.random.default_rng(1)
    inner = np.column_stack([np.full(50, 2.0), rng.uniform(0.2, 1.8, (50, 2))])
    outer = np.column_stack([np.zeros(50), rng.uniform(0.2, 1.8, (50, 2))])
    points = np.vstack([inner, outer])
    truth = np.vstack([np.tile([1.0, 0, 0], (50, 1)), np.tile([-1.0, 0, 0], (50, 1))])
    given = truth.copy()
    given[:50] *= -1  # wrong on every embedded point, right elsewhere
    for name, normals in (("truth_gt.ply", truth), ("given.ply", given)):
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        cloud.normals = o3d.utility.Vector3dVector(normals)
        o3d.io.write_point_cloud(str(tmp_path / name), cloud)
    strict, share, outer_share, wrong_embedded, wrong = outer_orientation.score(
        str(tmp_path / "boxes.off"), str(tmp_path / "truth_gt.ply"), str(tmp_path / "given.ply"))
    assert strict == pytest.approx(0.5)
    assert share == pytest.approx(0.5)
    assert outer_share == pytest.approx(1.0)
    assert (wrong_embedded, wrong) == (50, 50)
