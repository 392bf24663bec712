#!/usr/bin/python3
"""The best orientation any method can reach on a noisy cloud, estimated from the truth.

Where a part is thinner than the noise, a noisy sample can land past the part's middle, and
from positions alone it is then indistinguishable from a sample of the opposite side: no
method orients it right. With Gaussian noise σ along the normal and local thickness t (from
a sample, along its inward normal, to the opposite side), a sample stays on its own side of
the middle with probability Φ(t / 2σ); the mean over the cloud estimates the ceiling.

Thickness comes from the same mesh's clean cloud (NAME_clean_gt.ply: exact positions and
normals): for each sample, among its K nearest, the opposite-facing sample behind it that lies
most nearly along the inward normal (within 45°), its depth along the normal; none: thick. Each
noisy sample takes the thickness of its nearest clean sample. An estimate: on a tube the
chosen sample is a little off the diameter (a slightly thinner reading), and a part thicker
than K samples reach reads thick; on the corpus it lands within about ±0.4 % of what gmpu and
the peers reach where they come close.

Usage: orientation_bound.py CLOUD_DIR MODEL...   (clouds as tests/data/corpus/make.sh writes
them: MODEL_clean_gt.ply, MODEL_noise0.5_gt.ply, MODEL_noise1.0_gt.ply with their _meta.json)
"""
import json
import sys
from pathlib import Path

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree
from scipy.stats import norm

K = 200  # neighbours searched for the opposite side
OPPOSED = -0.3  # normals this opposed (cosine) face the other way
STEEPEST = 1.0  # lateral offset allowed, as a share of the depth along the normal (45°)


def load(path):
    cloud = o3d.io.read_point_cloud(str(path))
    return np.asarray(cloud.points), np.asarray(cloud.normals)


def thickness(points, normals):
    tree = cKDTree(points)
    dist, idx = tree.query(points, k=min(K, len(points)))
    t = np.full(len(points), np.inf)
    slope = np.full(len(points), STEEPEST)  # lateral / depth of the sample chosen so far
    for j in range(1, idx.shape[1]):
        q = idx[:, j]
        opposed = (normals * normals[q]).sum(1) < OPPOSED
        depth = -((points[q] - points) * normals).sum(1)
        lateral = np.sqrt(np.maximum(dist[:, j] ** 2 - depth ** 2, 0.0))
        steeper = opposed & (depth > 0) & (lateral < slope * depth)
        t[steeper] = depth[steeper]
        slope[steeper] = lateral[steeper] / depth[steeper]
    return tree, t


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip().splitlines()[-3], file=sys.stderr)
        return 2
    clouds = Path(argv[1])
    print("model\tvariant\tnoise_sigma_share\tceiling\tthinner_than_2sigma")
    for model in argv[2:]:
        clean, clean_normals = load(clouds / f"{model}_clean_gt.ply")
        tree, t = thickness(clean, clean_normals)
        for variant in ("noise0.5", "noise1.0"):
            meta = json.loads((clouds / f"{model}_{variant}_meta.json").read_text())
            sigma = meta["noise_sigma_abs"]
            noisy, _ = load(clouds / f"{model}_{variant}_gt.ply")
            _, nearest = tree.query(noisy)
            tn = t[nearest]
            ceiling = norm.cdf(tn / (2 * sigma)).mean()
            print(f"{model}\t{variant}\t{meta['noise']}\t{ceiling:.4f}\t{np.mean(tn < 2 * sigma):.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
