"""A Principled glass with volume absorption: Blender's glTF exporter writes transmission, IOR and
volume, snell loads the same values, and the add-on maps the material to those values too, but for the
attenuation colour: the exporter writes the absorption's Color itself, the add-on the colour that absorbs as
Cycles does (exp(Color - 1) over the same distance, 1 / Density; test_absorption_matches_cycles.py renders it).
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import SCRATCH, SNELL, check, enable_addon  # noqa: E402
from snell_blender import compat  # noqa: E402  (blender_support puts the add-on on the path)

TRANSMISSION, IOR, ROUGHNESS = 1.0, 1.45, 0.1
ATTENUATION, DENSITY, THICKNESS = (0.8, 0.5, 0.3), 2.0, 0.25
DISPERSION = 0.4  # KHR_materials_dispersion: 20 / Abbe number (50)

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
# The exporter reads the thickness (5.2's the dispersion too) from the glTF add-on's "glTF Material Output"
# group, made here by the add-on's own function, so with its real name and sockets.
try:
    from io_scene_gltf2.blender.com import material_helpers as gltf_helpers
except ImportError:  # 3.x's name
    from io_scene_gltf2.blender.com import gltf2_blender_material_helpers as gltf_helpers
group = gltf_helpers.create_settings_group(gltf_helpers.get_gltf_node_name())
settings = nodes.new("ShaderNodeGroup")
settings.node_tree = group
exporter_disperses = settings.inputs.get("Dispersion") is not None
if not exporter_disperses:  # before 5.2 the group has none: a user adds the input for snell to read
    if hasattr(group, "interface"):  # 4.0 moved a group's sockets into its interface
        group.interface.new_socket("Dispersion", in_out="INPUT", socket_type="NodeSocketFloat")
    else:
        group.inputs.new("NodeSocketFloat", "Dispersion")
print(f"the glTF add-on's group {group.name!r} has {[i.name for i in settings.inputs]}"
      f"{'' if exporter_disperses else ' (Dispersion added)'}")
settings.inputs["Thickness"].default_value = THICKNESS
settings.inputs["Dispersion"].default_value = DISPERSION
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
if exporter_disperses:
    check("KHR_materials_dispersion" in written and close(loaded["dispersion"], DISPERSION),
          f"the exporter writes the group's Dispersion and snell loads it ({loaded['dispersion']})")
else:
    print(f"Blender {bpy.app.version_string}'s glTF exporter writes no dispersion (5.2's is the first that does)")

from snell_blender import convert, runtime  # noqa: E402

check(runtime.device() is not None, f"the add-on found snell ({runtime.status()})")
mapped = convert.material_of(glass, convert.Textures(), "", [])
check(close(mapped.transmission, loaded["transmission"]) and close(mapped.ior, loaded["ior"])
      and close(mapped.thickness, loaded["thickness"])
      and close(mapped.attenuation_distance, loaded["attenuation_distance"]),
      "the add-on maps the material to the values snell loads from the export")
check(close(mapped.dispersion, DISPERSION),
      f"the add-on reads the dispersion from the glTF Material Output's Dispersion ({mapped.dispersion})")
check(all(close(a, math.exp(b - 1.0)) for a, b in zip(mapped.attenuation_color, ATTENUATION)),
      f"the add-on's attenuation colour is Cycles' absorption, exp(Color - 1) ({tuple(mapped.attenuation_color)}), "
      "not the exporter's Color")
