"""Renders the README's Blender picture headless: the add-on (installed and enabled as a user
would, from the zip) reconstructs the bunny cloud; the cloud (as small spheres, left) and the
new mesh (right) are rendered with Cycles on the CPU, which needs no GPU or display.

    blender -b --factory-startup --python bindings/blender/screenshot.py -- OUT.png

`make plugin-screenshots` runs it with throwaway Blender user directories and
GMPU_BUILD/GMPU_BLENDER_ADDON pointing at the build.
"""
import math
import os
import sys

import bpy
from mathutils import Vector

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BUILD = os.path.abspath(os.environ.get("GMPU_BUILD", os.path.join(ROOT, "build")))
ZIP = os.environ.get("GMPU_BLENDER_ADDON", os.path.join(BUILD, "plugins", "gmpu_reconstruct.zip"))
CLOUD = os.path.join(ROOT, "examples", "data", "bunny.ply")


def out_path():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    return os.path.abspath(args[0] if args else "blender.png")


def points_as_spheres(obj, radius, mat):
    """Geometry nodes: the vertices as a point cloud, which Cycles renders as spheres."""
    tree = bpy.data.node_groups.new("cloud_points", "GeometryNodeTree")
    tree.inputs.new("NodeSocketGeometry", "Geometry")
    tree.outputs.new("NodeSocketGeometry", "Geometry")
    group_in = tree.nodes.new("NodeGroupInput")
    group_out = tree.nodes.new("NodeGroupOutput")
    to_points = tree.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = radius
    tree.links.new(group_in.outputs["Geometry"], to_points.inputs["Mesh"])
    set_material = tree.nodes.new("GeometryNodeSetMaterial")
    set_material.inputs["Material"].default_value = mat
    tree.links.new(to_points.outputs["Points"], set_material.inputs["Geometry"])
    tree.links.new(set_material.outputs["Geometry"], group_out.inputs["Geometry"])
    obj.modifiers.new("points", "NODES").node_group = tree


def material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.45
    return mat


def main():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module="gmpu_reconstruct")
    bpy.context.preferences.addons["gmpu_reconstruct"].preferences.library_path = \
        os.path.join(BUILD, "lib", "libgmpu.so.1")
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)

    bpy.ops.import_mesh.ply(filepath=CLOUD)
    cloud = bpy.context.active_object
    result = bpy.ops.object.gmpu_reconstruct(resolution=128)
    if result != {'FINISHED'}:
        sys.exit(f"screenshot: the operator returned {result}")
    surface = bpy.context.active_object

    size = max(cloud.dimensions)
    centre = sum((Vector(c) for c in cloud.bound_box), Vector()) / 8
    cloud.location = (-0.55 * size, 0.0, 0.0)
    surface.location = (0.55 * size, 0.0, 0.0)
    points_as_spheres(cloud, 0.0025 * size, material("cloud", (0.15, 0.35, 0.8)))
    surface.data.materials.append(material("surface", (0.85, 0.75, 0.6)))

    # The cloud's up axis is +y: look at it from the front (+z, the camera's own axis in
    # Blender), from slightly above.
    height, distance = 0.3 * size, 3.2 * size
    bpy.ops.object.camera_add(location=centre + Vector((0.0, height, distance)))
    camera = bpy.context.active_object
    camera.rotation_euler = (-math.atan2(height, distance), 0.0, 0.0)
    camera.data.lens = 42
    bpy.context.scene.camera = camera
    bpy.ops.object.light_add(type='SUN', rotation=(math.radians(-35), math.radians(25), 0.0))
    bpy.context.active_object.data.energy = 2.0

    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = 24
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 960, 480
    scene.render.film_transparent = False
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.45, 0.47, 0.5, 1.0)
    scene.render.filepath = out_path()
    bpy.ops.render.render(write_still=True)
    print(f"screenshot: {scene.render.filepath}")


main()
