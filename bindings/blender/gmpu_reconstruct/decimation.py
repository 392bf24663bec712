"""Optional decimation of the reconstructed mesh (the "Target Triangles" setting).

The library's mesh simplification (gmpu_mesh_simplify) is newer than this add-on's first
version; the add-on asks the binding whether it has it rather than requiring it, so one
add-on works with libraries from before and after. This module is the one place that knows
how the binding exposes it.
"""
from __future__ import annotations

from typing import Optional, Tuple


def available(gmpu_module) -> bool:
    return callable(getattr(gmpu_module.Mesh, "simplify", None))


def apply(gmpu_module, mesh, target_triangles: int) -> Tuple[object, Optional[str]]:
    """(mesh, warning): the decimated mesh, or the mesh unchanged and why."""
    if target_triangles <= 0 or target_triangles >= len(mesh.faces):
        return mesh, None
    if not available(gmpu_module):
        return mesh, (f"Target Triangles ignored: gmpu {gmpu_module.library_version} has no mesh "
                      "simplification; the mesh keeps every triangle")
    return mesh.simplify(target_triangles=target_triangles), None
