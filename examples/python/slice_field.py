#!/usr/bin/env python3
# %% [markdown]
# # The signed field on a slice
#
# gmpu reconstructs an *implicit* surface: a function f that is positive inside the solid,
# negative outside, and about the signed distance near the surface. This notebook-style
# script (cells marked `# %%` run in Jupyter/VS Code, or run it whole) evaluates f on a
# plane through the middle of a point cloud and saves a picture of it with its zero level
# set, which is the surface that `polygonize` turns into a mesh.
#
#     PYTHONPATH=bindings/python /usr/bin/python3 examples/python/slice_field.py \
#         [IN.ply] [OUT.png] [--axis x|y|z] [--offset F] [--size N]

# %%
import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import TwoSlopeNorm  # noqa: E402

try:
    import gmpu
except ModuleNotFoundError:  # a source checkout without PYTHONPATH
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bindings" / "python"))
    import gmpu

HERE = Path(__file__).resolve().parent
ap = argparse.ArgumentParser(description="Picture of gmpu's signed field on a slice through a point cloud.")
ap.add_argument("input", nargs="?", default=str(HERE.parent / "data" / "bunny.ply"))
ap.add_argument("output", nargs="?", default="slice_field.png")
ap.add_argument("--axis", choices="xyz", default="z", help="the slice is normal to this axis")
ap.add_argument("--offset", type=float, default=0.5, help="where along the axis, 0..1 of the bounding box")
ap.add_argument("--size", type=int, default=320, help="grid samples along the longer side")
args = ap.parse_args()

# %% [markdown]
# ## Reconstruct
# Fit the local quadrics and orient them; no mesh is needed to evaluate f.

# %%
cloud = gmpu.read_points(args.input)
surface = gmpu.Surface(cloud).fit().orient()
lo, hi = cloud.positions.min(0), cloud.positions.max(0)
diag = surface.stats["bbox_diagonal"]
print(f"{len(cloud)} points, {surface.stats['leaves']} local fits, {surface.stats['components']} component(s)")

# %% [markdown]
# ## Evaluate f on a grid over the slice
# `evaluate` takes any (..., 3) array of query points and returns an array of shape (...).

# %%
k = "xyz".index(args.axis)
u, v = [d for d in range(3) if d != k]  # the two in-plane axes
margin = 0.08 * diag
extent_u = (lo[u] - margin, hi[u] + margin)
extent_v = (lo[v] - margin, hi[v] + margin)
span = max(extent_u[1] - extent_u[0], extent_v[1] - extent_v[0])
nu = max(2, round(args.size * (extent_u[1] - extent_u[0]) / span))
nv = max(2, round(args.size * (extent_v[1] - extent_v[0]) / span))
gu, gv = np.meshgrid(np.linspace(*extent_u, nu), np.linspace(*extent_v, nv))
plane = lo[k] + args.offset * (hi[k] - lo[k])
grid = np.empty(gu.shape + (3,))
grid[..., u], grid[..., v], grid[..., k] = gu, gv, plane
f = surface.evaluate(grid)  # shape (nv, nu)
print(f"f on the slice: {f.min():.4g} .. {f.max():.4g} ({(f > 0).mean():.0%} of the slice inside)")

# %% [markdown]
# ## Picture: the signed field, its zero level set, and the input points near the plane

# %%
near = np.abs(cloud.positions[:, k] - plane) < 0.004 * diag
clip = 0.05 * diag  # saturate far from the surface, so the band around it is readable
fig, ax = plt.subplots(figsize=(7, 7 * nv / nu + 0.6), dpi=110)
img = ax.imshow(np.clip(f, -clip, clip), origin="lower", extent=(*extent_u, *extent_v), cmap="RdBu_r",
                norm=TwoSlopeNorm(vmin=-clip, vcenter=0.0, vmax=clip), interpolation="bilinear")
ax.contour(gu, gv, f, levels=[0.0], colors="black", linewidths=1.4)
ax.plot(cloud.positions[near, u], cloud.positions[near, v], ".", ms=1.5, color="gold", label="input points near the plane")
ax.set_xlabel("xyz"[u])
ax.set_ylabel("xyz"[v])
ax.set_title(f"{Path(args.input).name}: f on {args.axis} = {plane:.3g}  (black: f = 0, the surface)")
ax.legend(loc="upper right", fontsize=8, markerscale=6)
bar = fig.colorbar(img, ax=ax, shrink=0.85)
bar.set_label("f  (red: inside, f > 0;  blue: outside, f < 0)")
fig.tight_layout()
fig.savefig(args.output, bbox_inches="tight")
surface.close()
print(f"wrote {args.output}")
