"""The add-on is a Blender 4.2+ Extension: its manifest validates, it builds, installs, enables and renders F12.

Run in bpy (4.2 and later) with BLENDER_USER_RESOURCES at a scratch folder,
so the install goes to a user repository of the test's own. Blender 3.4 has
no extensions: there the add-on is a legacy one (bl_info), and this test
says so and passes.
"""

import subprocess
import sys
import zipfile
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, SOURCE, check  # noqa: E402

if bpy.app.version < (4, 2, 0):
    print(f"skipped: Blender {bpy.app.version_string} has no extensions (they came in 4.2); bl_info serves it")
    raise SystemExit(0)

SCRATCH.mkdir(parents=True, exist_ok=True)
tool = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
source = SOURCE / "blender" / "snell_blender"
validated = subprocess.run([sys.executable, str(tool), "validate", str(source)], capture_output=True, text=True)
check(validated.returncode == 0 and "Success" in validated.stdout,
      f"Blender's own extension tool validates the manifest ({validated.stdout.strip()} {validated.stderr.strip()})")
built = subprocess.run([sys.executable, str(tool), "build", "--source-dir", str(source), "--output-dir", str(SCRATCH)],
                       capture_output=True, text=True)
package = SCRATCH / "snell_blender-0.1.0.zip"
check(built.returncode == 0 and package.exists(), f"it builds a package ({built.stdout.strip()[-200:]})")
with zipfile.ZipFile(package) as archive:
    names = set(archive.namelist())
check({"blender_manifest.toml", "__init__.py", "compat.py", "LICENSE"} <= names,
      f"the package holds the add-on ({sorted(names)[:6]} ...)")

# Installed by hand into the user repository, as Blender's installer would unpack it, then enabled as an extension.
repository = Path(bpy.utils.user_resource("EXTENSIONS", path="user_default", create=True))
with zipfile.ZipFile(package) as archive:
    archive.extractall(repository / "snell_blender")
bpy.ops.extensions.repo_refresh_all()
import addon_utils  # noqa: E402

module = "bl_ext.user_default.snell_blender"
addon_utils.enable(module, default_set=True)
check(module in bpy.context.preferences.addons, f"it is enabled as {module}")
prefs = bpy.context.preferences.addons[module].preferences
import os  # noqa: E402

prefs.module_path = os.environ.get("SNELL_PYTHON_DIR", "")
runtime = sys.modules[module + ".runtime"]
runtime.retry()
check(runtime.device() is not None, f"the extension finds snell through its own preferences ({runtime.status()})")

bpy.ops.mesh.primitive_uv_sphere_add()
scene = bpy.context.scene
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
camera.location, camera.rotation_euler = (0, -5, 0), (1.5708, 0, 0)
scene.collection.objects.link(camera)
scene.camera = camera
scene.render.engine = "SNELL"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 64, 48, 100
bpy.ops.render.render(write_still=False)
bpy.data.images["Render Result"].save_render(str(SCRATCH / "extension.png"))
check((SCRATCH / "extension.png").stat().st_size > 100, "F12 renders through the extension")
