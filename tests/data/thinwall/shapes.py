#!/usr/bin/python3
"""Closed thin-walled meshes (OFF) for checking sparse thin-walled reconstruction on shapes
the development corpus does not have. Usage: shapes.py OUTDIR

Walls are 0.012-0.035 thick in boxes of about 1: one to two sample spacings at 1,000-5,000
points, so local fits see two sheets in one support.
  first set (looked at while choosing the guide's floor, How it works 3 in README.md):
    hollow_box        box 1 x 0.8 x 0.6, wall 0.015
    hollow_ellipsoid  ellipsoid shell, semi-axes 0.5 0.3 0.2, wall 0.015 (scaled, so uneven)
    pipe_thick        capped pipe, outer radius 0.25, wall 0.03, height 0.7
    pipe_long         capped pipe, outer radius 0.15, wall 0.012, height 1
    ring              capped pipe, outer radius 0.4, wall 0.02, height 0.3
    plate_square      plate 0.8 x 0.8 x 0.015
    plate_thick       plate 1 x 0.4 x 0.035
  second set (measured once, after the floor was chosen):
    hollow_torus      torus shell, major radius 0.4, tube radius 0.15, wall 0.015
    lampshade         conical band revolved about z, radius 0.3 to 0.45, wall 0.02
    flanged_ring      ring wall r 0.35-0.37 with a flange out to 0.5 at the top, 0.02 thick
    washer            flat annulus r 0.2-0.5, 0.02 thick
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import thin_shells as ts  # noqa: E402


def shell(outer, inner):
    """The solid between two closed surfaces: the inner one wound inward."""
    (v1, f1), (v2, f2) = outer, inner
    return np.vstack([v1, v2]), np.vstack([f1, f2[:, ::-1] + len(v1)])


def torus(major, minor, nu=128, nv=48, inward=False):
    """A torus about z: its tube's circle revolved (lathe); inward: wound the other way."""
    v, f = lathe([(major + minor * np.cos(b), minor * np.sin(b)) for b in 2 * np.pi * np.arange(nv) / nv], nu)
    return v, f[:, ::-1] if inward else f


def refine(profile, step=0.01):
    """The closed polygon with its edges cut into pieces of at most `step`."""
    out = []
    for k in range(len(profile)):
        a, b = np.array(profile[k]), np.array(profile[(k + 1) % len(profile)])
        m = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        out += [tuple(a + (b - a) * t / m) for t in range(m)]
    return out


def lathe(profile, nu=128):
    """The closed (r, z) polygon, clear of the axis, revolved about z; wound outward."""
    p = np.array(profile)
    n = len(p)
    v = np.array([(r * np.cos(a), r * np.sin(a), z) for a in 2 * np.pi * np.arange(nu) / nu for r, z in p])
    idx = lambda i, k: (i % nu) * n + (k % n)
    f = []
    for i in range(nu):
        for k in range(n):
            a, b, c, d = idx(i, k), idx(i + 1, k), idx(i, k + 1), idx(i + 1, k + 1)
            f += [(a, b, d), (a, d, c)]
    f = np.array(f)
    volume = np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6
    return v, f[:, ::-1] if volume < 0 else f


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    w = lambda name, mesh: ts.write_off(os.path.join(out, name + ".off"), *mesh)
    w("hollow_box", shell(ts.box(1.0, 0.8, 0.6), ts.box(0.97, 0.77, 0.57)))
    sphere = ts.uv_sphere(1.0)
    w("hollow_ellipsoid", shell((sphere[0] * np.array([0.5, 0.3, 0.2]), sphere[1]),
                                (sphere[0] * np.array([0.485, 0.285, 0.185]), sphere[1])))
    w("pipe_thick", ts.pipe(0.25, 0.03, 0.7))
    w("pipe_long", ts.pipe(0.15, 0.012, 1.0))
    w("ring", ts.pipe(0.4, 0.02, 0.3))
    w("plate_square", ts.box(0.8, 0.8, 0.015))
    w("plate_thick", ts.box(1.0, 0.4, 0.035))
    outer, inner = torus(0.4, 0.15), torus(0.4, 0.135, inward=True)
    w("hollow_torus", (np.vstack([outer[0], inner[0]]), np.vstack([outer[1], inner[1] + len(outer[0])])))
    w("lampshade", lathe(refine([(0.3, -0.2), (0.45, 0.2), (0.43, 0.2), (0.28, -0.2)])))
    w("flanged_ring", lathe(refine([(0.35, -0.2), (0.37, -0.2), (0.37, 0.18), (0.5, 0.18), (0.5, 0.2), (0.35, 0.2)])))
    w("washer", lathe(refine([(0.2, -0.01), (0.5, -0.01), (0.5, 0.01), (0.2, 0.01)])))


if __name__ == "__main__":
    main()
