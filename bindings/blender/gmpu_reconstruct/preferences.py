"""Add-on preferences: where libgmpu is (the zip carries the Python binding, not the library)."""
import bpy
from bpy.props import StringProperty

from . import binding


class GmpuPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    library_path: StringProperty(
        name="Library Path", subtype='FILE_PATH', default="",
        description="libgmpu.so.1, or the directory holding it. Empty: $GMPU_LIBRARY, then the system's "
                    "library search path. Read at the first reconstruction of a Blender session")

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "library_path")
        path, version = binding.describe()
        if path:
            layout.label(text=f"Loaded: {path} (gmpu {version})", icon='CHECKMARK')
        else:
            layout.label(text="Loaded at the first reconstruction", icon='INFO')


def get(context) -> GmpuPreferences:
    return context.preferences.addons[__package__].preferences
