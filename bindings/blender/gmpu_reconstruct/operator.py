"""bpy.ops.object.gmpu_reconstruct: the active object's vertices → a new mesh object.

From the UI (invoke) the operator is modal: gmpu runs on a worker thread (job.py), a timer
polls it, moves Blender's progress indicator and keeps the UI live; Esc asks the job to
cancel, which the library honours within 100 ms. From scripts, the redo panel and
background Blender (execute) the same worker runs while this thread waits for it, still
showing progress; the hidden cancel_after_progress property drives the cancel path there.

Nothing in the scene changes until the result is complete: a cancelled or failed run leaves
the scene as it was. Failures are reports (self.report), never exceptions out of Blender.
"""
import time

import bpy
from bpy.props import IntProperty

from . import binding, mesh_io, params, preferences
from .job import ReconstructJob

_POLL_SECONDS = 0.1
# Jobs still running, so unregistering the add-on (or quitting) can stop them first.
RUNNING = set()


class GMPU_OT_reconstruct(bpy.types.Operator):
    """Reconstruct a closed surface from the active object's vertices (a point cloud) as a new mesh object"""

    bl_idname = "object.gmpu_reconstruct"
    bl_label = "Reconstruct Surface (gmpu)"
    bl_options = {'REGISTER', 'UNDO'}

    __annotations__ = {
        **params.annotations(),
        "cancel_after_progress": IntProperty(
            name="Cancel After", default=0, min=0, options={'HIDDEN', 'SKIP_SAVE'},
            description="Testing: cancel at this progress call, as Esc does (0: never)"),
    }

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if obj is None or obj.type != 'MESH':
            cls.poll_message_set("The active object must be a mesh or point cloud: its vertices are the input")
            return False
        return True

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        for name in params.NAMES:
            layout.prop(self, name)

    # -- shared by both paths ---------------------------------------------------------------

    def _start(self, context) -> bool:
        """Copies the input and starts the worker; False (with a report) if it cannot."""
        settings = getattr(context.scene, "gmpu_settings", None)
        if settings is not None:  # unset properties follow the sidebar panel
            for name in params.NAMES:
                if not self.properties.is_property_set(name):
                    setattr(self, name, getattr(settings, name))
        source = context.active_object
        points = mesh_io.object_points(source)
        if len(points) == 0:
            self.report({'ERROR'}, f"gmpu: '{source.name}' has no vertices to reconstruct from")
            return False
        try:
            gmpu = binding.load(preferences.get(context).library_path)
        except ImportError as e:
            self.report({'ERROR'}, f"gmpu: cannot load the library: {e}")
            return False
        self._source_name = source.name
        self._matrix = source.matrix_world.copy()
        self._started = time.monotonic()
        self._job = ReconstructJob(gmpu, points, params.gmpu_params(self), self.target_triangles,
                                   self.cancel_after_progress).start()
        RUNNING.add(self._job)
        return True

    def _finish(self, context):
        job = self._job
        RUNNING.discard(job)
        if job.cancelled:
            self.report({'WARNING'}, "gmpu: reconstruction cancelled; nothing was added")
            return {'CANCELLED'}
        if job.error is not None:
            self.report({'ERROR'}, f"gmpu: {job.error}")
            return {'CANCELLED'}
        if job.warning:
            self.report({'WARNING'}, f"gmpu: {job.warning}")
        mesh = job.mesh
        obj = mesh_io.new_mesh_object(context, self._source_name + "_gmpu", mesh.vertices, mesh.faces, self._matrix)
        self.report({'INFO'}, f"gmpu: {obj.name}: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles "
                              f"in {time.monotonic() - self._started:.1f} s")
        return {'FINISHED'}

    # -- scripts, redo, background: wait here for the worker --------------------------------

    def execute(self, context):
        if not self._start(context):
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        try:
            while not self._job.wait(_POLL_SECONDS):
                wm.progress_update(self._job.fraction)
        except KeyboardInterrupt:  # Ctrl-C in a terminal running background Blender
            self._job.cancel()
            self._job.wait()
        finally:
            wm.progress_end()
        return self._finish(context)

    # -- the UI: modal, polled by a timer ----------------------------------------------------

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        if not self._start(context):
            return {'CANCELLED'}
        wm = context.window_manager
        self._timer = wm.event_timer_add(_POLL_SECONDS, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0.0, 1.0)
        context.workspace.status_text_set("gmpu: reconstructing... (Esc to cancel)")
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            self._job.cancel()  # the next TIMER sees it end, within the library's 100 ms
            context.workspace.status_text_set("gmpu: cancelling...")
            return {'RUNNING_MODAL'}
        if event.type == 'TIMER':
            wm = context.window_manager
            wm.progress_update(self._job.fraction)
            if self._job.done:
                wm.event_timer_remove(self._timer)
                wm.progress_end()
                context.workspace.status_text_set(None)
                return self._finish(context)
        return {'PASS_THROUGH'}


def menu_entry(self, context):
    self.layout.operator(GMPU_OT_reconstruct.bl_idname, icon='MESH_ICOSPHERE')


def stop_running_jobs() -> None:
    for job in list(RUNNING):
        job.cancel()
        job.wait()
    RUNNING.clear()
