"""The extension zip that scripts/blender_extension writes installs with its wheels, enables and renders F12.

Run in bpy (4.2 and later) with BLENDER_USER_RESOURCES at a scratch folder,
so the install goes to a user repository of the test's own, and
SNELL_BLENDER_EXTENSION naming the zip. Blender's own tool validates it,
Blender's installer (Install from Disk: the bpy twin of `blender --command
extension install-file`) installs and enables it, which installs the wheel of
this Blender's Python; with no module folder set, the add-on finds snell in
that wheel. F12 draws a textured sphere through it, and the wheel's own
glTF and PNG decoding (tinygltf and stb, compiled into its libsnell) loads
Blender's glTF export of the same scene. Blender 3.4 has no extensions:
there the add-on is a legacy one (bl_info), and this test says so and passes.
"""

import importlib
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, pixels  # noqa: E402

if bpy.app.version < (4, 2, 0):
    print(f"skipped: Blender {bpy.app.version_string} has no extensions (they came in 4.2); bl_info serves it")
    raise SystemExit(0)

RED = (0.8, 0.05, 0.05)
SCRATCH.mkdir(parents=True, exist_ok=True)
package = Path(os.environ.get("SNELL_BLENDER_EXTENSION", ""))
check(package.is_file(), f"the extension zip is there ({package}; scripts/blender_extension writes it)")
tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
with zipfile.ZipFile(package) as archive:
    manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
    names = set(archive.namelist())
print(f"the package's wheels: {manifest.get('wheels')}, platforms: {manifest.get('platforms')}")
check(manifest.get("platforms") == ["linux-x64"] and all(w[2:] in names for w in manifest.get("wheels", [])),
      "its manifest names its platform and the wheels it holds")
check(any(f"-{tag}-{tag}-" in w for w in manifest["wheels"]),
      f"it holds a wheel for this Blender's Python ({tag}, Blender {bpy.app.version_string})")

tool = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
validated = subprocess.run([sys.executable, str(tool), "validate", str(package)], capture_output=True, text=True)
check(validated.returncode == 0 and "Success" in validated.stdout,
      f"Blender's own extension tool validates the package ({validated.stdout.strip()} {validated.stderr.strip()})")

check(importlib.util.find_spec("snell") is None, "before the install this Python has no snell module")
bpy.ops.extensions.package_install_files(filepath=str(package), repo="user_default", enable_on_install=True)
module = "bl_ext.user_default.snell_blender"
check(module in bpy.context.preferences.addons, f"Blender's installer installs and enables it as {module}")
prefs = bpy.context.preferences.addons[module].preferences
check(prefs.module_path == "", "no module folder is set")
runtime = sys.modules[module + ".runtime"]
runtime.retry()
check(runtime.device() is not None, f"the add-on finds snell in the extension's wheel ({runtime.status()})")
import snell  # noqa: E402  (the wheel's, installed above)

site = Path(bpy.utils.user_resource("EXTENSIONS", path=".local"))
check(Path(snell.__file__).resolve().is_relative_to(site.resolve()),
      f"the module is the wheel's, installed under the extensions' {site} ({snell.__file__})")

# A sphere whose colour is an image, in front of the camera, alone (the factory scene's cube would hide it).
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
bpy.ops.mesh.primitive_uv_sphere_add()
image = bpy.data.images.new("red", 8, 8)
image.pixels.foreach_set(np.tile([*RED, 1.0], 64).astype(np.float32))
image.pack()
material = bpy.data.materials.new("painted")
material.use_nodes = True
texture = material.node_tree.nodes.new("ShaderNodeTexImage")
texture.image = image
material.node_tree.links.new(texture.outputs["Color"], material.node_tree.nodes["Principled BSDF"].inputs[0])
bpy.context.object.data.materials.append(material)
scene = bpy.context.scene
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
camera.location, camera.rotation_euler = (0, -5, 0), (1.5708, 0, 0)
scene.collection.objects.link(camera)
scene.camera = camera
scene.render.engine = "SNELL"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 64, 48, 100
scene.render.image_settings.file_format = "OPEN_EXR"
bpy.ops.render.render(write_still=False)
bpy.data.images["Render Result"].save_render(str(SCRATCH / "extension.exr"))
drawn = pixels(SCRATCH / "extension.exr")
centre, corner = drawn[24, 32, :3], drawn[2, 2, :3]
check(centre[0] > 2 * max(centre[1], centre[2]) and np.abs(centre - corner).max() > 0.05,
      f"F12 renders the red sphere through the extension (centre {centre.round(3)}, corner {corner.round(3)})")

exported = SCRATCH / "sphere.glb"
bpy.ops.export_scene.gltf(filepath=str(exported), export_format="GLB", export_cameras=True)
with snell.Scene.load(str(exported)) as loaded, snell.Renderer(runtime.device(), loaded) as renderer:
    picture = renderer.render(snell.View(64, 48, camera=0))
centre = picture[24, 32, :3]
check(centre[0] > 2 * max(centre[1], centre[2]),
      f"the wheel's module loads Blender's glTF export, its PNG decoded, and draws it red ({centre.round(3)})")
