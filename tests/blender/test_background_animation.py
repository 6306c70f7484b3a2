"""A farm's use: `blender -b shot.blend -a` renders the frames with snell, the add-on and module installed.

The add-on is linked into a user scripts folder (BLENDER_USER_SCRIPTS) and
enabled with --addons; the module comes from PYTHONPATH, which Blender reads
with --python-use-system-env: as on a node where both are installed.
"""

import os
import subprocess
import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, SOURCE, check, demo_scene, pixels  # noqa: E402

SCRATCH.mkdir(parents=True, exist_ok=True)
scene, _ = demo_scene(96, 40)
scene.frame_start, scene.frame_end = 1, 3
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = str(SCRATCH / "frame_####")
shot = SCRATCH / "shot.blend"
bpy.ops.wm.save_as_mainfile(filepath=str(shot))

addons = SCRATCH / "scripts" / "addons"
addons.mkdir(parents=True, exist_ok=True)
link = addons / "snell_blender"
if not link.exists():
    link.symlink_to(SOURCE / "blender" / "snell_blender")
environment = dict(os.environ, BLENDER_USER_SCRIPTS=str(SCRATCH / "scripts"),
                   PYTHONPATH=os.environ.get("SNELL_PYTHON_DIR", ""))
for frame in range(1, 4):
    (SCRATCH / f"frame_{frame:04d}.png").unlink(missing_ok=True)
# The add-on first, so the file's render engine exists when the file loads.
done = subprocess.run([bpy.app.binary_path, "-b", "--python-use-system-env", "--addons", "snell_blender", str(shot),
                       "-a"], env=environment, capture_output=True, text=True, timeout=240)
print(done.stdout[-3000:], done.stderr[-2000:], sep="\n")
check(done.returncode == 0, f"blender -b -a exited {done.returncode}")
check("snell:" not in done.stdout + done.stderr and "not available" not in done.stdout + done.stderr,
      "the file's engine was there and the add-on reported no problem")
images = [pixels(SCRATCH / f"frame_{frame:04d}.png") for frame in range(1, 4)]
check(all(image.shape == (40, 96, 4) for image in images), "every frame of the range was written")
check(all(image[..., :3].std() > 0.05 for image in images), "every frame shows the eyes, not a blank image")
# The farm's frame is the add-on's own F12 of that frame, pixel for pixel.
scene.frame_set(1)
bpy.ops.render.render(write_still=False)
bpy.data.images["Render Result"].save_render(str(SCRATCH / "here_0001.png"))
here = pixels(SCRATCH / "here_0001.png")
check(abs(here - images[0]).max() <= 1 / 255 + 1e-6, "frame 1 from the farm's command equals this session's F12")
