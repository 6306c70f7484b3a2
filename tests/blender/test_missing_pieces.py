"""Without numpy, the snell module or a Vulkan device, the add-on explains itself and Blender carries on."""

import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, check, demo_scene, enable_addon  # noqa: E402

SCRATCH.mkdir(parents=True, exist_ok=True)
scene, _ = demo_scene(64, 32)
from snell_blender import runtime  # noqa: E402


def f12_error() -> str:
    """F12 with the add-on unable to draw: the error it reports, or '' when it rendered."""
    try:
        bpy.ops.render.render(write_still=False)
    except RuntimeError as error:  # what the engine reported, as Blender raises it to scripts
        return str(error)
    return ""


# No snell module: an import of it fails.
sys.modules["snell"] = None
runtime.retry()
problem = runtime.problem()
check(problem is not None and "snell Python module is not found" in problem,
      f"a missing module is named, with what to do: {problem}")
error = f12_error()
check("snell Python module is not found" in error, f"F12 reports the missing module: {error}")
del sys.modules["snell"]

# No numpy.
saved = sys.modules.pop("numpy")
sys.modules["numpy"] = None
runtime.retry()
problem = runtime.problem()
sys.modules["numpy"] = saved
check(problem is not None and "numpy" in problem, f"a missing numpy is named: {problem}")

# No Vulkan device that fits.
enable_addon()
bpy.context.preferences.addons["snell_blender"].preferences.device = "no-such-gpu"
runtime.retry()
problem = runtime.problem()
check(problem is not None and "no Vulkan device" in problem and "no-such-gpu" in problem,
      f"a device that is not there is named: {problem}")
check("no Vulkan device" in f12_error(), "F12 reports the missing device")

# With everything back, it renders.
bpy.context.preferences.addons["snell_blender"].preferences.device = ""
runtime.retry()
check(runtime.problem() is None and f12_error() == "", f"with every piece there, F12 renders ({runtime.status()})")

# A node snell does not read is named, with its material, in the console and in the panel's list; F12 still renders.
import contextlib  # noqa: E402
import io  # noqa: E402

sclera = bpy.data.materials["Sclera"]
nodes, links = sclera.node_tree.nodes, sclera.node_tree.links
veins = nodes.new("ShaderNodeTexNoise")
veins.name = "Veins"
bsdf = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
links.new(veins.outputs["Color"], bsdf.inputs["Base Color"])
skin = bpy.data.materials["Skin"]
wax = skin.node_tree.nodes.new("ShaderNodeSubsurfaceScattering")
wax.name = "Wax"
output = next(n for n in skin.node_tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
skin.node_tree.links.new(wax.outputs[0], output.inputs["Surface"])
console = io.StringIO()
with contextlib.redirect_stdout(console):
    error = f12_error()
check(error == "", f"F12 renders what it can ({error})")
for name, node, kind in (("Sclera", "Veins", "ShaderNodeTexNoise"), ("Skin", "Wax", "ShaderNodeSubsurfaceScattering")):
    named = f"material '{name}': node '{node}' ({kind})"
    check(named in console.getvalue(), f"the console names {named}")
    check(any(named in line for line in runtime.scene_problems()), f"the panel's list names {named}")
