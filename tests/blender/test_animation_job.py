"""An animation render of the deforming rig keeps one scene for the job, sends only what moved, reports
progress, stops at Esc without writing the frame under way, and lets go of everything when a frame raises.

Frames 1-20 of the demo rig at 96x40. Esc's stand-in is the engine's
test_break turning true inside frame 12 (after the frame's work began); a
real Esc also makes Blender stop the job, while with the stand-in Blender
goes on asking for frames 13-20, which the engine drops at once.
"""

import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene, pixels  # noqa: E402

DEFORMING = {"Eyeball.L", "Eyeball.R", "Iris.L", "Iris.R"}
ESC_FRAME = 12
SCRATCH.mkdir(parents=True, exist_ok=True)
scene, _ = demo_scene(96, 40)
scene.frame_start, scene.frame_end = 1, 20
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = str(SCRATCH / "anim_####")
for frame in range(1, 21):
    (SCRATCH / f"anim_{frame:04d}.png").unlink(missing_ok=True)

from snell_blender import engine, job  # noqa: E402  (demo_scene enabled the add-on)

progress: dict = {}   # frame -> the fractions the progress bar was given
stats: dict = {}      # frame -> the status lines
asked: dict = {}      # frame -> times the engine asked whether Esc was pressed
escape_pressed, report_progress = engine.escape_pressed, engine.report_progress


def esc_in_frame_12(renderer) -> bool:
    frame = bpy.context.scene.frame_current
    asked[frame] = asked.get(frame, 0) + 1
    return frame > ESC_FRAME or (frame == ESC_FRAME and asked[frame] > 2)


def recorded(renderer, fraction, status) -> None:
    frame = bpy.context.scene.frame_current
    if fraction is not None:
        progress.setdefault(frame, []).append(fraction)
    stats.setdefault(frame, []).append(status)
    report_progress(renderer, fraction, status)


engine.escape_pressed, engine.report_progress = esc_in_frame_12, recorded
bpy.ops.render.render(animation=True)
done = job.finished
check(done is not None and job.last_stats() is None, "the job ended with the render and holds nothing since")
check(done.frames == ESC_FRAME - 1, f"frames 1-{ESC_FRAME - 1} were rendered ({done.frames})")
check(done.dropped == 20 - ESC_FRAME + 1, f"frame {ESC_FRAME}, stopped part way, and the later ones were dropped "
                                          f"({done.dropped})")
check(done.rebuilds == 1, f"one scene served the whole job ({done.rebuilds} built)")
check(set(done.sent[1]) >= DEFORMING | {"Face"}, f"the first frame sent every mesh ({done.sent[1]})")
later = [set(done.sent[f]) for f in range(2, ESC_FRAME)]
check(all(sent and sent <= DEFORMING for sent in later),
      f"after it, each frame sent only deformed meshes ({[sorted(s) for s in later][:3]} ...)")
for frame in range(1, ESC_FRAME):
    values = progress.get(frame, [])
    check(values and values[-1] == 1.0 and all(b >= a for a, b in zip(values, values[1:])),
          f"frame {frame}'s progress rose to 1 ({len(values)} steps)")
check(any("Frame 5 (5 of 20)" in line for line in stats[5]), f"the status line names the frame ({stats[5][-1]})")
check(ESC_FRAME in asked and 1.0 not in progress.get(ESC_FRAME, []), f"frame {ESC_FRAME} was stopped before its end")
check(any("stopped" in line for line in stats[ESC_FRAME]), f"the status line says so ({stats[ESC_FRAME][-1]})")

# The frames written are the rig's, each equal to a still F12 of that frame.
images = {f: pixels(SCRATCH / f"anim_{f:04d}.png") for f in range(1, ESC_FRAME)}
check(all(img[..., :3].std() > 0.05 for img in images.values()), "every frame written shows the eyes")
check(np.abs(images[1] - images[11]).max() > 0.2, "the eyes moved between frames 1 and 11")
engine.escape_pressed = escape_pressed
scene.frame_set(7)
bpy.ops.render.render(write_still=False)
bpy.data.images["Render Result"].save_render(str(SCRATCH / "still_0007.png"))
check(np.abs(pixels(SCRATCH / "still_0007.png") - images[7]).max() <= 1 / 255 + 1e-6,
      "frame 7 of the job equals a still F12 of frame 7")

# A frame that raises: the engine says what failed, the job lets go, and the next render works.
from snell_blender import sync  # noqa: E402

send_changed = sync.SceneSync.send_changed
failures = {"left": 1}


def failing(self, *args, **kwargs):
    if failures["left"]:
        failures["left"] -= 1
        raise RuntimeError("a stand-in failure")
    return send_changed(self, *args, **kwargs)


sync.SceneSync.send_changed = failing
scene.frame_start, scene.frame_end = 1, 3
scene.render.filepath = str(SCRATCH / "again_####")
try:
    bpy.ops.render.render(animation=True)
    reported = ""
except RuntimeError as error:  # what the engine reported, as Blender raises it to scripts
    reported = str(error)
check("snell: a stand-in failure" in reported, f"the failure is reported, named ({reported.strip()})")
check(job.last_stats() is None, "after a frame raised, the job holds nothing")
check(job.finished is not None and job.finished.frames == 1,
      f"the frame before the failure was rendered, the failed one not ({job.finished.frames})")
bpy.ops.render.render(write_still=False)
check(job.finished.frames == 1 and job.finished.rebuilds == 1, "the next render builds afresh and renders")
