"""Headless test of the Blender add-on, run inside Blender:

    BLENDER_USER_SCRIPTS=$(mktemp -d) BLENDER_USER_CONFIG=$(mktemp -d) \
        blender -b --factory-startup --python tests/plugins/blender_test.py

(`make test-plugins` does this, with throwaway user directories, so the add-on is never
installed into the user's own Blender.) It installs and enables the add-on from the zip
`make plugins` builds, points its preference at build/lib, imports a shared cloud with
Blender's PLY importer, runs the operator twice with different parameters and checks each new
mesh is closed and equal to the C CLI's for the same input and parameters; then that a
cancelled run, a failed run and bad input leave the scene as it was and come back as
reports, never as a crash. Exit status 0 when every check passes, 1 otherwise.
"""
import os
import shutil
import subprocess
import sys
import traceback

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plugin_checks as pc  # noqa: E402

ADDON = "gmpu_reconstruct"
ZIP = os.environ.get("GMPU_BLENDER_ADDON", os.path.join(pc.build_dir(), "plugins", ADDON + ".zip"))
# Blender keeps vertices in float32: 2^-24 of a coordinate, well under 1e-6 of the diagonal.
TOLERANCE = 1e-6

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def scene_state():
    """Everything a run may change: objects, meshes, the active and selected objects."""
    ctx = bpy.context
    return (sorted(bpy.data.objects.keys()), sorted(bpy.data.meshes.keys()),
            ctx.view_layer.objects.active.name if ctx.view_layer.objects.active else None,
            sorted(o.name for o in ctx.selected_objects))


def mesh_arrays(obj):
    import numpy as np

    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    sizes = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    if len(sizes) and not (sizes == 3).all():
        return co.reshape(-1, 3), None
    return co.reshape(-1, 3), loops.reshape(-1, 3)


def activate(obj):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def run_operator(**kwargs):
    """The operator's result set, or the RuntimeError text its ERROR report becomes."""
    try:
        return bpy.ops.object.gmpu_reconstruct(**kwargs), ""
    except RuntimeError as e:
        return None, str(e)


def test_install():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module=ADDON)
    check(ADDON in bpy.context.preferences.addons, f"add-on installed and enabled from {ZIP}")
    check(hasattr(bpy.types, "OBJECT_OT_gmpu_reconstruct") or "gmpu_reconstruct" in dir(bpy.ops.object),
          "operator bpy.ops.object.gmpu_reconstruct registered")
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.library_path = pc.library_path()


def import_cloud():
    bpy.ops.import_mesh.ply(filepath=pc.CLOUD)
    cloud = bpy.context.active_object
    check(cloud is not None and len(cloud.data.vertices) == 5000 and len(cloud.data.polygons) == 0,
          f"PLY import: a 5000-point cloud ({pc.CLOUD})")
    return cloud


def test_runs(cloud):
    for i, params in enumerate(pc.RUNS, 1):
        activate(cloud)
        before = set(bpy.data.objects.keys())
        result, error = run_operator(**params)
        check(result == {'FINISHED'}, f"run {i} {params}: FINISHED {error}")
        added = [bpy.data.objects[n] for n in set(bpy.data.objects.keys()) - before]
        check(len(added) == 1 and added[0].type == 'MESH', f"run {i}: one new mesh object")
        if len(added) != 1:
            continue
        obj = added[0]
        check(bpy.context.view_layer.objects.active == obj, f"run {i}: the new object {obj.name} is active")
        check(obj.matrix_world == cloud.matrix_world, f"run {i}: it has the cloud's transform")
        vertices, faces = mesh_arrays(obj)
        check(faces is not None, f"run {i}: every face is a triangle")
        if faces is None:
            continue
        problem = pc.closed_problem(faces)
        check(not problem, f"run {i}: closed (every edge shared by two triangles) {problem}")
        ref_v, ref_f = pc.cli_mesh(pc.CLOUD, params)
        diff = pc.difference(vertices, faces, ref_v, ref_f, TOLERANCE)
        check(not diff, f"run {i}: equal to the CLI's mesh ({len(ref_v)} vertices, {len(ref_f)} triangles) {diff}")


def test_decimation(cloud):
    """Target Triangles: decimated (closed, fewer triangles) when the binding has mesh
    simplification; otherwise a warning and the full mesh."""
    activate(cloud)
    before = set(bpy.data.objects.keys())
    target = 4000
    result, error = run_operator(**pc.RUNS[0], target_triangles=target)
    check(result == {'FINISHED'}, f"Target Triangles {target}: FINISHED {error}")
    added = [bpy.data.objects[n] for n in set(bpy.data.objects.keys()) - before]
    if len(added) != 1:
        check(False, "Target Triangles: one new object")
        return
    vertices, faces = mesh_arrays(added[0])
    gmpu = sys.modules.get(ADDON + ".gmpu")
    from gmpu_reconstruct import decimation

    if decimation.available(gmpu):
        # The library keeps topology, which may stop it above the target: fewer than the
        # full mesh's triangles, still closed.
        full = len(pc.cli_mesh(pc.CLOUD, pc.RUNS[0])[1])
        check(faces is not None and len(faces) < full and not pc.closed_problem(faces),
              f"Target Triangles {target}: a closed mesh with fewer triangles than the full {full}")
    else:
        ref_v, ref_f = pc.cli_mesh(pc.CLOUD, pc.RUNS[0])
        check(faces is not None and not pc.difference(vertices, faces, ref_v, ref_f, TOLERANCE),
              "Target Triangles without mesh simplification in the library: the full mesh (and a warning)")


def test_cancel(cloud):
    activate(cloud)
    before = scene_state()
    result, error = run_operator(**pc.RUNS[0], cancel_after_progress=3)
    check(result == {'CANCELLED'} and not error, f"cancelled run returns CANCELLED, no error {error}")
    check(scene_state() == before, "cancelled run leaves the scene as it was")


def test_failures(cloud):
    activate(cloud)
    before = scene_state()
    result, error = run_operator(**dict(pc.RUNS[0], resolution=3))
    check(result is None and "resolution" in error.lower(), f"a parameter the library refuses is an error report: {error!r}")
    check(scene_state() == before, "a failed run leaves the scene as it was")

    empty = bpy.data.objects.new("empty_cloud", bpy.data.meshes.new("empty_cloud"))
    bpy.context.collection.objects.link(empty)
    activate(empty)
    before = scene_state()
    result, error = run_operator()
    check(result is None and "no vertices" in error, f"an object without vertices is an error report: {error!r}")
    check(scene_state() == before, "... and adds nothing")

    bpy.ops.object.camera_add()
    result, error = run_operator()
    check(result is None and "poll" in error, f"a non-mesh active object: the operator is unavailable: {error!r}")

    prefs = bpy.context.preferences.addons[ADDON].preferences
    saved, prefs.library_path = prefs.library_path, "/nonexistent/libgmpu.so.1"
    activate(cloud)
    before = scene_state()
    result, error = run_operator(**pc.RUNS[0])
    check(result is None and "cannot load the library" in error,
          f"another library than the loaded one is an error report: {error!r}")
    check(scene_state() == before, "... and adds nothing")
    prefs.library_path = saved


def test_library_missing():
    """A fresh Blender whose preference names no library: the run is an error report naming
    the places tried, and Blender exits normally (the installed add-on is reused)."""
    script = (
        "import bpy, addon_utils\n"
        f"bpy.ops.preferences.addon_enable(module={ADDON!r})\n"
        f"bpy.context.preferences.addons[{ADDON!r}].preferences.library_path = '/nonexistent/libgmpu.so.1'\n"
        "bpy.ops.mesh.primitive_cube_add()\n"
        "try:\n"
        "    print('RESULT', bpy.ops.object.gmpu_reconstruct())\n"
        "except RuntimeError as e:\n"
        "    print('REPORT', e)\n"
        "print('objects', len(bpy.data.objects))\n")
    env = dict(os.environ)
    env.pop("GMPU_LIBRARY", None)
    proc = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                           "--python-expr", script], env=env, capture_output=True, text=True, timeout=300)
    out = proc.stdout
    check(proc.returncode == 0 and "REPORT Error: gmpu: cannot load the library" in out and "/nonexistent" in out
          and "objects 4" in out,
          f"no library: an error report naming where it looked, nothing added, Blender exits 0 "
          f"(status {proc.returncode}; {[l for l in out.splitlines() if l.startswith(('REPORT', 'RESULT', 'objects'))]})")


def uninstall():
    """Disables the add-on and deletes its installed copy (addon_remove needs a UI area)."""
    module = sys.modules.get(ADDON)
    if ADDON in bpy.context.preferences.addons:
        bpy.ops.preferences.addon_disable(module=ADDON)
    if module is not None:
        shutil.rmtree(os.path.dirname(module.__file__), ignore_errors=True)


def main():
    try:
        test_install()
        cloud = import_cloud()
        test_runs(cloud)
        test_decimation(cloud)
        test_cancel(cloud)
        test_failures(cloud)
        test_library_missing()
    except Exception:
        traceback.print_exc()
        failures.append("unexpected exception")
    finally:
        uninstall()
    print(f"blender_test: {len(failures)} failure(s)" if failures else "blender_test: all checks passed", flush=True)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
