"""gmpu Reconstruct: a Blender add-on that turns a point cloud (the active object's vertices)
into a closed, outward-facing mesh with the gmpu library.

Object > Reconstruct Surface (gmpu), or 3D Viewport > Sidebar > gmpu. From scripts:
bpy.ops.object.gmpu_reconstruct(error=0.002, max_depth=10, resolution=0, noise_scale=1.75,
sharp_features=False, threads=0, target_triangles=0).
"""
bl_info = {
    "name": "gmpu Reconstruct",
    "author": "gmpu authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > gmpu, and Object > Reconstruct Surface (gmpu)",
    "description": "Closed, outward-facing surface from an unoriented point cloud (MPU implicits)",
    "category": "Mesh",
}

import bpy

from . import operator, panel, preferences

_CLASSES = (preferences.GmpuPreferences, panel.GmpuSettings, operator.GMPU_OT_reconstruct,
            panel.GMPU_PT_reconstruct)


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    panel.register_settings()
    bpy.types.VIEW3D_MT_object.append(operator.menu_entry)


def unregister():
    operator.stop_running_jobs()
    bpy.types.VIEW3D_MT_object.remove(operator.menu_entry)
    panel.unregister_settings()
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)
