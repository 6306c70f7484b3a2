"""The add-on's F12 render of the demo rig equals `snell render` of Blender's own glTF export.

Frames 1 and 20: the eyes turn on their bones (one bone per vertex, so glTF's
skinned normals are Blender's) and the pupils dilate by shape key. The
exporter writes frame f at f/24 s and lights in its 'COMPAT' units, the
add-on's own. Within 1/255 on at least 99% of pixels, in sRGB.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene, export_gltf, pixels, render_f12, snell, srgb  # noqa: E402

WIDTH, HEIGHT = 320, 134
SCRATCH.mkdir(parents=True, exist_ok=True)
scene, rig = demo_scene(WIDTH, HEIGHT)
import bpy  # noqa: E402

exported = export_gltf(SCRATCH / "rig.glb")
background = ",".join(f"{c:.6f}" for c in bpy.context.scene.world.node_tree.nodes["Background"].inputs["Color"]
                      .default_value[:3])

frames = {}
for frame in (1, 20):
    scene.frame_set(frame)
    ours = render_f12(SCRATCH / f"addon_{frame}.exr")
    snell("render", exported, "-o", SCRATCH / f"cli_{frame}.exr", "--size", f"{WIDTH}x{HEIGHT}",
          "--time", frame / 24, "--background", background, "--float")
    theirs = pixels(SCRATCH / f"cli_{frame}.exr")
    difference = np.abs(srgb(ours) - srgb(theirs)).max(axis=2)
    within = float((difference <= 1.0 / 255.0 + 1e-6).mean())
    print(f"frame {frame}: {within:.2%} of pixels within 1/255, largest difference {difference.max() * 255:.2f}/255")
    check(within >= 0.99, f"frame {frame}: the add-on's F12 matches snell render of the export on >= 99% of pixels")
    frames[frame] = srgb(ours)

# The pupil's refracted outline moved: the eyes turned and the pupils opened.
moved = np.abs(frames[1] - frames[20]).max(axis=2) > 16 / 255
check(moved.mean() > 0.02, f"the eyes changed between frames 1 and 20 ({moved.mean():.1%} of pixels)")
for side, columns in (("right", slice(0, WIDTH // 2)), ("left", slice(WIDTH // 2, WIDTH))):
    # The pupil seen through the cornea: the darkest pixels of each eye.
    centres = []
    for frame in (1, 20):
        dark = np.argwhere(frames[frame][:, columns].mean(axis=2) < 0.1)
        centres.append(dark.mean(axis=0))
    shift = float(np.linalg.norm(centres[1] - centres[0]))
    check(shift > 3.0, f"the {side} eye's pupil outline moved {shift:.1f} pixels between frames 1 and 20")
