# SPDX-License-Identifier: GPL-3.0-or-later
"""An animation render on every GPU: Blender poses the frames, snell's workers draw them.

Blender's own animation render asks the engine for one frame at a time, so
one GPU draws them all. snell.render_animation (Render > snell: Render
Animation, and Ctrl+F12 when the preference "Animations on every GPU" is on
and snell is the engine) hands the frame range to snell.render_frames
instead: Blender's main thread sets each frame and reads every mesh's
evaluated vertices, every transform and the camera, a few frames ahead, and
one worker per GPU draws them; each finished frame is written where
Blender's animation render writes it, in its format and colour management.
Each frame carries the whole scene state, so its pixels do not depend on
which GPU drew it. The shot runs on a thread of its own: the interface stays
live, and Esc stops it after the frames under way.
"""

from __future__ import annotations

import queue
import threading
import time
from typing import Optional

import bpy

from . import camera, runtime

AHEAD = 2  # frames posed and waiting for the shot's thread
last: Optional[dict] = None  # the last shot's summary (snell.render_frames'), for tests


class Cancelled(Exception):
    """Esc: the frames not yet drawn are dropped."""


class AnimationShot:
    """The frames of a scene's range on `devices`, posed on this thread and drawn on the shot's."""

    def __init__(self, context, devices: str, device: str = "") -> None:
        import snell

        from .sync import SceneSync

        scene = context.scene
        if scene.camera is None:
            raise RuntimeError("the scene has no camera to render from")
        self.scene = scene
        self.devices, self.device = devices, device
        self.frames = list(range(scene.frame_start, scene.frame_end + 1, max(1, scene.frame_step)))
        scale = scene.render.resolution_percentage / 100.0
        self.width = max(1, int(scene.render.resolution_x * scale))
        self.height = max(1, int(scene.render.resolution_y * scale))
        self._frame_before = scene.frame_current
        scene.frame_set(self.frames[0])
        depsgraph = context.evaluated_depsgraph_get()
        self.sync = SceneSync(None, depsgraph)  # the scene alone: each worker makes its own renderer
        self.view = self._view(depsgraph)
        self._snell = snell
        self._posed = 0                       # frames handed to the shot's thread
        self._feed: queue.Queue = queue.Queue()   # posed frames (None: no more; Cancelled: stop)
        self._drawn: queue.Queue = queue.Queue()  # pictures (None: the shot ended)
        self._image = bpy.data.images.new("snell shot", self.width, self.height, alpha=True, float_buffer=True)
        self.written: list = []  # the files written, in the order the frames finished
        self.summary: Optional[dict] = None
        self.error: Optional[BaseException] = None
        self.started = time.perf_counter()
        self._thread = threading.Thread(target=self._draw, name="snell shot", daemon=True)
        self._thread.start()

    def _camera(self, depsgraph) -> tuple:
        """The scene camera's (view matrix in snell's world, projection) at the depsgraph's frame."""
        pixel_aspect = (self.scene.render.pixel_aspect_x, self.scene.render.pixel_aspect_y)
        return camera.scene_camera(depsgraph, self.scene.camera, self.width, self.height, pixel_aspect)

    def _view(self, depsgraph):
        """The shot's View: the scene's settings (method, optics, background); each frame brings its camera."""
        view_matrix, projection = self._camera(depsgraph)
        return camera.view_of(self.scene, self.width, self.height, view_matrix, projection, False,
                              self.sync.background)

    def _draw(self) -> None:
        """The shot's thread: snell.render_frames over the posed frames."""
        def frames():
            while True:
                frame = self._feed.get()
                if frame is None:
                    return
                if isinstance(frame, Cancelled):
                    raise frame
                yield frame

        try:
            self.summary = self._snell.render_frames(self.sync.scene, self.view, frames(), self._drawn.put,
                                                     devices=self.devices, device=self.device)
        except BaseException as error:  # noqa: B902  (handed to the main thread, which reports it)
            self.error = error
        finally:
            self._drawn.put(None)

    def step(self) -> bool:
        """Poses frames while the shot's thread runs low and writes those drawn; False once it ended."""
        while self._posed < len(self.frames) and self._feed.qsize() < AHEAD:
            number = self.frames[self._posed]
            self.scene.frame_set(number)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            vertices, transforms = self.sync.frame_state(depsgraph)
            view_matrix, projection = self._camera(depsgraph)
            self._feed.put(self._snell.ShotFrame(number, view_matrix=view_matrix, projection=projection,
                                                 transforms=transforms, vertices=vertices))
            self._posed += 1
            if self._posed == len(self.frames):
                self._feed.put(None)
        while True:
            try:
                picture = self._drawn.get(timeout=0.01)
            except queue.Empty:
                return True
            if picture is None:
                return False
            self._write(picture)

    def _write(self, picture: dict) -> None:
        """A drawn frame into the file Blender's animation render would write for it."""
        path = self.scene.render.frame_path(frame=picture["number"])
        self._image.pixels.foreach_set(picture["rgba"][::-1].ravel())
        self._image.save_render(runtime.bpy_path(path), scene=self.scene)
        self.written.append(path)

    def cancel(self) -> None:
        self._feed.put(Cancelled("stopped by Esc"))

    def finish(self) -> None:
        """Waits for the shot's thread and lets go of everything; raises what failed (not Esc)."""
        self._thread.join()
        bpy.data.images.remove(self._image)
        self.sync.close()
        self.scene.frame_set(self._frame_before)  # as Blender's own animation render leaves it
        if self.error is not None and not isinstance(self.error, Cancelled):
            raise self.error

    @property
    def progress(self) -> float:
        return len(self.written) / len(self.frames)


def devices_for(context) -> tuple:
    """(devices, device) for snell.render_frames: every GPU where the preference says so, else the add-on's one."""
    prefs = context.preferences.addons[__package__].preferences
    return ("all", "") if prefs.every_gpu else ("", prefs.device)


class SNELL_OT_render_animation(bpy.types.Operator):
    """Render the animation with snell, its frames drawn on every GPU at once where the preferences say so"""

    bl_idname = "snell.render_animation"
    bl_label = "snell: Render Animation"

    devices: bpy.props.StringProperty(
        name="Devices", default="", options={"SKIP_SAVE"},
        description="The GPUs to draw on ('all', or indices '0,1'); empty: as the add-on's preferences say")
    shortcut: bpy.props.BoolProperty(
        default=False, options={"HIDDEN", "SKIP_SAVE"},
        description="Started by Ctrl+F12: Blender's own animation render unless the preference says every GPU")

    @classmethod
    def poll(cls, context) -> bool:
        return context.scene.render.engine == "SNELL"

    def _start(self, context) -> bool:
        if runtime.device() is None:  # also finds the snell module
            self.report({"ERROR"}, f"snell: {runtime.problem()}")
            return False
        devices, device = (self.devices, "") if self.devices else devices_for(context)
        try:
            self.shot = AnimationShot(context, devices, device)
        except Exception as error:  # snell.Error, or a scene snell cannot take
            self.report({"ERROR"}, f"snell: {error}")
            return False
        return True

    def _end(self, context) -> set:
        shot = self.shot
        try:
            shot.finish()
        except Exception as error:
            self.report({"ERROR"}, f"snell: {error}")
            return {"CANCELLED"}
        global last
        summary = last = shot.summary or {"workers": []}
        split = ", ".join(f"{w['frames']} on {w['device']}" for w in summary["workers"])
        cancelled = isinstance(shot.error, Cancelled)
        self.report({"WARNING" if cancelled else "INFO"},
                    f"snell: {len(shot.written)} of {len(shot.frames)} frames in "
                    f"{time.perf_counter() - shot.started:.1f} s" + (f" ({split})" if split else "") +
                    (", stopped by Esc" if cancelled else ""))
        return {"CANCELLED"} if cancelled else {"FINISHED"}

    def execute(self, context):
        """Blocking: for scripts and background renders."""
        if not self._start(context):
            return {"CANCELLED"}
        while self.shot.step():
            pass
        return self._end(context)

    def invoke(self, context, event):
        """From the interface: the shot runs while Blender stays live; Esc stops it."""
        if self.shortcut and not context.preferences.addons[__package__].preferences.every_gpu:
            return {"PASS_THROUGH"}  # Ctrl+F12 stays Blender's own animation render
        if not self._start(context):
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.05, window=context.window)
        wm.progress_begin(0, 1)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            self.shot.cancel()
        if event.type != "TIMER" and event.type != "ESC":
            return {"PASS_THROUGH"}
        running = self.shot.step()
        wm.progress_update(self.shot.progress)
        context.workspace.status_text_set(f"snell: {len(self.shot.written)} of {len(self.shot.frames)} frames")
        if running:
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._end(context)


def menu_entry(self, context) -> None:
    if context.scene.render.engine == "SNELL":
        self.layout.operator(SNELL_OT_render_animation.bl_idname, icon="RENDER_ANIMATION")


_keymaps: list = []


def register() -> None:
    bpy.utils.register_class(SNELL_OT_render_animation)
    bpy.types.TOPBAR_MT_render.append(menu_entry)
    # Ctrl+F12 is snell's when the preference is on (the operator's keymap item runs before Blender's own).
    config = bpy.context.window_manager.keyconfigs.addon
    if config is not None:
        keymap = config.keymaps.new(name="Screen", space_type="EMPTY")
        item = keymap.keymap_items.new(SNELL_OT_render_animation.bl_idname, "F12", "PRESS", ctrl=True)
        item.properties.shortcut = True
        _keymaps.append((keymap, item))


def unregister() -> None:
    for keymap, item in _keymaps:
        keymap.keymap_items.remove(item)
    _keymaps.clear()
    bpy.types.TOPBAR_MT_render.remove(menu_entry)
    bpy.utils.unregister_class(SNELL_OT_render_animation)
