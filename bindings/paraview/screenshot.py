"""Renders the README's ParaView picture headless with pvpython: the bunny cloud (points,
left) and "gmpu Reconstruct"'s surface coloured by its normals' z (right), saved with
SaveScreenshot from an offscreen render view.

    pvpython --force-offscreen-rendering bindings/paraview/screenshot.py OUT.png

`make plugin-screenshots` runs it on the plugin in build/plugins, with GMPU_LIBRARY set.
"""
import os
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BUILD = os.path.abspath(os.environ.get("GMPU_BUILD", os.path.join(ROOT, "build")))
PLUGIN_DIR = os.path.join(BUILD, "plugins")
CLOUD = os.path.join(ROOT, "examples", "data", "bunny.ply")

sys.path.insert(0, PLUGIN_DIR)
import gmpu_paraview  # noqa: E402  (the plugin file; load() registers it)

gmpu_paraview.load(globals())
from paraview.simple import (ColorBy, CreateView, GetColorTransferFunction, PLYReader, SaveScreenshot,  # noqa: E402
                             Show, Transform)


def main(out):
    cloud = PLYReader(FileNames=[CLOUD])
    surface = gmpuReconstruct(Input=cloud, Resolution=128)  # noqa: F821 (added by load())
    shifted = Transform(Input=surface)
    shifted.Transform.Translate = [1.1, 0.0, 0.0]

    view = CreateView("RenderView")
    view.ViewSize = [960, 480]
    view.OrientationAxesVisibility = 0
    view.Background = [0.32, 0.34, 0.43]
    view.UseColorPaletteForBackground = 0

    points = Show(cloud, view)
    # A PLY cloud has no vertex cells, which the Points representation needs; Point Gaussian
    # draws every point.
    points.SetRepresentationType("Point Gaussian")
    points.ShaderPreset = "Sphere"
    points.GaussianRadius = 0.003
    points.AmbientColor = [0.55, 0.75, 1.0]
    points.DiffuseColor = [0.55, 0.75, 1.0]
    points.ColorArrayName = ["POINTS", ""]

    mesh = Show(shifted, view)
    mesh.SetRepresentationType("Surface")
    ColorBy(mesh, ("POINTS", "Normals", "Z"))
    mesh.RescaleTransferFunctionToDataRange(True, False)
    GetColorTransferFunction("Normals").ApplyPreset("Cool to Warm", True)

    view.CameraPosition = [0.55, 0.3, 3.4]
    view.CameraFocalPoint = [0.55, 0.0, 0.0]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelProjection = 0
    view.ResetCamera(False)
    view.CameraPosition = [0.55, 0.3, 2.7]
    SaveScreenshot(out, view, ImageResolution=[960, 480])
    print(f"screenshot: {out}")


main(os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "paraview.png"))
