# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's feed of a subdivided, deforming character: Blender's CPU modifier against the cage plus snell's GPU.

    python bench/blender_subdivision_feed.py [--frames N] [--json FILE]   # with bpy (PyPI's Blender module)
    blender -b --factory-startup --python bench/blender_subdivision_feed.py -- [--frames N] [--json FILE]

The character: a UV sphere of 32 x 16 faces (an eyeball's cage) with an
animated shape key and a Simple Deform twist, then a Subdivision Surface of
render level 2 (the levels the viewport and F12 use), in front of a card.
Each frame Blender evaluates the depsgraph (frame_set) and the add-on sends
what changed (SceneSync.send_changed), then snell draws a 320x240 frame:

- "blender": the object's "Subdivide on the GPU" off: Blender subdivides on
  the CPU, and the add-on reads and sends the subdivided mesh;
- "snell": on: Blender leaves its last modifier undone (it is the last one),
  the add-on reads and sends the cage, and snell refines it on the GPU.

Both run in one process, alternately, frame for frame; the table gives the
median milliseconds of the host's part (frame_set, the feed) and of snell's
GPU refine pass. Host times are this machine's CPU; GPU times are the
device's (lavapipe's are CPU time too, and count only beside each other).
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "blender"))
sys.path.insert(0, str(ROOT / "tests" / "blender"))
ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]

import bpy  # noqa: E402
import numpy as np  # noqa: E402


def option(name: str, default: str) -> str:
    return ARGS[ARGS.index(name) + 1] if name in ARGS else default


FRAMES = int(option("--frames", "24"))
JSON = option("--json", "")


def build():
    from blender_support import enable_addon

    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    scene = bpy.context.scene
    scene.render.engine = "SNELL"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 320, 240, 100
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0)
    eye = bpy.context.object
    for polygon in eye.data.polygons:
        polygon.use_smooth = True
    eye.shape_key_add(name="Basis")
    squash = eye.shape_key_add(name="Squash")
    for point in squash.data:
        point.co.z *= 0.7
    squash.value = 0.0
    squash.keyframe_insert("value", frame=1)
    squash.value = 1.0
    squash.keyframe_insert("value", frame=FRAMES)
    twist = eye.modifiers.new("Twist", "SIMPLE_DEFORM")
    twist.deform_method = "TWIST"
    twist.angle = math.radians(20)
    subsurf = eye.modifiers.new("Subdivision", "SUBSURF")
    subsurf.levels = subsurf.render_levels = 2
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location, camera.rotation_euler = (0, -5.0, 0), (math.radians(90), 0, 0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.frame_start, scene.frame_end = 1, FRAMES
    return scene, eye


def main() -> int:
    scene, eye = build()
    from snell_blender import runtime
    from snell_blender.sync import SceneSync

    if runtime.device() is None:  # the add-on finds the snell module, and puts it on the path
        print(f"blender_subdivision_feed: {runtime.problem()}", file=sys.stderr)
        return 1
    import snell

    view = snell.View(320, 240, eye=(0, -5, 0), target=(0, 0, 0), up=(0, 0, 1))
    syncs = {}
    for mode, on in (("blender", False), ("snell", True)):
        eye.snell.gpu_subdivision = on
        scene.frame_set(1)
        syncs[mode] = SceneSync(runtime.device(), bpy.context.evaluated_depsgraph_get())
        syncs[mode].renderer.render(view)
    times = {mode: {"frame_set_ms": [], "feed_ms": [], "refine_ms": [], "vertices_sent": 0} for mode in syncs}
    for frame in range(2, FRAMES + 1):
        for mode in (("blender", "snell") if frame % 2 else ("snell", "blender")):
            eye.snell.gpu_subdivision = mode == "snell"
            started = time.perf_counter()
            scene.frame_set(frame)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            evaluated = time.perf_counter()
            sync = syncs[mode]
            sync.send_changed(depsgraph)
            fed = time.perf_counter()
            sync.renderer.render(view)
            info = sync.renderer.last_frame()
            t = times[mode]
            t["frame_set_ms"].append((evaluated - started) * 1000)
            t["feed_ms"].append((fed - evaluated) * 1000)
            t["refine_ms"].append(info["pass_ms"].get("refine", 0.0))
            t["vertices_sent"] = sum(sync.scene.vertex_count(p.mesh) for g in sync.geometry.values() for p in g.parts
                                     if g.name == eye.name)
    device = runtime.device().name
    print(f"device: {device}; Blender {bpy.app.version_string}; {FRAMES - 1} frames each, alternately")
    print(f"{'feed':<9} {'vertices sent':>14} {'frame_set ms':>13} {'feed ms':>9} {'host ms':>9} {'GPU refine ms':>14}")
    rows = {}
    for mode, t in times.items():
        host = np.median(np.array(t["frame_set_ms"]) + np.array(t["feed_ms"]))
        rows[mode] = {"vertices_sent": t["vertices_sent"], "frame_set_ms": float(np.median(t["frame_set_ms"])),
                      "feed_ms": float(np.median(t["feed_ms"])), "host_ms": float(host),
                      "refine_ms": float(np.median(t["refine_ms"]))}
        r = rows[mode]
        print(f"{mode:<9} {r['vertices_sent']:>14} {r['frame_set_ms']:>13.2f} {r['feed_ms']:>9.2f} {r['host_ms']:>9.2f} "
              f"{r['refine_ms']:>14.3f}")
    print(f"host time, Blender's subdivision over snell's: {rows['blender']['host_ms'] / rows['snell']['host_ms']:.2f}x")
    if JSON:
        Path(JSON).write_text(json.dumps({"bench": "blender-subdivision-feed", "device": device,
                                          "blender": bpy.app.version_string, "frames": FRAMES - 1, "rows": rows},
                                         indent=2) + "\n")
    for sync in syncs.values():
        sync.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
