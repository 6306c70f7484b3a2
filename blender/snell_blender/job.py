# SPDX-License-Identifier: GPL-3.0-or-later
"""An F12 or animation render job: one scene sync for every frame of it.

Blender makes a new RenderEngine for each frame (two, in fact), so what must
outlive a frame lives here: the job starts with the first frame the engine
renders, keeps its SceneSync (and so snell's scene, trees and GPU memory),
and ends when Blender says the render is complete or cancelled, when a
single frame is done, or when a frame raises. After the first frame a frame
sends only the vertices that changed and the transforms that moved, as the
viewport does.

A frame larger than STRIP_PIXELS is traced in strips of rows, each a view
of its own (an off-centre projection of the same camera), so that Esc is
heard between strips and the render window fills as they finish.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Optional

import bpy

from . import runtime

STRIP_PIXELS = 1 << 20  # traced whole below this; in strips of about this many pixels above


@dataclass
class FramePicture:
    """One frame's pixels, row 0 at the top: 'rgba' and the snell AOVs its passes ask for."""

    planes: dict = field(default_factory=dict)


@dataclass
class Stats:
    """What the job did, for the engine's status line, tests and benchmarks."""

    frames: int = 0
    rebuilds: int = 0
    dropped: int = 0
    meshes_sent: list = field(default_factory=list)  # the last frame's
    sent: dict = field(default_factory=dict)  # per rendered frame number: the meshes it sent
    seconds: dict = field(default_factory=dict)  # per rendered frame number: (sync, render) seconds


class RenderJob:
    """The frames of one render: a SceneSync kept from the first to the last."""

    def __init__(self) -> None:
        self.sync = None
        self.stats = Stats()

    def close(self) -> None:
        if self.sync is not None:
            self.sync.close()
            self.sync = None

    def _synced(self, depsgraph, stop: Callable[[], bool], progress: Callable[[float, str], None]) -> bool:
        """The sync brought to this frame (built at the first); False when stopped part way."""
        from .sync import SceneSync, TopologyChanged

        if self.sync is not None:
            try:
                done = self.sync.send_changed(depsgraph, stop, lambda i, n: progress(0.5 * i / max(n, 1), "sending"))
                if done is None:
                    return False
                self.stats.meshes_sent = done["meshes_sent"]
                return True
            except TopologyChanged as change:
                print(f"snell: {change}: the scene is built again")
                self.close()
        progress(0.0, "building the scene")
        self.sync = SceneSync(runtime.device(), depsgraph)
        self.stats.rebuilds += 1
        self.stats.meshes_sent = sorted(self.sync.geometry)
        return True

    def render_frame(self, depsgraph, camera, width: int, height: int, pixel_aspect: tuple, passes: list,
                     stop: Callable[[], bool], progress: Callable[[float, str], None]) -> Optional[FramePicture]:
        """The frame at the depsgraph's time, or None when `stop()` said so between its steps."""
        import numpy as np

        from .camera import scene_camera, view_of

        started = time.perf_counter()
        if not self._synced(depsgraph, stop, progress):
            return None
        synced = time.perf_counter()
        scene = depsgraph.scene
        view_matrix, projection = scene_camera(depsgraph, camera, width, height, pixel_aspect)
        picture = FramePicture()
        keys = ["rgba"] + [key for key, *_ in passes]
        for key in keys:
            channels = {"rgba": 4, "normal": 3}.get(key, 1)
            dtype = np.float32 if key in ("rgba", "depth", "normal") else np.uint32
            picture.planes[key] = np.zeros((height, width, channels) if channels > 1 else (height, width), dtype)
        rows = strips(width, height)
        for done, (top, count) in enumerate(rows):
            if stop():
                return None
            step = "tracing" if len(rows) == 1 else f"tracing strip {done + 1} of {len(rows)}"
            progress(0.5 + 0.5 * done / len(rows), step)
            view = view_of(scene, width, count, view_matrix, strip_projection(projection, height, top, count), False,
                           self.sync.background)
            if passes:
                planes = self.sync.renderer.render_aovs(view)
                for key in keys:
                    picture.planes[key][top:top + count] = planes[key]
            else:
                picture.planes["rgba"][top:top + count] = self.sync.renderer.render(view)
        if stop():
            return None
        self.stats.frames += 1
        self.stats.sent[scene.frame_current] = list(self.stats.meshes_sent)
        self.stats.seconds[scene.frame_current] = (synced - started, time.perf_counter() - synced)
        progress(1.0, "done")
        return picture


def strips(width: int, height: int) -> list:
    """(first row, rows) of the strips a width x height frame is traced in: one below STRIP_PIXELS."""
    if width * height <= STRIP_PIXELS:
        return [(0, height)]
    rows = max(1, STRIP_PIXELS // width)
    return [(top, min(rows, height - top)) for top in range(0, height, rows)]


def strip_projection(projection, height: int, top: int, rows: int):
    """The projection of rows [top, top + rows) of a frame `height` rows high, as a view of their own.

    Row 0 is the top, where clip-space y is +1: the strip's window spans y in
    [1 - 2 (top + rows) / height, 1 - 2 top / height], which is mapped onto [-1, 1].
    """
    if top == 0 and rows == height:
        return projection
    scale = rows / height
    centre = 1.0 - (2.0 * top + rows) / height
    strip = projection.copy()
    strip[1] = (projection[1] - centre * projection[3]) / scale
    return strip


_current: Optional[RenderJob] = None
finished: Optional[Stats] = None  # the last ended job's, for tests and benchmarks


def current() -> RenderJob:
    """The render's job, started by its first frame."""
    global _current
    if _current is None:
        _current = RenderJob()
    return _current


def end(*_args) -> None:
    """Ends the render's job and lets go of its GPU memory (render complete or cancelled, or a failure)."""
    global _current, finished
    if _current is not None:
        _current.close()
        finished = _current.stats
    _current = None


def last_stats() -> Optional[Stats]:
    """The running job's statistics (None between jobs)."""
    return _current.stats if _current is not None else None


@bpy.app.handlers.persistent
def _on_render_end(*_args) -> None:
    end()


def register() -> None:
    for handlers in (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel):
        if _on_render_end not in handlers:
            handlers.append(_on_render_end)


def unregister() -> None:
    for handlers in (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel):
        if _on_render_end in handlers:
            handlers.remove(_on_render_end)
    end()
