"""A Principled glass with volume absorption: Blender's glTF exporter writes transmission, IOR and
volume, snell loads the same values, and the add-on maps the material to those values too."""

import json
import subprocess
import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, SNELL, check, enable_addon  # noqa: E402
from snell_blender import compat  # noqa: E402  (blender_support puts the add-on on the path)

TRANSMISSION, IOR, ROUGHNESS = 1.0, 1.45, 0.1
ATTENUATION, DENSITY, THICKNESS = (0.8, 0.5, 0.3), 2.0, 0.25

SCRATCH.mkdir(parents=True, exist_ok=True)
enable_addon()
for obj in list(bpy.context.scene.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
bpy.ops.mesh.primitive_cube_add()
cube = bpy.context.active_object

glass = bpy.data.materials.new("Glass")
glass.use_nodes = True
nodes, links = glass.node_tree.nodes, glass.node_tree.links
bsdf = nodes["Principled BSDF"]
compat.principled_input(bsdf, "transmission").default_value = TRANSMISSION
bsdf.inputs["IOR"].default_value = IOR
bsdf.inputs["Roughness"].default_value = ROUGHNESS
absorption = nodes.new("ShaderNodeVolumeAbsorption")
absorption.inputs["Color"].default_value = (*ATTENUATION, 1.0)
absorption.inputs["Density"].default_value = DENSITY
links.new(absorption.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
# The exporter reads the thickness from its "glTF Material Output" group, as its own UI makes it.
group = bpy.data.node_groups.new("glTF Material Output", "ShaderNodeTree")
if hasattr(group, "interface"):  # 4.0 moved a group's sockets into its interface
    group.interface.new_socket("Thickness", in_out="INPUT", socket_type="NodeSocketFloat")
else:
    group.inputs.new("NodeSocketFloat", "Thickness")
settings = nodes.new("ShaderNodeGroup")
settings.node_tree = group
settings.inputs["Thickness"].default_value = THICKNESS
cube.data.materials.append(glass)

exported = SCRATCH / "glass.gltf"
bpy.ops.export_scene.gltf(filepath=str(exported), export_format="GLTF_SEPARATE")
written = json.loads(exported.read_text())["materials"][0]["extensions"]
print("the exporter wrote:", json.dumps(written))
for extension in ("KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"):
    check(extension in written, f"the exporter wrote {extension}")

info = subprocess.run([SNELL, "info", str(exported), "--json", "-"], capture_output=True, text=True, timeout=120)
check(info.returncode == 0, f"snell info loads the export ({info.stderr.strip()})")
loaded = json.loads(info.stdout)["materials"][0]
print("snell loaded:", json.dumps(loaded))


def close(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-5 * max(1.0, abs(b))


check(loaded["refractive"] and close(loaded["transmission"], TRANSMISSION), "snell loads the transmission")
check(close(loaded["ior"], IOR), f"snell loads the IOR ({loaded['ior']})")
check(close(loaded["roughness"], ROUGHNESS), f"snell loads the roughness ({loaded['roughness']})")
check(close(loaded["thickness"], THICKNESS), f"snell loads the thickness ({loaded['thickness']})")
check(all(close(a, b) for a, b in zip(loaded["attenuation_color"], ATTENUATION)), "snell loads the attenuation colour")
check(close(loaded["attenuation_distance"], 1.0 / DENSITY), "snell loads the attenuation distance (1 / density)")

from snell_blender import convert, runtime  # noqa: E402

check(runtime.device() is not None, f"the add-on found snell ({runtime.status()})")
mapped = convert.material_of(glass, convert.Textures(), "", [])
check(close(mapped.transmission, loaded["transmission"]) and close(mapped.ior, loaded["ior"])
      and close(mapped.thickness, loaded["thickness"])
      and close(mapped.attenuation_distance, loaded["attenuation_distance"])
      and all(close(a, b) for a, b in zip(mapped.attenuation_color, loaded["attenuation_color"])),
      "the add-on maps the material to the values snell loads from the export")
