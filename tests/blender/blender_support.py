"""Shared by the add-on's tests, which run inside Blender (tests/CMakeLists.txt starts them).

ctest sets SNELL_BINARY (the command line), SNELL_PYTHON_DIR (the built
module's folder, for Blender's CPython 3.11; empty in bpy 5.1 and later,
whose 3.13 takes the extension's own wheel from SNELL_BLENDER_EXTENSION) and
SNELL_TEST_DIR (a scratch folder of the test's own).
"""

from __future__ import annotations

import io
import math
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import bpy
import numpy as np

SOURCE = Path(__file__).resolve().parents[2]
SCRATCH = Path(os.environ.get("SNELL_TEST_DIR", "/tmp/snell_blender_test"))
SNELL = os.environ.get("SNELL_BINARY", str(SOURCE / "build" / "release" / "snell"))
sys.path.insert(0, str(SOURCE / "blender"))

import demo_eye_rig  # noqa: E402  (from the checkout's blender/ folder, put on the path above)


def surface_material(name: str, node_type: str, **inputs):
    """A material whose Surface is one node of `node_type` (the Principled BSDF taken out), with `inputs` (by
    socket name) set; returns the material and the node."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    node = nodes.new(node_type)
    for socket, value in inputs.items():
        node.inputs[socket].default_value = value
    material.node_tree.links.new(node.outputs[0], nodes["Material Output"].inputs["Surface"])
    return material, node


def module_folder() -> str:
    """The snell module's folder: the build's, or where the build's is not for this Python, the wheel of this
    Python from the extension zip, unpacked into the scratch folder."""
    folder = os.environ.get("SNELL_PYTHON_DIR", "")
    package = os.environ.get("SNELL_BLENDER_EXTENSION", "")
    if folder or not package:
        return folder
    tag = f"-cp{sys.version_info.major}{sys.version_info.minor}-"
    target = SCRATCH / "python"
    if target.exists():  # once: rewriting a library this process has loaded would pull code from under it
        return str(target)
    with zipfile.ZipFile(package) as archive:
        wheel = next(name for name in archive.namelist() if name.endswith(".whl") and tag in name)
        with zipfile.ZipFile(io.BytesIO(archive.read(wheel))) as inner:
            inner.extractall(target)
    return str(target)


def enable_addon(module_path: str | None = None) -> None:
    """The add-on from the checkout, with the snell module from the build (or `module_path`)."""
    import addon_utils

    addon_utils.enable("snell_blender", default_set=True)
    prefs = bpy.context.preferences.addons["snell_blender"].preferences
    prefs.module_path = module_path if module_path is not None else module_folder()
    from snell_blender import runtime

    runtime.retry()


def demo_scene(width: int, height: int):
    """The demo rig in the current scene, rendered by snell at width x height."""
    enable_addon()
    rig = demo_eye_rig.build()
    scene = bpy.context.scene
    scene.render.engine = "SNELL"
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.dither_intensity = 0.0
    return scene, rig


def cycles_comparison(scene, width: int, height: int, samples: int, background: float) -> None:
    """What the tests against Cycles share: a camera at (0, -6, 0) looking down +Y, a world of one grey, a
    width x height film in the 'Standard' view, snell's Fresnel off, and Cycles with `samples` a pixel, a
    one-pixel box filter, no denoising, no caustics and a fixed seed."""
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location, camera.rotation_euler = (0, -6.0, 0), (math.radians(90), 0, 0)
    camera.data.lens = 50.0
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (background, background, background, 1)
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = width, height, 100
    scene.view_settings.view_transform = "Standard"
    scene.snell.fresnel = False
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.cycles.caustics_reflective = scene.cycles.caustics_refractive = False
    scene.cycles.seed = 1


def export_gltf(path: Path) -> Path:
    """Blender's own glTF export of the scene (GLB, cameras, lights, animations), lights in its 'COMPAT'
    (unitless) units, the add-on's own; 4.2 renamed that option, so it is found by either name."""
    options = bpy.ops.export_scene.gltf.get_rna_type().properties.keys()
    names = ("export_import_convert_lighting_mode", "convert_lighting_mode")
    lighting = next(name for name in names if name in options)
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_cameras=True, export_lights=True,
                              export_animations=True, **{lighting: "COMPAT"})
    return path


def pixels(path: Path) -> np.ndarray:
    """An image file as Blender reads it: (height, width, 4) floats, row 0 at the top."""
    image = bpy.data.images.load(str(path), check_existing=False)
    width, height = image.size
    values = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(values)
    bpy.data.images.remove(image)
    return values.reshape(height, width, 4)[::-1]


def srgb(linear: np.ndarray) -> np.ndarray:
    """Linear RGB to sRGB-encoded values in [0, 1] (what a display shows)."""
    c = np.clip(linear[..., :3].astype(np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def render_f12(path: Path) -> np.ndarray:
    """F12 at the scene's current frame, saved as a 32-bit EXR (linear) and read back."""
    scene = bpy.context.scene
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.ops.render.render(write_still=False)
    bpy.data.images["Render Result"].save_render(str(path))
    return pixels(path)


def snell(*args) -> None:
    """Runs snell's command line; a failure fails the test with its message."""
    done = subprocess.run([SNELL, "--quiet", *map(str, args)], capture_output=True, text=True, timeout=300)
    if done.returncode != 0:
        raise AssertionError(f"snell {' '.join(map(str, args))} exited {done.returncode}: {done.stderr}")


def check(condition: bool, message: str) -> None:
    """Fails the test (the script's exception makes Blender exit 1) unless `condition`."""
    print(("ok: " if condition else "FAILED: ") + message, flush=True)
    if not condition:
        raise AssertionError(message)
