"""The add-on's interactive path, in a real Blender window (on Xvfb, no GPU needed):

    xvfb-run -a blender --factory-startup --enable-event-simulate \\
        --python tests/plugins/blender_ui_test.py

The operator is invoked as the Reconstruct button does (INVOKE_DEFAULT: modal, worker
thread, timer); the test then checks, from a timer of its own while the UI keeps running,
that the run ends with a new closed mesh equal to the CLI's, and that a run interrupted by a
simulated Esc press ends cancelled with the scene unchanged. It installs the add-on from the
zip as blender_test.py does (`make test-plugins` gives it throwaway Blender user
directories). Blender quits with status 0 when every check passes, 1 otherwise.
"""
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plugin_checks as pc  # noqa: E402
from blender_test import ADDON, ZIP, TOLERANCE, activate, check, failures, mesh_arrays, scene_state  # noqa: E402

TIMEOUT = 300.0  # seconds for the whole test: a stuck modal operator must not hang CI
state = {"step": "start", "since": time.monotonic(), "began": time.monotonic()}


def window_context():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    return dict(window=window, area=area, region=region)


def invoke(**params):
    with bpy.context.temp_override(**window_context()):
        return bpy.ops.object.gmpu_reconstruct('INVOKE_DEFAULT', **params)


def open_sidebar_panel():
    """Shows the 3D Viewport's sidebar with the panel, recording each of its draws (an
    exception in a panel's draw is only printed by Blender). Blender 3.4 cannot switch the
    sidebar's tab from Python, so the panel is re-registered on the tab shown first."""
    from gmpu_reconstruct.panel import GMPU_PT_reconstruct

    draws = state["panel_draws"] = []
    original = GMPU_PT_reconstruct.draw

    def draw(self, context):
        try:
            original(self, context)
            draws.append(True)
        except Exception:
            draws.append(False)
            raise

    GMPU_PT_reconstruct.draw = draw
    bpy.utils.unregister_class(GMPU_PT_reconstruct)
    GMPU_PT_reconstruct.bl_category = "Item"
    bpy.utils.register_class(GMPU_PT_reconstruct)
    ctx = window_context()
    ctx["area"].spaces.active.show_region_ui = True
    ctx["area"].tag_redraw()


def finish():
    print(f"blender_ui_test: {len(failures)} failure(s)" if failures else "blender_ui_test: all checks passed",
          flush=True)
    os._exit(1 if failures else 0)  # quit now, from a timer, whatever the UI is doing


def step():
    """One state-machine step per timer tick; returns the delay to the next tick."""
    now = time.monotonic()
    if now - state["began"] > TIMEOUT:
        check(False, f"timed out in step {state['step']}")
        finish()
    s = state["step"]
    if s == "start":
        bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
        bpy.ops.preferences.addon_enable(module=ADDON)
        bpy.context.preferences.addons[ADDON].preferences.library_path = pc.library_path()
        bpy.ops.import_mesh.ply(filepath=pc.CLOUD)
        state["cloud"] = bpy.context.active_object
        state["before"] = set(bpy.data.objects.keys())
        open_sidebar_panel()
        state["step"], state["since"] = "panel", now
    elif s == "panel":
        drawn = state["panel_draws"]
        if not drawn and now - state["since"] < 20:
            return 0.2
        check(drawn and all(ok for ok in drawn), f"sidebar panel drawn without error ({len(drawn)} draws)")
        shot = os.environ.get("GMPU_UI_SCREENSHOT")
        if shot:
            with bpy.context.temp_override(**window_context()):
                bpy.ops.screen.screenshot(filepath=shot)
        result = invoke(**pc.RUNS[0])
        check(result == {'RUNNING_MODAL'}, f"invoke: the operator runs modal ({result})")
        state["step"] = "wait_run"
    elif s == "wait_run":
        added = set(bpy.data.objects.keys()) - state["before"]
        if not added:
            return 0.2
        obj = bpy.data.objects[added.pop()]
        vertices, faces = mesh_arrays(obj)
        check(faces is not None and not pc.closed_problem(faces), "modal run: a closed triangle mesh")
        ref_v, ref_f = pc.cli_mesh(pc.CLOUD, pc.RUNS[0])
        diff = pc.difference(vertices, faces, ref_v, ref_f, TOLERANCE) if faces is not None else "no faces"
        check(not diff, f"modal run: equal to the CLI's mesh {diff}")
        # Esc: a run long enough to be interrupted (depth 9, fine grid), cancelled at once.
        activate(state["cloud"])
        state["before_cancel"] = scene_state()
        check(invoke(**dict(pc.RUNS[1], max_depth=9, resolution=400)) == {'RUNNING_MODAL'}, "second run started")
        state["step"], state["since"] = "press_esc", now
    elif s == "press_esc":
        from gmpu_reconstruct import operator as op_module  # the running jobs

        jobs = list(op_module.RUNNING)
        check(len(jobs) == 1, "the second run is running when Esc is pressed")
        state["job"] = jobs[0] if jobs else None
        window = bpy.context.window_manager.windows[0]
        window.event_simulate(type='ESC', value='PRESS')
        window.event_simulate(type='ESC', value='RELEASE')
        state["step"], state["since"] = "wait_cancel", now
        return 0.5
    elif s == "wait_cancel":
        from gmpu_reconstruct import operator as op_module  # the running jobs

        if op_module.RUNNING and now - state["since"] < 30:
            return 0.2
        check(not op_module.RUNNING, "Esc: the worker has stopped")
        job = state["job"]
        check(job is not None and job.cancelled and job.mesh is None, "Esc: the run was cancelled, not finished")
        check(scene_state() == state["before_cancel"], "Esc: the scene is as it was")
        finish()
    return 0.1


def tick():
    try:
        return step()
    except Exception:
        import traceback

        traceback.print_exc()
        check(False, "unexpected exception")
        finish()


bpy.app.timers.register(tick, first_interval=1.0)
