# SPDX-License-Identifier: GPL-3.0-or-later
"""Per-frame cost of snell's Rendered viewport inside Blender, on the demo eye rig.

    blender -b --factory-startup --python bench/blender_viewport.py -- \
        [--size 1920x1080] [--frames 24] [--json bench/results/blender-viewport-lavapipe.json]

Run in the background, it saves the demo rig and opens it in a windowed
Blender on a private X server (xvfb-run), whose one 3D viewport fills the
window, in Rendered shading through the camera. Then, for each display path
(OpenGL interop, pixel upload), it steps the animation one frame at a time
and redraws synchronously, timing:

  evaluate  Blender's own depsgraph evaluation of the frame (armature, shape keys)
  feed      the add-on's view_update: evaluated vertices into snell's mapped memory
  render    snell's frame (copy, refit, top level, raster, masked trace) and the
            image's way to OpenGL (interop: a wait; upload: readback and texture)
  gpu       snell's own pass times within render
  blit      drawing the texture through Blender's colour management

It prints a table of medians and writes them, with every frame's figures, as JSON.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "blender"))
ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def option(name: str, default: str) -> str:
    return ARGS[ARGS.index(name) + 1] if name in ARGS else default


WIDTH, HEIGHT = (int(v) for v in option("--size", "1920x1080").split("x"))
FRAMES = int(option("--frames", "24"))
JSON = option("--json", "")
SCRATCH = Path(os.environ.get("SNELL_BENCH_DIR", "/tmp/snell_blender_bench"))
RESULT = SCRATCH / "result.json"


def background_part() -> None:
    import demo_eye_rig

    SCRATCH.mkdir(parents=True, exist_ok=True)
    demo_eye_rig.enable_addon()
    demo_eye_rig.build()
    bpy.context.scene.render.engine = "SNELL"
    blend = SCRATCH / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    RESULT.unlink(missing_ok=True)
    screen = f"-screen 0 {WIDTH}x{HEIGHT}x24"
    environment = dict(os.environ, SNELL_BENCH_WINDOW="1", LP_NUM_THREADS=os.environ.get("LP_NUM_THREADS", "2"))
    command = ["xvfb-run", "-a", "-s", screen, bpy.app.binary_path, "--factory-startup", "--window-geometry", "0",
               "0", str(WIDTH), str(HEIGHT), str(blend), "--python", __file__, "--", *ARGS]
    done = subprocess.run(command, env=environment, timeout=1800, capture_output=True, text=True)
    if not RESULT.exists():
        print(done.stdout[-3000:], done.stderr[-3000:], sep="\n")
        raise SystemExit(f"the windowed Blender exited {done.returncode} without results")
    report = json.loads(RESULT.read_text())
    report["command"] = "blender -b --factory-startup --python bench/blender_viewport.py -- " + " ".join(ARGS)
    print(f"snell's Rendered viewport in Blender {bpy.app.version_string}, demo eye rig, "
          f"region {report['region'][0]}x{report['region'][1]}, {report['device']}, medians of {FRAMES} frames (ms)")
    columns = ("evaluate", "feed", "render", "gpu", "blit", "total")
    print(f"{'display path':44s}" + "".join(f"{c:>10s}" for c in columns))
    for path in report["paths"]:
        print(f"{path['path']:44s}" + "".join(f"{path['median_ms'][c]:10.2f}" for c in columns))
    if JSON:
        Path(JSON).write_text(json.dumps(report, indent=1) + "\n")
        print(f"wrote {JSON}")


def window_part() -> None:
    import demo_eye_rig

    demo_eye_rig.enable_addon()
    bpy.context.scene.render.engine = "SNELL"
    from snell_blender import engine, runtime

    report = {"blender": bpy.app.version_string, "frames": FRAMES, "paths": []}

    def viewport():
        window = bpy.context.window_manager.windows[0]
        area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
        return window, area, next(r for r in area.regions if r.type == "WINDOW")

    def start():
        window, area, region = viewport()
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screen_full_area(use_hide_panels=True)
        bpy.app.timers.register(measure, first_interval=1.0)

    def measure():
        try:
            window, area, region = viewport()
            space = area.spaces.active
            space.shading.type = "RENDERED"
            space.overlay.show_overlays = False
            space.region_3d.view_perspective = "CAMERA"
            scene = bpy.context.scene
            report["region"] = [region.width, region.height]
            report["device"] = runtime.device().name

            def redraw() -> None:
                with bpy.context.temp_override(window=window, area=area, region=region):
                    bpy.ops.wm.redraw_timer(type="DRAW", iterations=1)

            for display in ("AUTO", "UPLOAD"):
                scene.snell.display = display
                scene.frame_set(scene.frame_start)
                for _ in range(3):  # warm: pipelines, the first build, textures at this size
                    redraw()
                rows = []
                for step in range(FRAMES):
                    frame = scene.frame_start + 1 + step % (scene.frame_end - scene.frame_start)
                    started = time.perf_counter()
                    scene.frame_set(frame)
                    evaluated = time.perf_counter()
                    redraw()
                    s = engine.STATS
                    rows.append({"frame": frame, "evaluate": (evaluated - started) * 1000, "feed": s["feed_ms"],
                                 "render": s["render_ms"], "gpu": s["gpu_ms"], "blit": s["blit_ms"],
                                 "total": (evaluated - started) * 1000 + s["feed_ms"] + s["draw_ms"],
                                 "meshes_sent": len(s["meshes_sent"]), "pass_ms": s["frame"]["pass_ms"]})
                report["paths"].append({
                    "path": engine.STATS["draw_path"],
                    "median_ms": {k: statistics.median(r[k] for r in rows)
                                  for k in ("evaluate", "feed", "render", "gpu", "blit", "total")},
                    "frames": rows})
        except Exception as error:
            import traceback

            traceback.print_exc()
            report["error"] = repr(error)
        RESULT.write_text(json.dumps(report))
        bpy.ops.wm.quit_blender()

    bpy.app.timers.register(start, first_interval=1.0)


if os.environ.get("SNELL_BENCH_WINDOW") == "1":
    window_part()
else:
    background_part()
