# SPDX-License-Identifier: GPL-3.0-or-later
"""The render engine: snell in the Rendered viewport, for F12 and for animation renders.

The viewport (view_update, view_draw) keeps one SceneSync per engine: the
first update sends the topology, later ones only what Blender re-evaluated.
Each draw renders the region's own view and projection (perspective,
orthographic, or the camera view with its zoom, offset and lens shift) as
snell's viewport composite, and shows it through Blender's colour
management: zero-copy through OpenGL interop where the driver allows it,
otherwise by uploading the pixels.
"""

from __future__ import annotations

import time
from typing import Optional

import bpy

from . import compat, runtime
from . import job as jobs
from .properties import enabled_passes, settings

# What the last viewport update and draw did, for the overlay, benchmarks and tests.
STATS: dict = {"updates": 0, "rebuilds": 0, "meshes_sent": [], "draw_path": None}


class SnellRenderEngine(bpy.types.RenderEngine):
    """snell: refraction through deforming meshes, ray traced by Vulkan compute."""

    bl_idname = "SNELL"
    bl_label = "snell"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False  # materials are Blender's own node trees

    def __init__(self, *args, **kwargs) -> None:
        # 4.4 hands a RenderEngine subclass's __init__ arguments it must pass on.
        super().__init__(*args, **kwargs)
        self.sync = None
        self.display = None
        self.problem: Optional[str] = None

    def __del__(self) -> None:
        # Blender may call this after the add-on's module state is gone.
        try:
            self._release()
        except Exception:
            pass

    def _release(self) -> None:
        if getattr(self, "display", None) is not None:
            self.display.close()
            self.display = None
        if getattr(self, "sync", None) is not None:
            self.sync.close()
            self.sync = None

    # ------------------------------------------------------------ F12 and animation

    def update_render_passes(self, scene=None, renderlayer=None) -> None:
        """The passes a view layer's snell settings ask for, so the compositor and EXR files see them."""
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for _, name, channels, kind, _ in enabled_passes(renderlayer):
            self.register_pass(scene, renderlayer, name, len(channels), channels, kind)

    def render(self, depsgraph) -> None:
        """One frame of an F12 or animation render, in the render job's scene sync (job.py)."""
        scene = depsgraph.scene
        if runtime.device() is None:
            self.report({"ERROR"}, f"snell: {runtime.problem()}")
            return
        if scene.camera is None:
            self.report({"ERROR"}, "snell: the scene has no camera to render from")
            return
        scale = scene.render.resolution_percentage / 100.0
        width = max(1, int(scene.render.resolution_x * scale))
        height = max(1, int(scene.render.resolution_y * scale))
        view_layer = depsgraph.view_layer
        # The layer's own settings: 5.0's evaluated copy of a view layer does not carry an add-on's properties.
        passes = enabled_passes(scene.original.view_layers.get(view_layer.name, view_layer))
        if passes and settings(scene).method not in TRACED_METHODS:
            self.report({"WARNING"}, f"snell: the passes come from the trace; method {settings(scene).method} "
                                     "writes the combined image alone")
            passes = []
        frame, (index, total) = scene.frame_current, _frame_index(scene, self.is_animation)
        status = f"Frame {frame}" + (f" ({index} of {total})" if total > 1 else "")

        job = jobs.current()
        try:
            picture = job.render_frame(depsgraph, scene.camera, width, height,
                                       (scene.render.pixel_aspect_x, scene.render.pixel_aspect_y), passes,
                                       lambda: escape_pressed(self),
                                       lambda fraction, step: report_progress(self, fraction, f"{status} | {step}"))
        except Exception as error:  # snell.Error, or Blender data snell cannot take: nothing is kept
            jobs.end()
            self.report({"ERROR"}, f"snell: {error}")
            return
        if picture is None:  # Esc: the frame under way is dropped and nothing of it is written
            job.stats.dropped += 1
            report_progress(self, None, f"{status} | stopped")
            return
        if "normal" in picture.planes:
            picture.planes["normal"] = _turned_to_camera(picture.planes["normal"], depsgraph, scene.camera, width,
                                                         height)
        for _, name, channels, _, _ in passes:
            self.add_pass(name, len(channels), channels, layer=view_layer.name)
        result = self.begin_result(0, 0, width, height, layer=view_layer.name)
        try:
            layer = result.layers[0]
            # Blender's rows run bottom to top; each pass is written at once.
            compat.write_pass(layer.passes["Combined"], _rows_up(picture.planes["rgba"]))
            for key, name, _, _, _ in passes:
                compat.write_pass(layer.passes[name], _rows_up(_pass_values(key, picture.planes[key])))
        finally:
            self.end_result(result)
        if not self.is_animation:
            jobs.end()  # a still: nothing to keep for a next frame

    # ------------------------------------------------------------ the viewport

    def view_update(self, context, depsgraph) -> None:
        from .sync import SceneSync, TopologyChanged

        device = runtime.device()
        if device is None:
            self.problem = runtime.problem()
            return
        STATS["updates"] += 1
        try:
            if self.sync is not None:
                try:
                    done = self.sync.update(depsgraph)
                    STATS["meshes_sent"] = done["meshes_sent"]
                    STATS["feed_ms"] = done["feed_ms"]
                    return
                except TopologyChanged as change:
                    STATS["rebuild_reason"] = str(change)
                    self.sync.close()
                    self.sync = None
            self.sync = SceneSync(device, depsgraph)
            STATS["rebuilds"] += 1
            STATS["meshes_sent"] = sorted(self.sync.geometry)
            STATS["feed_ms"] = self.sync.build_seconds * 1000
            self.problem = None
        except Exception as error:
            self.problem = str(error)
            print(f"snell: {error}")

    def view_draw(self, context, depsgraph) -> None:
        from . import display

        region, rv3d, scene = context.region, context.region_data, depsgraph.scene
        if self.sync is None:
            display.draw_text(self.problem or runtime.problem() or "snell: nothing to draw", error=True)
            return
        started = time.perf_counter()
        from .camera import viewport_view

        view = viewport_view(scene, region, rv3d, self.sync.background)
        if self.display is None:
            self.display = display.Display(runtime.device())
        try:
            self.display.render(self.sync.renderer, view, settings(scene).display == "AUTO")
        except Exception as error:
            display.draw_text(f"snell: {error}", error=True)
            return
        rendered = time.perf_counter()
        gpu_state_set = display.begin_colour_managed()
        self.bind_display_space_shader(scene)
        self.display.draw(region.width, region.height)
        self.unbind_display_space_shader()
        display.end_colour_managed(gpu_state_set)
        done = time.perf_counter()
        frame = self.sync.renderer.last_frame()
        # render: snell's frame and the image's way to OpenGL; blit: drawing it through colour management.
        STATS.update(draw_path=self.display.path, render_ms=(rendered - started) * 1000,
                     blit_ms=(done - rendered) * 1000, draw_ms=(done - started) * 1000, gpu_ms=frame["gpu_ms"],
                     frame=frame)
        if settings(scene).overlay:
            notes = "; ".join(sorted(self.sync.notes))
            display.draw_text(
                f"snell {frame['method']} via {self.display.path}: GPU {frame['gpu_ms']:.2f} ms, "
                f"draw {STATS['draw_ms']:.1f} ms, feed {STATS.get('feed_ms', 0):.1f} ms"
                + (f"  ({notes})" if notes else ""))


def escape_pressed(engine) -> bool:
    """Whether the user asked the render to stop (Esc): asked between a frame's steps."""
    return engine.test_break()


def report_progress(engine, fraction: Optional[float], status: str) -> None:
    """The render window's progress bar (the frame's fraction done, if given) and status line."""
    if fraction is not None:
        engine.update_progress(fraction)
    engine.update_stats("", f"snell | {status}")


# The methods whose F12 image is the trace's, and so has AOVs to give as passes.
TRACED_METHODS = ("trace", "trace-1", "auto")


def _frame_index(scene, animation: bool) -> tuple:
    """This frame's place in the render: (1-based index, frames in all); (1, 1) for a still."""
    if not animation:
        return 1, 1
    step = max(1, scene.frame_step)
    return (scene.frame_current - scene.frame_start) // step + 1, (scene.frame_end - scene.frame_start) // step + 1


def _rows_up(plane):
    """A (height, width[, channels]) plane as a (pixels, channels) float32 block, bottom row first, as passes
    hold it."""
    import numpy as np

    return np.ascontiguousarray(plane[::-1], np.float32).reshape(plane.shape[0] * plane.shape[1], -1)


def _turned_to_camera(normals, depsgraph, camera, width: int, height: int):
    """snell's face normals (its Y-up world, as winding makes them) turned towards the camera along each
    pixel's ray, as Blender's Normal pass has them: a mesh wound inwards still shows normals that face out."""
    import numpy as np

    from .camera import pixel_rays

    along = np.einsum("hwc,hwc->hw", normals, pixel_rays(depsgraph, camera, width, height))
    return np.where((along > 0.0)[..., None], -normals, normals).astype(np.float32)


def _pass_values(key: str, plane):
    """A snell AOV in the form Blender's pass of it holds."""
    import numpy as np

    from .camera import normals_to_blender

    if key == "depth":
        return np.where(np.isfinite(plane), plane, np.float32(1e10))  # Blender's depth where nothing is hit
    if key == "normal":
        return normals_to_blender(plane)
    if key in ("instance", "primitive"):
        return np.where(plane == 0xFFFFFFFF, -1.0, plane.astype(np.float64)).astype(np.float32)
    return plane.astype(np.float32)


def compatible_panels() -> list:
    """Blender's own panels (materials, lights, world, output) that should show for snell."""
    wanted = {"MATERIAL_PT_", "EEVEE_MATERIAL_PT_", "DATA_PT_light", "DATA_PT_EEVEE_light", "DATA_PT_spot",
              "DATA_PT_camera", "DATA_PT_lens", "WORLD_PT_", "RENDER_PT_format", "RENDER_PT_frame_range",
              "RENDER_PT_output", "RENDER_PT_color_management", "VIEWLAYER_PT_"}
    panels = []
    for name in dir(bpy.types):
        panel = getattr(bpy.types, name)
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and engines & set(compat.EEVEE_IDS) and any(name.startswith(w) for w in wanted):
            panels.append(panel)
    return panels


def register() -> None:
    jobs.register()
    bpy.utils.register_class(SnellRenderEngine)
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.add("SNELL")


def unregister() -> None:
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.discard("SNELL")
    bpy.utils.unregister_class(SnellRenderEngine)
    jobs.unregister()
