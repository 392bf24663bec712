"""gmpu Reconstruct: a ParaView (5.11) Python plugin whose filter turns a point dataset into a
closed, outward-facing surface (vtkPolyData with point normals) with the gmpu library.

GUI: Tools > Manage Plugins > Load New... (this file), then Filters > gmpu Reconstruct.
pvpython:

    from paraview.simple import *
    LoadPlugin("build/plugins/gmpu_paraview.py", ns=globals())
    surface = gmpuReconstruct(Input=PLYReader(FileNames=["cloud.ply"]), Error=0.002)

The filter uses the gmpu Python binding (cffi + numpy, in Debian's ParaView Python): an
installed or $PYTHONPATH gmpu first, else the copy `make plugins` puts beside this file, else
the source tree's bindings/python. The library comes from $GMPU_LIBRARY, or as the binding
finds it (see gmpu._library). Progress goes to ParaView's progress bar; aborting the filter
(vtkAlgorithm::SetAbortExecute) cancels gmpu within the library's 100 ms, leaving the output
empty. Failures are ParaView error messages with the library's text, never a crash.
"""
import inspect
import os
import sys

if not hasattr(inspect, "getargspec"):
    # Debian 12's ParaView 5.11.0 imports inspect.getargspec, which Python 3.11 removed, in the
    # module behind every Python plugin; its decorators only read .args, which
    # getfullargspec's result has too. Set before that module is first imported (see load()).
    inspect.getargspec = inspect.getfullargspec

import numpy as np
from paraview.util.vtkAlgorithm import VTKPythonAlgorithmBase, smdomain, smhint, smproperty, smproxy
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPointSet, vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkDemandDrivenPipeline

paraview_plugin_name = "gmpu Reconstruct"
paraview_plugin_version = "0.1.0"



def _this_file():
    """This file's path. `paraview --script=` runs the source without a file name, so then it
    is looked for on the Python path (README: PYTHONPATH=build/plugins)."""
    try:
        return os.path.abspath(__file__)
    except NameError:
        for directory in sys.path:
            candidate = os.path.join(directory or ".", "gmpu_paraview.py")
            if os.path.isfile(candidate):
                return os.path.abspath(candidate)
        return ""


_HERE = os.path.dirname(_this_file())
# The long stages in pipeline order, each a third of the progress bar.
_STAGES = ("fit", "orient", "polygonize")


def _import_gmpu():
    """The gmpu module, or (None, why) when it cannot be imported."""
    try:
        import gmpu
        return gmpu, ""
    except ModuleNotFoundError as e:
        if e.name != "gmpu":
            return None, str(e)
    except ImportError as e:  # found, but its library was not
        return None, str(e)
    for candidate in (_HERE, os.path.join(_HERE, "..", "python")):
        if os.path.isfile(os.path.join(candidate, "gmpu", "__init__.py")):
            sys.path.insert(0, os.path.abspath(candidate))
            try:
                import gmpu
                return gmpu, ""
            except ImportError as e:
                return None, str(e)
    return None, ("the gmpu Python package was found neither on the Python path nor beside this plugin "
                  "(build it with `make plugins`, or set PYTHONPATH to bindings/python)")


class _Aborted(Exception):
    """Raised in the progress callback when ParaView asks to abort: the binding turns it into
    the library's cancel and re-raises it once the C call has returned."""


@smproxy.filter(name="gmpuReconstruct", label="gmpu Reconstruct")
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkPointSet"], composite_data_supported=False)
class GmpuReconstruct(VTKPythonAlgorithmBase):
    """Points in (any vtkPointSet: a PLY cloud, a mesh's vertices), closed surface out."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkPolyData")
        self._params = {"error": 0.002, "max_depth": 10, "resolution": 0, "noise_scale": 1.75,
                        "sharp_features": False, "threads": 0}
        self._target_triangles = 0
        #: The latest run's warning ("" if none), e.g. a decimation the library cannot do.
        self.last_warning = ""
        #: The latest failure's message ("" after a success or a cancel), for scripts.
        self.last_error = ""
        #: Whether the latest run was aborted.
        self.last_cancelled = False

    def FillInputPortInformation(self, port, info):
        info.Set(self.INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet")
        return 1

    def _set(self, name, value):
        if self._params[name] != value:
            self._params[name] = value
            self.Modified()

    # Properties appear in the panel in reverse order of declaration.
    @smproperty.intvector(name="TargetTriangles", label="Target Triangles", default_values=0)
    @smdomain.intrange(min=0, max=10000000)
    @smhint.xml('<Documentation>Decimate the surface to about this many triangles, keeping it closed '
                '(0: keep every triangle). Needs a gmpu library with mesh simplification.</Documentation>')
    def SetTargetTriangles(self, value):
        if self._target_triangles != int(value):
            self._target_triangles = int(value)
            self.Modified()

    @smproperty.intvector(name="Threads", default_values=0)
    @smdomain.intrange(min=0, max=64)
    @smhint.xml('<Documentation>Worker threads; 0 uses every core.</Documentation>')
    def SetThreads(self, value):
        self._set("threads", int(value))

    @smproperty.intvector(name="SharpFeatures", label="Sharp Features", default_values=0)
    @smdomain.xml('<BooleanDomain name="bool"/>')
    def SetSharpFeatures(self, value):
        self._set("sharp_features", bool(value))

    @smproperty.doublevector(name="NoiseScale", label="Noise Scale", default_values=1.75)
    @smdomain.doublerange(min=0.0, max=20.0)
    @smhint.xml('<Documentation>Noise handling: the fit never works below this many times the estimated '
                'sampling noise. 0 fits the noise too.</Documentation>')
    def SetNoiseScale(self, value):
        self._set("noise_scale", float(value))

    @smproperty.intvector(name="Resolution", default_values=0)
    @smdomain.intrange(min=0, max=1024)
    @smhint.xml('<Documentation>Polygonization grid cubes along the longest side (at least 8); '
                '0 chooses from the fit.</Documentation>')
    def SetResolution(self, value):
        self._set("resolution", int(value))

    @smproperty.intvector(name="MaxDepth", label="Max Depth", default_values=10)
    @smdomain.intrange(min=1, max=16)
    def SetMaxDepth(self, value):
        self._set("max_depth", int(value))

    @smproperty.doublevector(name="Error", default_values=0.002)
    @smdomain.doublerange(min=0.0001, max=0.05)
    @smhint.xml('<Documentation>How far points may lie from each local fit, as a fraction of the '
                'bounding-box diagonal. Smaller keeps more detail and takes longer.</Documentation>')
    def SetError(self, value):
        self._set("error", float(value))

    # -- execution -------------------------------------------------------------------------

    def _progress(self, stage, fraction):
        if self.GetAbortExecute():
            raise _Aborted()
        name = str(stage)
        index = _STAGES.index(name) if name in _STAGES else 0
        self.UpdateProgress((index + min(max(fraction, 0.0), 1.0)) / len(_STAGES))

    def _fail(self, message):
        self.last_error = message
        vtkOutputWindow.GetInstance().DisplayErrorText(f"gmpu Reconstruct: {message}\n")
        return 0

    def _decimated(self, gmpu, mesh):
        """The mesh decimated to the target when asked and the binding can (Mesh.simplify,
        which keeps the mesh closed and may stop above the target); else the mesh, with a
        warning when asked."""
        target = self._target_triangles
        if target <= 0 or target >= len(mesh.faces):
            return mesh
        if not callable(getattr(gmpu.Mesh, "simplify", None)):
            self.last_warning = (f"Target Triangles ignored: gmpu {gmpu.library_version} has no mesh "
                                 "simplification; the surface keeps every triangle")
            vtkOutputWindow.GetInstance().DisplayWarningText(f"gmpu Reconstruct: {self.last_warning}\n")
            return mesh
        return mesh.simplify(target_triangles=target)

    def RequestData(self, request, inInfo, outInfo):
        self.last_error, self.last_warning, self.last_cancelled = "", "", False
        source = vtkPointSet.GetData(inInfo[0])
        output = vtkPolyData.GetData(outInfo)
        output.Initialize()
        gmpu, why = _import_gmpu()
        if gmpu is None:
            return self._fail(f"cannot load gmpu: {why}")
        if source is None or source.GetPoints() is None or source.GetNumberOfPoints() == 0:
            return self._fail("the input has no points")
        points = numpy_support.vtk_to_numpy(source.GetPoints().GetData())
        try:
            mesh = self._decimated(gmpu, gmpu.reconstruct(points, progress=self._progress, **self._params))
        except (_Aborted, gmpu.CancelledError):
            self.last_cancelled = True
            # VTK leaves the abort flag set, which would cancel every later run at its first
            # progress call; and an aborted output is not current: marked not generated, the
            # next update runs again.
            self.SetAbortExecute(0)
            outInfo.GetInformationObject(0).Set(vtkDemandDrivenPipeline.DATA_NOT_GENERATED(), 1)
            return 1
        except gmpu.Error as e:
            return self._fail(str(e))
        except (ValueError, TypeError) as e:  # e.g. points that are not 3-D
            return self._fail(str(e))
        _fill(output, mesh)
        return 1


def _fill(output, mesh):
    """The gmpu.Mesh as triangles with point normals (double precision: the library's)."""
    points = vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(mesh.vertices), deep=1))
    count = len(mesh.faces)
    id_type = numpy_support.ID_TYPE_CODE
    offsets = np.arange(0, 3 * count + 1, 3, dtype=id_type)
    connectivity = np.ascontiguousarray(mesh.faces, dtype=id_type).ravel()
    cells = vtkCellArray()
    cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=1),
                  numpy_support.numpy_to_vtkIdTypeArray(connectivity, deep=1))
    output.SetPoints(points)
    output.SetPolys(cells)
    if mesh.normals is not None:
        normals = numpy_support.numpy_to_vtk(np.ascontiguousarray(mesh.normals), deep=1)
        normals.SetName("Normals")
        output.GetPointData().SetNormals(normals)


def load(namespace=None):
    """Registers this file as a ParaView plugin (paraview.simple.LoadPlugin), having first
    made ParaView's Python plugin support importable (the getargspec fix above): on Debian 12
    a bare LoadPlugin of any Python plugin fails. namespace: where the filter's function
    gmpuReconstruct goes (e.g. globals())."""
    from paraview.simple import LoadPlugin

    path = _this_file()
    if not path:
        raise RuntimeError("gmpu_paraview.py is not on the Python path: set PYTHONPATH to its directory")
    LoadPlugin(path, remote=False, ns=namespace)


if __name__ == "__main__":  # paraview --script=gmpu_paraview.py: load it into the GUI
    print(f"gmpu Reconstruct: loading {_this_file()}")
    load()
