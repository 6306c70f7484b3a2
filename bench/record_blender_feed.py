# SPDX-License-Identifier: GPL-3.0-or-later
"""Records what the Blender add-on feeds snell for the demo eye rig, to replay it without Blender.

    blender -b --factory-startup --python bench/record_blender_feed.py -- OUT_FOLDER [--size 1920x1080]

Writes OUT_FOLDER/feed.npz: the meshes, materials, textures, lights and
instances the add-on built (SceneSync.arrays), the camera's view and
projection matrices at the size given, and each frame's evaluated positions
and normals per mesh, as the add-on sends them; and OUT_FOLDER/rig.glb,
Blender's glTF export of the same rig, for `snell bench frame`.
bench/python_frame.py replays the feed through the snell module.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "blender"))
ARGS = sys.argv[sys.argv.index("--") + 1:]
OUT = Path(ARGS[0])
WIDTH, HEIGHT = (int(v) for v in (ARGS[ARGS.index("--size") + 1] if "--size" in ARGS else "1920x1080").split("x"))

import demo_eye_rig  # noqa: E402

OUT.mkdir(parents=True, exist_ok=True)
demo_eye_rig.enable_addon()
demo_eye_rig.build()
scene = bpy.context.scene
scene.render.engine = "SNELL"
# The exported camera's yfov follows the render size's aspect: export at the size replayed.
scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
bpy.ops.export_scene.gltf(filepath=str(OUT / "rig.glb"), export_format="GLB", convert_lighting_mode="COMPAT")

from snell_blender import runtime  # noqa: E402
from snell_blender.sync import SceneSync, Y_UP  # noqa: E402

scene.frame_set(scene.frame_start)
sync = SceneSync(runtime.device(), bpy.context.evaluated_depsgraph_get())
arrays = sync.arrays
record: dict = {}
for i, mesh in enumerate(arrays["meshes"]):
    record[f"mesh{i}_indices"] = mesh.indices
    if mesh.uvs is not None:
        record[f"mesh{i}_uvs"] = mesh.uvs
for i, texture in enumerate(arrays["textures"]):
    record[f"texture{i}"] = texture.rgba
for i, instance in enumerate(arrays["instances"]):
    record[f"instance{i}"] = np.asarray(instance.transform, np.float64)
camera = scene.camera.evaluated_get(bpy.context.evaluated_depsgraph_get())
record["view_matrix"] = np.array(camera.matrix_world.inverted(), np.float64) @ np.linalg.inv(Y_UP)
record["projection"] = np.array(camera.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=WIDTH, y=HEIGHT))
fields = ("name", "base_color", "base_color_texture", "transmission", "ior", "roughness", "thickness",
          "attenuation_color", "attenuation_distance", "double_sided", "emissive", "dispersion")


def plain(value):
    """A material field as JSON takes it: vectors as lists."""
    return value if isinstance(value, (str, bool, int, float)) else [float(v) for v in value]


description = {
    "size": [WIDTH, HEIGHT],
    "meshes": [{"name": m.name, "material": m.material} for m in arrays["meshes"]],
    "instance_meshes": [instance.mesh for instance in arrays["instances"]],
    "materials": [{f: plain(getattr(m, f)) for f in fields} for m in arrays["materials"]],
    "lights": [{"type": l.type, "color": list(l.color), "intensity": l.intensity, "position": list(l.position),
                "direction": list(l.direction), "inner_cone_angle": l.inner_cone_angle,
                "outer_cone_angle": l.outer_cone_angle} for l in arrays["lights"]],
    "background": list(sync.background),
    "frames": [],
}
parts = [(g.name, p) for g in sync.geometry.values() for p in g.parts]
for frame in range(scene.frame_start, scene.frame_end + 1):
    scene.frame_set(frame)
    # The viewport sends what Blender re-evaluated; a script sees no update list, so it sends
    # every mesh and keeps those that moved.
    before = {p.mesh: p.positions.copy() for _, p in parts}
    sync.send_every_mesh(bpy.context.evaluated_depsgraph_get())
    moved = sorted({name for name, p in parts if not np.array_equal(before[p.mesh], p.positions)})
    description["frames"].append({"frame": frame, "meshes_sent": moved})
    for name, part in parts:
        if name in moved:
            record[f"frame{frame}_positions{part.mesh}"] = part.positions.copy()
            record[f"frame{frame}_normals{part.mesh}"] = part.normals.copy()
for i, mesh in enumerate(arrays["meshes"]):  # the rest pose of every mesh
    record[f"mesh{i}_positions"] = mesh.positions
    record[f"mesh{i}_normals"] = mesh.normals
record["description"] = np.frombuffer(json.dumps(description).encode(), np.uint8)
np.savez_compressed(OUT / "feed.npz", **record)
print(f"recorded {len(description['frames'])} frames of {len(arrays['meshes'])} meshes into {OUT / 'feed.npz'}")
