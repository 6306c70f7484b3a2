"""snell's AOVs are render passes: off by default, on per view layer, in the compositor and multilayer EXRs.

The demo rig at 160x66, its face plate hidden: the values the engine hands
Blender's passes are checked against what the scene is, and the multilayer
EXR Blender writes is read back by OpenImageIO (Debian's python3, in a
process of its own: bpy carries an OpenImageIO of its own) for the passes'
channels. bpy 5.0 writes no pass beside Combined into a multilayer EXR from
the scene's output, Cycles' own Depth neither: there the file's part is
skipped, with a message, when a Cycles render shows the same.
"""

import json
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene  # noqa: E402

WIDTH, HEIGHT = 160, 66
PASSES = {"Depth": ["Z"], "Normal": ["X", "Y", "Z"], "snell Instance": ["X"], "snell Primitive": ["X"],
          "snell Interfaces": ["X"], "snell Cost": ["X"]}
SCRATCH.mkdir(parents=True, exist_ok=True)
scene, _ = demo_scene(WIDTH, HEIGHT)
bpy.data.objects["Face"].hide_render = True  # so that some pixels show nothing
layer = scene.view_layers[0]

READ = """
import json, sys
import OpenImageIO as oiio
image = oiio.ImageInput.open(sys.argv[1])
spec = image.spec()
pixels = image.read_image(oiio.FLOAT)
print(json.dumps({"channels": list(spec.channelnames), "pixels": pixels.tolist()}))
"""


def render_exr(name: str) -> dict:
    """F12 saved as a multilayer EXR, read back: channel name -> (height, width) array, row 0 at the top."""
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # 5.0 offers the multilayer format for that media type alone
        settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    bpy.ops.render.render(write_still=False)
    path = SCRATCH / f"{name}.exr"
    bpy.data.images["Render Result"].save_render(str(path))
    done = subprocess.run(["/usr/bin/python3", "-c", READ, str(path)], capture_output=True, text=True, timeout=120)
    if done.returncode != 0:
        raise AssertionError(f"reading {path} failed: {done.stderr}")
    found = json.loads(done.stdout)
    pixels = np.array(found["pixels"], np.float64)
    return {name: pixels[..., i] for i, name in enumerate(found["channels"])}


from snell_blender import compat  # noqa: E402  (demo_scene enabled the add-on)

written: dict = {}  # pass name -> the (pixels, channels) block the engine handed Blender, bottom row first
write_pass = compat.write_pass


def spy(render_pass, block) -> None:
    written[render_pass.name] = block.copy()
    write_pass(render_pass, block)


def blender_writes_passes() -> bool:
    """Whether this Blender's multilayer EXR from the scene's output carries passes: Cycles' Depth, say."""
    engine = scene.render.engine
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False  # Debian's 3.4 is built without OpenImageDenoise
    layer.use_pass_z = True
    planes = render_exr("cycles")
    layer.use_pass_z = False
    scene.render.engine = engine
    return any(key.endswith("Depth.Z") for key in planes)


def plane(name: str, channels: int) -> np.ndarray:
    """A pass's values as the engine wrote them: (height, width[, channels]), row 0 at the top."""
    block = written[name].reshape(HEIGHT, WIDTH, channels)[::-1]
    return block[..., 0] if channels == 1 else block


compat.write_pass = spy
# Off by default: the layer writes the combined image alone.
plain = render_exr("plain")
check(not any(name in key for key in plain for name in PASSES), f"no snell pass by default ({sorted(plain)})")
check(set(written) == {"Combined"}, f"the engine wrote the combined image alone ({sorted(written)})")

for option in ("depth", "normal", "instance", "primitive", "interfaces", "cost"):
    setattr(layer.snell, option, True)
written.clear()
planes = render_exr("passes")
check(set(written) == {"Combined"} | set(PASSES), f"the engine wrote every pass asked for ({sorted(written)})")
if blender_writes_passes():
    for render_pass, components in PASSES.items():
        for component in components:
            check(any(k.endswith(f"{render_pass}.{component}") for k in planes),
                  f"the EXR holds {render_pass}.{component}")
else:
    print(f"skipped: bpy {bpy.app.version_string} writes no pass beside Combined into the scene's multilayer EXR, "
          "Cycles' own Depth neither; the passes' values are checked as the engine hands them to Blender")

depth, instance = plane("Depth", 1), plane("snell Instance", 1)
hit = instance >= 0
check(hit.mean() > 0.2 and (~hit).any(), f"the instance pass marks what was hit ({hit.mean():.0%}) and -1 elsewhere")
check(np.all(depth[~hit] >= 1e9), "depth is Blender's 1e10 where nothing was hit")
# The camera is 11 units in front of the eyes (y = -11, the eyeballs' radius 1) and looks along +y.
check(np.all((depth[hit] > 9.0) & (depth[hit] < 12.0)), f"depth is the camera distance ({depth[hit].min():.2f} to "
                                                        f"{depth[hit].max():.2f})")
normal = plane("Normal", 3)
length = np.linalg.norm(normal[hit], axis=-1)
check(np.allclose(length, 1.0, atol=1e-3), "normals are unit length where something was hit")
# Where the eyes are nearest the camera their faces look back at it: Blender's -Y, not snell's Y-up -Z.
facing = normal[depth == depth[hit].min()][0]
check(facing[1] < -0.9, f"normals are in Blender's Z-up world, turned to the camera ({np.round(facing, 3)})")
interfaces = plane("snell Interfaces", 1)
check(interfaces.max() >= 1 and np.all(interfaces[~hit] == 0), "rays through the corneas count their interfaces")
check(np.all(plane("snell Cost", 1)[hit] > 0), "every traced pixel counts its cost")
primitive = plane("snell Primitive", 1)
check(np.all(primitive[hit] >= 0) and np.all(primitive[~hit] == -1), "primitive ids where hit, -1 elsewhere")

# The compositor sees the passes the layer asks for.
if hasattr(scene, "node_tree") and hasattr(scene, "use_nodes"):  # 5.0 moved the compositor to a node group
    scene.use_nodes = True
    tree = scene.node_tree
else:
    tree = bpy.data.node_groups.new("Compositing", "CompositorNodeTree")
    scene.compositing_node_group = tree
node = tree.nodes.new("CompositorNodeRLayers")
node.scene, node.layer = scene, layer.name
outputs = {o.name for o in node.outputs if o.enabled}
check(set(PASSES) <= outputs, f"the compositor's Render Layers node offers the passes ({sorted(outputs)})")
