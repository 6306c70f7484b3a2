# SPDX-License-Identifier: GPL-3.0-or-later
"""Seconds a frame of an F12 animation render of the demo rig: one scene for the job against one per frame.

    python tests/blender/run_in_bpy.py bench/blender_f12_animation.py -- \
        [--size 1920x1080] [--frames 12] [--json bench/results/blender-f12-animation-lavapipe.json]
    blender -b --factory-startup --python bench/blender_f12_animation.py -- [the same]

Renders frames 1..N of the demo rig (blender/demo_eye_rig.py) to PNG files
twice, alternating which goes first, and times each frame between Blender's
render_pre and render_post handlers:

  job     the add-on as it is: one scene sync for the whole job; after the
          first frame only the deformed vertices and moved transforms go
  each    the way it was before: the job ended after every frame, so each
          frame builds its scene anew (a full topology upload, every tree built)

It prints a table of medians (the first frame apart: both build there) and
writes every frame's seconds as JSON.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "blender"))
sys.path.insert(0, str(ROOT / "tests" / "blender"))
ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def option(name: str, default: str) -> str:
    return ARGS[ARGS.index(name) + 1] if name in ARGS else default


WIDTH, HEIGHT = (int(v) for v in option("--size", "1920x1080").split("x"))
FRAMES = int(option("--frames", "12"))
JSON = option("--json", "")
SCRATCH = Path("/tmp/snell_f12_animation")


def render_job(mode: str) -> list:
    """Seconds of each frame of one animation render in `mode` ('job' or 'each')."""
    from snell_blender import job

    scene = bpy.context.scene
    scene.render.filepath = str(SCRATCH / f"{mode}_####")
    started, seconds = {}, []

    def pre(*_):
        started["at"] = time.perf_counter()

    def post(*_):
        seconds.append(time.perf_counter() - started["at"])
        if mode == "each":
            job.end()  # the next frame builds its scene anew, as every frame did before the job kept one

    bpy.app.handlers.render_pre.append(pre)
    bpy.app.handlers.render_post.append(post)
    try:
        bpy.ops.render.render(animation=True)
    finally:
        bpy.app.handlers.render_pre.remove(pre)
        bpy.app.handlers.render_post.remove(post)
    return seconds


def main() -> None:
    from blender_support import demo_scene

    SCRATCH.mkdir(parents=True, exist_ok=True)
    scene, _ = demo_scene(WIDTH, HEIGHT)
    scene.frame_start, scene.frame_end = 1, FRAMES
    scene.render.image_settings.file_format = "PNG"
    from snell_blender import runtime

    runs = {"job": [], "each": []}
    for order in (("job", "each"), ("each", "job")):
        for mode in order:
            runs[mode].append(render_job(mode))
    later = {mode: [s for run in r for s in run[1:]] for mode, r in runs.items()}
    first = {mode: [run[0] for run in r] for mode, r in runs.items()}
    device = runtime.status()
    print(f"F12 animation of the demo rig, {WIDTH}x{HEIGHT}, frames 1-{FRAMES}, Blender {bpy.app.version_string}, "
          f"{device}; two renders of each, alternating; medians in seconds")
    print("| scene sync | first frame | later frames | frames a second (later) |")
    print("|---|---:|---:|---:|")
    for mode, label in (("each", "one per frame (before)"), ("job", "one for the job (now)")):
        median = statistics.median(later[mode])
        print(f"| {label} | {statistics.median(first[mode]):.3f} | {median:.3f} | {1.0 / median:.2f} |")
    print(f"later frames: {statistics.median(later['each']) / statistics.median(later['job']):.2f}x faster with one "
          "scene for the job")
    if JSON:
        Path(JSON).write_text(json.dumps({
            "scene": "blender/demo_eye_rig.py", "size": [WIDTH, HEIGHT], "frames": FRAMES,
            "blender": bpy.app.version_string, "device": device,
            "seconds": {mode: runs[mode] for mode in runs},
            "median_later_seconds": {mode: statistics.median(later[mode]) for mode in later},
            "median_first_seconds": {mode: statistics.median(first[mode]) for mode in first},
        }, indent=1) + "\n")


main()
