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

from . import runtime
from .properties import settings

# What the last viewport update and draw did, for the overlay, benchmarks and tests.
STATS: dict = {"updates": 0, "rebuilds": 0, "meshes_sent": [], "draw_path": None}


def _view(scene, width: int, height: int, view_matrix, projection, viewport: bool, background):
    """A snell.View of the scene's settings through Blender's view and projection matrices."""
    import numpy as np
    import snell

    from .sync import Y_UP

    options = settings(scene)
    to_camera = np.array([list(row) for row in view_matrix], np.float64) @ np.linalg.inv(Y_UP)
    return snell.View(width, height, view_matrix=to_camera, projection=np.array([list(r) for r in projection]),
                      viewport=viewport, method=options.method, max_interfaces=options.max_interfaces,
                      fresnel=options.fresnel, dispersion=options.dispersion, volume=options.volume,
                      background=background)


class SnellRenderEngine(bpy.types.RenderEngine):
    """snell: refraction through deforming meshes, ray traced by Vulkan compute."""

    bl_idname = "SNELL"
    bl_label = "snell"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False  # materials are Blender's own node trees

    def __init__(self) -> None:
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

    def render(self, depsgraph) -> None:
        scene = depsgraph.scene
        device = runtime.device()
        if device is None:
            self.report({"ERROR"}, f"snell: {runtime.problem()}")
            return
        camera = scene.camera
        if camera is None:
            self.report({"ERROR"}, "snell: the scene has no camera to render from")
            return
        scale = scene.render.resolution_percentage / 100.0
        width = max(1, int(scene.render.resolution_x * scale))
        height = max(1, int(scene.render.resolution_y * scale))
        try:
            import numpy as np

            from .sync import SceneSync

            sync = SceneSync(device, depsgraph)
            camera = camera.evaluated_get(depsgraph)
            projection = camera.calc_matrix_camera(depsgraph, x=width, y=height,
                                                   scale_x=scene.render.pixel_aspect_x,
                                                   scale_y=scene.render.pixel_aspect_y)
            view = _view(scene, width, height, camera.matrix_world.inverted(), projection, False, sync.background)
            rgba = sync.renderer.render(view)
            sync.close()
        except Exception as error:  # snell.Error, or Blender data snell cannot take
            self.report({"ERROR"}, f"snell: {error}")
            return
        result = self.begin_result(0, 0, width, height)
        try:
            # Blender's rows run bottom to top; foreach_set takes the (pixels, 4) float32 block at once.
            result.layers[0].passes["Combined"].rect.foreach_set(np.ascontiguousarray(rgba[::-1]).reshape(-1, 4))
        finally:
            self.end_result(result)

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
        view = _view(scene, region.width, region.height, rv3d.view_matrix, rv3d.window_matrix, True,
                     self.sync.background)
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


def compatible_panels() -> list:
    """Blender's own panels (materials, lights, world, output) that should show for snell."""
    wanted = {"MATERIAL_PT_", "EEVEE_MATERIAL_PT_", "DATA_PT_light", "DATA_PT_EEVEE_light", "DATA_PT_spot",
              "DATA_PT_camera", "DATA_PT_lens", "WORLD_PT_", "RENDER_PT_format", "RENDER_PT_frame_range",
              "RENDER_PT_output", "RENDER_PT_color_management", "VIEWLAYER_PT_"}
    panels = []
    for name in dir(bpy.types):
        panel = getattr(bpy.types, name)
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and "BLENDER_EEVEE" in engines and any(name.startswith(w) for w in wanted):
            panels.append(panel)
    return panels


def register() -> None:
    bpy.utils.register_class(SnellRenderEngine)
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.add("SNELL")


def unregister() -> None:
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.discard("SNELL")
    bpy.utils.unregister_class(SnellRenderEngine)
