#!/usr/bin/env python3
"""Orientation on the outer surface only, for corpus meshes that intersect themselves.

Some corpus meshes (cow, man, camel) are closed but self-intersecting: a leg runs into the
body, and the part of its surface inside the body is sampled like the rest. The true normal
of such a point faces into solid material, which no closed outward surface can give it, so
the strict orientation score counts it against every method. This script splits the points:
a point is *embedded* when the true mesh's generalized winding number just in front of its
true surface point (along the true normal) is over ½, i.e. in front of it lies the inside
of another part. It prints the strict orientation, the embedded share, and the orientation
over the other points.

    /usr/bin/python3 tests/bench/outer_orientation.py MESH.off CLOUD_gt.ply NORMALS.ply ...

(arguments in threes: the true mesh, the cloud's ground-truth normals as make.sh writes
them, and gmpu's oriented normals at the same points, e.g. the CLI's --normals-out).
Brute force: points × triangles solid angles, a minute or so for 35k points on a 35k mesh.
"""
import sys

import numpy as np

# In front of the true surface point by this share of the diagonal: well under any wall's
# thickness in the corpus, well over the float error of the closest point.
FRONT_OFFSET = 0.0005


def winding_numbers(vertices, triangles, queries, chunk=32):
    """Generalized winding number of the triangle mesh at each query (van Oosterom–Strackee)."""
    a0, b0, c0 = (vertices[triangles[:, k]] for k in range(3))
    out = np.empty(len(queries))
    for s in range(0, len(queries), chunk):
        x = queries[s:s + chunk, None, :]
        a, b, c = a0[None] - x, b0[None] - x, c0[None] - x
        la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
        det = (a * np.cross(b, c)).sum(2)
        den = la * lb * lc + (a * b).sum(2) * lc + (b * c).sum(2) * la + (c * a).sum(2) * lb
        out[s:s + chunk] = (2.0 * np.arctan2(det, den)).sum(1) / (4.0 * np.pi)
    return out


def score(mesh_path, truth_path, normals_path):
    import open3d as o3d  # here, so that winding_numbers needs numpy alone

    mesh = o3d.io.read_triangle_mesh(mesh_path)
    vertices, triangles = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    truth = o3d.io.read_point_cloud(truth_path)
    points, true_normals = np.asarray(truth.points), np.asarray(truth.normals)
    normals = np.asarray(o3d.io.read_point_cloud(normals_path).normals)
    if len(normals) != len(points):
        raise SystemExit(f"{normals_path}: {len(normals)} normals for {len(points)} points")
    diag = np.linalg.norm(vertices.max(0) - vertices.min(0))
    # Noisy points are first taken to the true surface: the question is about the surface.
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    on_surface = scene.compute_closest_points(o3d.core.Tensor(points.astype(np.float32)))["points"].numpy()
    embedded = winding_numbers(vertices, triangles,
                               on_surface.astype(float) + FRONT_OFFSET * diag * true_normals) > 0.5
    right = (normals * true_normals).sum(1) > 0
    outer = right[~embedded].mean() if (~embedded).any() else float("nan")
    return right.mean(), embedded.mean(), outer, int((~right & embedded).sum()), int((~right).sum())


def main(args):
    if not args or len(args) % 3:
        raise SystemExit(__doc__)
    print("| cloud | orientation (strict) | embedded points | orientation on the outer surface | wrong normals on embedded points |")
    print("|---|---:|---:|---:|---:|")
    for i in range(0, len(args), 3):
        strict, share, outer, wrong_embedded, wrong = score(*args[i:i + 3])
        name = args[i + 1].rsplit("/", 1)[-1].removesuffix("_gt.ply")
        print(f"| {name} | {100 * strict:.2f}% | {100 * share:.2f}% | {100 * outer:.2f}% | {wrong_embedded} of {wrong} |",
              flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
