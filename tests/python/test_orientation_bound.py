"""tests/bench/orientation_bound.py: the orientation ceiling on a noisy cloud, checked on a slab
whose answer is known in closed form (two sheets t apart, noise σ: Φ(t / 2σ)), and on a
thick part, where nothing is lost."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import open3d as o3d
from scipy.stats import norm

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tests" / "bench" / "orientation_bound.py"


def write_cloud(path, points, normals):
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    cloud.normals = o3d.utility.Vector3dVector(normals)
    assert o3d.io.write_point_cloud(str(path), cloud)


def slab(rng, n, gap):
    """n samples on the two faces z = ±gap/2 of a wide slab, outward normals."""
    side = rng.integers(0, 2, n) * 2 - 1
    points = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), side * gap / 2])
    normals = np.column_stack([np.zeros(n), np.zeros(n), side.astype(float)])
    return points, normals


def make_set(folder, model, gap, sigmas, seed=3):
    rng = np.random.default_rng(seed)
    clean, clean_normals = slab(rng, 40000, gap)
    write_cloud(folder / f"{model}_clean_gt.ply", clean, clean_normals)
    for variant, sigma in sigmas.items():
        points, normals = slab(rng, 20000, gap)
        write_cloud(folder / f"{model}_{variant}_gt.ply", points + rng.normal(0, sigma, points.shape), normals)
        (folder / f"{model}_{variant}_meta.json").write_text(json.dumps({"noise": sigma, "noise_sigma_abs": sigma}))


def ceilings(folder, model):
    out = subprocess.run([sys.executable, str(TOOL), str(folder), model], check=True, capture_output=True,
                         text=True).stdout.strip().splitlines()
    return {line.split("\t")[1]: float(line.split("\t")[3]) for line in out[1:]}


def test_a_slab_thinner_than_the_noise_loses_what_crosses_its_middle(tmp_path):
    gap = 0.02
    make_set(tmp_path, "slab", gap, {"noise0.5": 0.01, "noise1.0": 0.02})
    got = ceilings(tmp_path, "slab")
    # The sheets' edges read no opposite side (the slab's rim): a little above the formula.
    assert abs(got["noise0.5"] - norm.cdf(gap / (2 * 0.01))) < 0.01
    assert abs(got["noise1.0"] - norm.cdf(gap / (2 * 0.02))) < 0.01


def test_a_part_much_thicker_than_the_noise_loses_nothing(tmp_path):
    make_set(tmp_path, "block", 1.0, {"noise0.5": 0.01, "noise1.0": 0.02})
    got = ceilings(tmp_path, "block")
    assert got["noise0.5"] > 0.9999 and got["noise1.0"] > 0.9999
