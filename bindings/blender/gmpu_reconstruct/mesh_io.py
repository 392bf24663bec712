"""Between Blender meshes and numpy arrays, in bulk (foreach_get/foreach_set: no Python loop
over vertices, so a million-point cloud takes a fraction of a second)."""
from __future__ import annotations

import bpy
import numpy as np


def object_points(obj) -> np.ndarray:
    """The object's vertex positions (n×3 float32, object space): what a PLY point cloud
    import makes, or any mesh's vertices. float32 is Blender's own precision; gmpu takes it
    without a copy."""
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def new_mesh_object(context, name: str, vertices: np.ndarray, faces: np.ndarray, matrix_world):
    """Links a new object holding the triangle mesh into the active collection, with the
    source's transform (so it sits on the cloud), and makes it the only selected, active one."""
    nv, nt = len(vertices), len(faces)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(nv)
    mesh.vertices.foreach_set("co", np.ascontiguousarray(vertices, dtype=np.float32).ravel())
    mesh.loops.add(3 * nt)
    mesh.loops.foreach_set("vertex_index", np.ascontiguousarray(faces, dtype=np.int32).ravel())
    mesh.polygons.add(nt)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * nt, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(nt, 3, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(nt, dtype=bool))
    mesh.update(calc_edges=True)
    obj = bpy.data.objects.new(name, mesh)
    obj.matrix_world = matrix_world
    context.collection.objects.link(obj)
    for other in context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return obj
