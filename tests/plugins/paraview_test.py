"""Headless test of the ParaView plugin, run with pvpython:

    pvpython --force-offscreen-rendering tests/plugins/paraview_test.py

It loads the plugin file `make plugins` copies into build/plugins, reads a shared cloud with
ParaView's PLYReader, applies "gmpu Reconstruct" with two parameter sets and checks each
output is closed, carries normals, and equals the C CLI's mesh for the same input and
parameters; then that an abort (vtkAlgorithm::SetAbortExecute from a progress observer, as
ParaView's GUI does) cancels the run and leaves the output empty, the next update running
again in full; and that a parameter the library refuses is an error message, not a crash.
Exit status 0 when every check passes, 1 otherwise.
"""
import os
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plugin_checks as pc  # noqa: E402

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import PLYReader  # noqa: E402
from vtkmodules.util import numpy_support  # noqa: E402

PLUGIN = os.environ.get("GMPU_PARAVIEW_PLUGIN", os.path.join(pc.build_dir(), "plugins", "gmpu_paraview.py"))
TOLERANCE = 1e-9  # ParaView keeps the library's doubles
PROPERTIES = {"error": "Error", "max_depth": "MaxDepth", "resolution": "Resolution", "noise_scale": "NoiseScale",
              "sharp_features": "SharpFeatures", "threads": "Threads"}

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def configure(proxy, params):
    for name, prop in PROPERTIES.items():
        value = params[name]
        setattr(proxy, prop, int(value) if isinstance(value, bool) else value)


def output_arrays(proxy):
    data = servermanager.Fetch(proxy)
    n = data.GetNumberOfPoints()
    vertices = numpy_support.vtk_to_numpy(data.GetPoints().GetData()) if n else np.empty((0, 3))
    polys = data.GetPolys()
    offsets = numpy_support.vtk_to_numpy(polys.GetOffsetsArray())
    connectivity = numpy_support.vtk_to_numpy(polys.GetConnectivityArray())
    if len(offsets) > 1 and not (np.diff(offsets) == 3).all():
        return vertices, None, None
    normals = data.GetPointData().GetNormals()
    normals = numpy_support.vtk_to_numpy(normals) if normals is not None else None
    return vertices, connectivity.reshape(-1, 3), normals


def check_equal_to_cli(filt, params, what):
    vertices, faces, normals = output_arrays(filt)
    check(faces is not None, f"{what}: every cell is a triangle")
    if faces is None:
        return
    problem = pc.closed_problem(faces)
    check(not problem, f"{what}: closed (every edge shared by two triangles) {problem}")
    check(normals is not None and normals.shape == vertices.shape
          and np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-6), f"{what}: unit point normals")
    ref_v, ref_f = pc.cli_mesh(pc.CLOUD, params)
    diff = pc.difference(vertices, faces, ref_v, ref_f, TOLERANCE)
    check(not diff, f"{what}: equal to the CLI's mesh ({len(ref_v)} vertices, {len(ref_f)} triangles) {diff}")


def load_plugin(namespace):
    """As the README says: import the plugin file as a module, then its load()."""
    sys.path.insert(0, os.path.dirname(PLUGIN))
    module = __import__(os.path.splitext(os.path.basename(PLUGIN))[0])
    module.load(namespace)


def main():
    namespace = globals()
    load_plugin(namespace)
    check("gmpuReconstruct" in namespace, f"plugin {PLUGIN} loaded: filter gmpuReconstruct")
    reader = PLYReader(FileNames=[pc.CLOUD])
    reader.UpdatePipeline()
    check(servermanager.Fetch(reader).GetNumberOfPoints() == 5000, f"PLYReader: 5000 points ({pc.CLOUD})")
    filt = namespace["gmpuReconstruct"](Input=reader)
    algorithm = filt.GetClientSideObject()

    for i, params in enumerate(pc.RUNS, 1):
        configure(filt, params)
        filt.UpdatePipeline()
        check(not algorithm.last_error, f"run {i} {params}: no error {algorithm.last_error}")
        check_equal_to_cli(filt, params, f"run {i}")

    # Abort after a few progress events, as the GUI's abort does.
    calls = []

    def abort_soon(caller, event):
        calls.append(1)
        if len(calls) == 3:
            caller.SetAbortExecute(1)

    tag = algorithm.AddObserver("ProgressEvent", abort_soon)
    configure(filt, pc.RUNS[0])
    filt.UpdatePipeline()
    algorithm.RemoveObserver(tag)
    check(algorithm.last_cancelled and not algorithm.last_error, "abort: the run is cancelled, with no error")
    check(servermanager.Fetch(filt).GetNumberOfPoints() == 0, "abort: the output is empty")
    check(not algorithm.GetAbortExecute(), "abort: the filter clears VTK's abort flag for the next run")
    # The next run (new parameters, as a user would set after aborting) is complete.
    configure(filt, pc.RUNS[1])
    filt.UpdatePipeline()
    check(not algorithm.last_cancelled, "after an abort, the next update runs in full")
    check_equal_to_cli(filt, pc.RUNS[1], "after an abort")

    # Target Triangles: decimated when the library can, else the full mesh and a warning.
    configure(filt, pc.RUNS[0])
    filt.TargetTriangles = 4000
    filt.UpdatePipeline()
    full = len(pc.cli_mesh(pc.CLOUD, pc.RUNS[0])[1])
    _, faces, normals = output_arrays(filt)
    if algorithm.last_warning:
        check("Target Triangles ignored" in algorithm.last_warning and faces is not None and len(faces) == full,
              f"Target Triangles without mesh simplification: the full mesh and a warning ({algorithm.last_warning})")
    else:
        check(faces is not None and 0 < len(faces) < full and not pc.closed_problem(faces) and normals is not None,
              f"Target Triangles 4000: a closed surface with fewer triangles than the full {full}, with normals")
    filt.TargetTriangles = 0

    configure(filt, dict(pc.RUNS[0], resolution=3))
    print("(expected: an error message and VTK's \"returned failure\" below)", flush=True)
    filt.UpdatePipeline()
    check("resolution" in algorithm.last_error.lower(),
          f"a parameter the library refuses is an error message: {algorithm.last_error!r}")
    check(servermanager.Fetch(filt).GetNumberOfPoints() == 0, "... and the output is empty")


def test_plain_vtk():
    """The filter class in a plain VTK pipeline (no proxy): after an abort, Update() with the
    same parameters runs again in full (the aborted output is marked not generated)."""
    import gmpu_paraview
    from vtkmodules.vtkIOPLY import vtkPLYReader

    reader = vtkPLYReader()
    reader.SetFileName(pc.CLOUD)
    algorithm = gmpu_paraview.GmpuReconstruct()
    algorithm.SetInputConnection(reader.GetOutputPort())
    params = pc.RUNS[0]
    algorithm.SetError(params["error"])
    algorithm.SetMaxDepth(params["max_depth"])
    algorithm.SetResolution(params["resolution"])
    algorithm.SetNoiseScale(params["noise_scale"])
    algorithm.SetThreads(params["threads"])
    calls = []

    def abort_once(caller, event):
        calls.append(1)
        if len(calls) == 3:
            caller.SetAbortExecute(1)

    tag = algorithm.AddObserver("ProgressEvent", abort_once)
    algorithm.Update()
    algorithm.RemoveObserver(tag)
    check(algorithm.last_cancelled and algorithm.GetOutputDataObject(0).GetNumberOfPoints() == 0,
          "plain VTK: an abort leaves the output empty")
    algorithm.Update()
    out = algorithm.GetOutputDataObject(0)
    check(not algorithm.last_cancelled and out.GetNumberOfPoints() > 0,
          "plain VTK: the next Update() with the same parameters runs in full")


try:
    main()
    test_plain_vtk()
except Exception:
    traceback.print_exc()
    failures.append("unexpected exception")
print(f"paraview_test: {len(failures)} failure(s)" if failures else "paraview_test: all checks passed", flush=True)
sys.exit(1 if failures else 0)
