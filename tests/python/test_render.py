"""The bench's renderer (tests/bench/render.py): every panel of a picture shows its mesh
(non-background pixels), and a missing, empty or off-frame mesh fails loudly instead of
leaving a blank panel."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "bench"))
import render  # noqa: E402

pytest.importorskip("matplotlib")

# An octahedron wound counter-clockwise seen from outside.
VERTICES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
TRIANGLES = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                      [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def colored(image):
    return (image != render.BACKGROUND).any(axis=2)


def test_every_panel_shows_its_mesh(tmp_path):
    inside_out = (VERTICES, TRIANGLES[:, ::-1])
    panels = [("ground truth", (VERTICES, TRIANGLES)), ("gmpu", (VERTICES * 0.9, TRIANGLES)),
              ("peer", inside_out), ("failed peer", None)]
    out = tmp_path / "panels.png"
    images = render.side_by_side(panels, out, "octahedron", size=96)
    assert out.stat().st_size > 0
    assert images[3] is None
    for image in images[:3]:
        assert colored(image).mean() > 0.1  # the octahedron covers a good share of the frame
    # Seen from its back, the inside-out one is mostly red.
    red = (images[2][..., 0] > images[2][..., 2]) & colored(images[2])
    assert red.sum() > 0.5 * colored(images[2]).sum()


def test_missing_mesh_fails_loudly(tmp_path):
    with pytest.raises(FileNotFoundError):
        render.read_mesh(tmp_path / "absent.ply")
    with pytest.raises(FileNotFoundError):
        render.side_by_side([("gmpu", tmp_path / "absent.ply")], tmp_path / "x.png", "t")


def test_empty_mesh_fails_loudly(tmp_path):
    pytest.importorskip("open3d")
    empty = tmp_path / "empty.off"
    empty.write_text("OFF\n0 0 0\n")
    with pytest.raises(ValueError, match="empty"):
        render.read_mesh(empty)


def test_blank_panel_fails_loudly(tmp_path):
    far = (VERTICES + 100.0, TRIANGLES)
    with pytest.raises(ValueError, match="blank"):
        render.side_by_side([("gt", (VERTICES, TRIANGLES)), ("wild", far)], tmp_path / "x.png", "t", size=64)
