"""The sidebar panel (3D Viewport > Sidebar > gmpu): the parameters, kept in the scene, and
the button that runs the operator with them."""
import bpy

from . import params
from .operator import GMPU_OT_reconstruct


class GmpuSettings(bpy.types.PropertyGroup):
    __annotations__ = params.annotations()


class GMPU_PT_reconstruct(bpy.types.Panel):
    bl_label = "gmpu Reconstruct"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "gmpu"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.gmpu_settings
        obj = context.active_object
        if obj is not None and obj.type == 'MESH':
            layout.label(text=f"{obj.name}: {len(obj.data.vertices):,} points", icon='OUTLINER_DATA_POINTCLOUD')
        else:
            layout.label(text="Select a point cloud or mesh", icon='INFO')
        col = layout.column()
        for name in params.NAMES:
            col.prop(settings, name)
        op = layout.operator(GMPU_OT_reconstruct.bl_idname, text="Reconstruct", icon='MESH_ICOSPHERE')
        params.copy(settings, op)


def register_settings():
    bpy.types.Scene.gmpu_settings = bpy.props.PointerProperty(type=GmpuSettings)


def unregister_settings():
    del bpy.types.Scene.gmpu_settings
