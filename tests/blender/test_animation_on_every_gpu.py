"""snell: Render Animation draws the rig's frames on two workers and writes the files Blender's own
animation render writes for them; with the preference off, Ctrl+F12 stays Blender's own.

Frames 1-6 of the demo rig at 96x40, as PNG, through Blender's colour
management; the two workers are lavapipe twice ("0,0"), as two GPUs would be.
"""

import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene, pixels  # noqa: E402

FRAMES = range(1, 7)
SCRATCH.mkdir(parents=True, exist_ok=True)
scene, _ = demo_scene(96, 40)
scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
scene.frame_set(3)
scene.render.image_settings.file_format = "PNG"
for name in ("blender", "shot"):
    for frame in FRAMES:
        (SCRATCH / f"{name}_{frame:04d}.png").unlink(missing_ok=True)

from snell_blender import shot  # noqa: E402  (demo_scene enabled the add-on)

scene.render.filepath = str(SCRATCH / "blender_####")
bpy.ops.render.render(animation=True)
scene.render.filepath = str(SCRATCH / "shot_####")
check(bpy.ops.snell.render_animation(devices="0,0") == {"FINISHED"}, "the shot finished")
check(scene.frame_current == 3, f"the scene is back at its frame ({scene.frame_current})")
workers = shot.last["workers"]
check(len(workers) == 2 and all(w["frames"] > 0 for w in workers) and sum(w["frames"] for w in workers) == 6,
      f"both workers drew frames ({[w['frames'] for w in workers]})")

for frame in FRAMES:
    own, drawn = pixels(SCRATCH / f"blender_{frame:04d}.png"), pixels(SCRATCH / f"shot_{frame:04d}.png")
    check(np.abs(own - drawn).max() <= 1 / 255 + 1e-6,
          f"frame {frame} is the file Blender's animation render wrote (max {np.abs(own - drawn).max() * 255:.1f}/255)")
first, last = pixels(SCRATCH / "shot_0001.png"), pixels(SCRATCH / "shot_0006.png")
check(first[..., :3].std() > 0.05 and np.abs(first - last).max() > 0.1, "the frames show the eyes, moving")

prefs = bpy.context.preferences.addons["snell_blender"].preferences
check(not prefs.every_gpu and shot.devices_for(bpy.context) == ("", prefs.device),
      "by default the shot draws on the add-on's one device")
prefs.every_gpu = True
check(shot.devices_for(bpy.context) == ("all", ""), "with the preference on, on every GPU")
prefs.every_gpu = False
