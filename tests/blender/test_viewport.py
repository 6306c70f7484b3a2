"""The Rendered viewport of the demo rig, in a real Blender window (Xvfb).

Run in the background (-b), the script saves the demo as a .blend and opens
it in a windowed Blender on a private X server, running itself again there.
The window's part: the 3D viewport in Rendered shading, looking through the
camera; a screenshot at frame 1, then at frame 20. It checks that the
screenshot's camera frame shows the F12 image (the same view transform:
Standard), that the refracted iris is in it, and that the frame change sent
snell only the meshes that deform (the eyes, not the face plate), and that
an edit in a material's node tree reaches snell.
"""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene, pixels  # noqa: E402

RESULT = SCRATCH / "viewport.json"
DEFORMING = {"Eyeball.L", "Eyeball.R", "Iris.L", "Iris.R"}


def background_part() -> None:
    """Saves the demo, runs the window part under xvfb-run, and checks what it found."""
    SCRATCH.mkdir(parents=True, exist_ok=True)
    demo_scene(320, 134)
    blend = SCRATCH / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    RESULT.unlink(missing_ok=True)
    environment = dict(os.environ, LP_NUM_THREADS="1", SNELL_VIEWPORT_WINDOW="1")
    command = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
               "--window-geometry", "0", "0", "1280", "800", str(blend), "--python", __file__]
    started = time.perf_counter()
    done = subprocess.run(command, env=environment, timeout=240, capture_output=True, text=True)
    print(done.stdout[-4000:], done.stderr[-2000:], sep="\n")
    print(f"the windowed Blender ran {time.perf_counter() - started:.1f} s and exited {done.returncode}")
    check(RESULT.exists(), "the windowed Blender wrote its findings")
    found = json.loads(RESULT.read_text())
    print(json.dumps(found, indent=1))
    check(found["error"] is None, f"the window part ran without error ({found['error']})")
    check(found["draw_path"].startswith("interop"), f"the viewport drew through OpenGL interop ({found['draw_path']})")
    check(found["iris_pixels"] > 200, f"the refracted iris shows in the viewport ({found['iris_pixels']} pixels)")
    check(found["within_8"] >= 0.95 and found["mean_difference"] < 3.0,
          f"the viewport's camera frame matches the F12 image: {found['within_8']:.1%} of pixels within 8/255, "
          f"mean difference {found['mean_difference']:.2f}/255")
    check(set(found["sent_after_frame_change"]) == DEFORMING,
          f"after the frame change snell got the deformed meshes only: {found['sent_after_frame_change']}")
    check(found["rebuilds"] == 1, f"the frame change rebuilt nothing ({found['rebuilds']} builds in all)")
    check(found["moved"] > 0.01, f"the viewport changed with the frame ({found['moved']:.1%} of the frame's pixels)")
    check(found["rebuilds_after_edit"] == 1 and found["green_pixels"] > 2000,
          f"an edit in a material's nodes reached snell: {found['rebuilds_after_edit']} rebuild "
          f"({found['rebuild_reason']}), {found['green_pixels']} green pixels")


# ------------------------------------------------------------------ the window part

def window_part() -> None:
    from bpy_extras import view3d_utils

    from blender_support import enable_addon

    found = {"error": None}
    state = {}

    def finish() -> None:
        RESULT.write_text(json.dumps(found))
        bpy.ops.wm.quit_blender()

    def viewport():
        window = bpy.context.window_manager.windows[0]
        area = max((a for a in window.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.width * a.height)
        region = next(r for r in area.regions if r.type == "WINDOW")
        return window, area, region

    def screenshot(name: str) -> np.ndarray:
        window, area, region = viewport()
        path = SCRATCH / f"{name}.png"
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=str(path))
        shot = pixels(path)  # the area, row 0 at the top
        top = area.y + area.height - (region.y + region.height)
        left = region.x - area.x
        return shot[top:top + region.height, left:left + region.width, :3]

    def start():
        try:
            enable_addon()
            scene = bpy.context.scene
            scene.render.engine = "SNELL"
            scene.frame_set(1)
            window, area, region = viewport()
            space = area.spaces.active
            space.shading.type = "RENDERED"
            space.overlay.show_overlays = False
            space.region_3d.view_perspective = "CAMERA"
            with bpy.context.temp_override(window=window, area=area, region=region):
                bpy.ops.view3d.view_center_camera()
            area.tag_redraw()
            bpy.app.timers.register(at_frame_1, first_interval=6.0)
        except Exception as error:
            found["error"] = repr(error)
            finish()

    def at_frame_1():
        try:
            from snell_blender import engine

            state["frame_1"] = screenshot("viewport_1")
            found["draw_path"] = engine.STATS["draw_path"]
            found["rebuilds_before"] = engine.STATS["rebuilds"]
            bpy.context.scene.frame_set(20)
            bpy.app.timers.register(at_frame_20, first_interval=4.0)
        except Exception as error:
            found["error"] = repr(error)
            finish()

    def at_frame_20():
        try:
            from snell_blender import engine

            scene = bpy.context.scene
            frame_20 = screenshot("viewport_20")
            found["sent_after_frame_change"] = sorted(engine.STATS["meshes_sent"])
            found["rebuilds"] = engine.STATS["rebuilds"]
            found["draw_ms"], found["gpu_ms"] = engine.STATS["draw_ms"], engine.STATS["gpu_ms"]
            # Where the camera's frame lies in the region, to the pixel.
            window, area, region = viewport()
            camera = scene.camera
            corners = [camera.matrix_world @ c for c in camera.data.view_frame(scene=scene)]
            xy = np.array([view3d_utils.location_3d_to_region_2d(region, area.spaces.active.region_3d, c)
                           for c in corners])
            x0, x1 = xy[:, 0].min(), xy[:, 0].max()
            y0, y1 = region.height - xy[:, 1].max(), region.height - xy[:, 1].min()  # rows from the top
            found["frame"] = [float(x0), float(y0), float(x1), float(y1)]
            # F12 at the frame's size in pixels, shown through the same view transform (Standard).
            scene.render.resolution_x, scene.render.resolution_y = round(x1 - x0), round(y1 - y0)
            scene.render.image_settings.file_format = "PNG"
            scene.render.image_settings.color_depth = "8"
            bpy.ops.render.render(write_still=False)
            bpy.data.images["Render Result"].save_render(str(SCRATCH / "f12_20.png"))
            f12 = pixels(SCRATCH / "f12_20.png")[..., :3]
            rows = np.arange(int(np.ceil(y0)) + 1, int(np.floor(y1)) - 1)
            columns = np.arange(int(np.ceil(x0)) + 1, int(np.floor(x1)) - 1)
            seen = frame_20[np.ix_(rows, columns)]
            f_rows = np.clip(((rows + 0.5 - y0) / (y1 - y0) * f12.shape[0]).astype(int), 0, f12.shape[0] - 1)
            f_columns = np.clip(((columns + 0.5 - x0) / (x1 - x0) * f12.shape[1]).astype(int), 0, f12.shape[1] - 1)
            expected = f12[np.ix_(f_rows, f_columns)]
            difference = np.abs(seen - expected).max(axis=2) * 255
            found["within_8"] = float((difference <= 8).mean())
            found["mean_difference"] = float(difference.mean())
            iris = (seen[..., 2] > seen[..., 0] + 0.08) & (seen[..., 1] > seen[..., 0] + 0.05)  # blue-green
            found["iris_pixels"] = int(iris.sum())
            before = state["frame_1"][np.ix_(rows, columns)]
            found["moved"] = float((np.abs(seen - before).max(axis=2) > 16 / 255).mean())
            # An edit in a material's node tree: the face plate turns green.
            state["rebuilds"] = engine.STATS["rebuilds"]
            skin = bpy.data.materials["Skin"]
            bsdf = next(n for n in skin.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
            bsdf.inputs["Base Color"].default_value = (0.05, 0.8, 0.05, 1.0)
            viewport()[1].tag_redraw()
            bpy.app.timers.register(after_material_edit, first_interval=4.0)
        except Exception as error:
            import traceback

            traceback.print_exc()
            found["error"] = repr(error)
            finish()

    def after_material_edit():
        try:
            from snell_blender import engine

            shot = screenshot("viewport_green")
            found["rebuilds_after_edit"] = engine.STATS["rebuilds"] - state["rebuilds"]
            found["rebuild_reason"] = engine.STATS.get("rebuild_reason", "")
            found["green_pixels"] = int(((shot[..., 1] > 2 * shot[..., 0]) & (shot[..., 1] > 2 * shot[..., 2])).sum())
        except Exception as error:
            found["error"] = repr(error)
        finish()

    bpy.app.timers.register(start, first_interval=1.0)


if os.environ.get("SNELL_VIEWPORT_WINDOW") == "1":
    window_part()
else:
    background_part()
