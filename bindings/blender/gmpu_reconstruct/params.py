"""The reconstruction parameters as Blender properties, declared once for both the operator
(its properties: scripts, redo panel) and the sidebar panel's settings (saved in the scene).

Ranges are the C library's (include/gmpu/gmpu.h), so the UI cannot produce a value the
library refuses, except the few that only the library can judge (a resolution of 1..7):
those come back as an error report.
"""
from __future__ import annotations

from typing import Any, Dict

from bpy.props import BoolProperty, FloatProperty, IntProperty

#: Property names that are gmpu parameters of the same name (gmpu.reconstruct keywords).
GMPU_PARAMS = ("error", "max_depth", "resolution", "noise_scale", "sharp_features", "threads")
#: Every shared property, in panel order.
NAMES = GMPU_PARAMS + ("target_triangles",)


def annotations() -> Dict[str, Any]:
    """Fresh property definitions (Blender needs one set per class)."""
    return {
        "error": FloatProperty(
            name="Error", default=0.002, min=1e-6, max=0.5, soft_min=0.0002, soft_max=0.05, step=0.01,
            precision=4,
            description="How far the points may lie from each local fit, as a fraction of the bounding-box "
                        "diagonal. Smaller keeps more detail and takes longer"),
        "max_depth": IntProperty(
            name="Max Depth", default=10, min=1, max=16,
            description="Deepest octree level: caps the finest detail the fit can reach"),
        "resolution": IntProperty(
            name="Resolution", default=0, min=0, max=4096, soft_max=512,
            description="Polygonization grid cubes along the longest side (at least 8). "
                        "0: chosen from the fit's detail"),
        "noise_scale": FloatProperty(
            name="Noise Scale", default=1.75, min=0.0, max=20.0, soft_max=5.0, step=5,
            description="Noise handling: the fit never works below this many times the estimated "
                        "sampling noise, so noisy scans give smooth surfaces. 0: fit the noise too"),
        "sharp_features": BoolProperty(
            name="Sharp Features", default=False,
            description="Fit piecewise quadrics at sharp edges and corners (CAD parts)"),
        "threads": IntProperty(
            name="Threads", default=0, min=0, max=1024, soft_max=64,
            description="Worker threads. 0: every core"),
        "target_triangles": IntProperty(
            name="Target Triangles", default=0, min=0,
            description="Decimate the result to about this many triangles, keeping it closed. "
                        "0: keep every triangle. Needs a gmpu library with mesh simplification"),
    }


def gmpu_params(owner) -> Dict[str, Any]:
    """The gmpu.reconstruct keyword arguments from an object holding the properties."""
    return {name: getattr(owner, name) for name in GMPU_PARAMS}


def copy(source, target) -> None:
    for name in NAMES:
        setattr(target, name, getattr(source, name))
