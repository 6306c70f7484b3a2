# SPDX-License-Identifier: GPL-3.0-or-later
"""A rigged eye pair for snell's Blender add-on, built from nothing.

    blender --python blender/demo_eye_rig.py            # opens it in the Rendered viewport, playing
    blender -b --python blender/demo_eye_rig.py -- --save eyes.blend

Each eye is an eyeball mesh whose front faces are the cornea's glass (IOR
1.376) and whose other faces are the sclera, and an iris disc behind it with
a painted iris texture and a "Dilate" shape key that widens the pupil. An
armature turns both eyes (every vertex on one bone: glTF's skinning and
Blender's deformation then agree exactly), and the animation looks around
while the pupils dilate. Run inside Blender, the script enables the snell
add-on from this checkout (blender/snell_blender) and, if the snell module
is not installed, points the add-on at build/release/python.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import bpy
import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
from snell_blender import compat  # noqa: E402  (the add-on's version gates, from this checkout)
EYE_SEPARATION = 1.6  # centre to centre is twice this
LIMBUS = math.radians(35.0)  # the angle from the eye's axis where the cornea meets the sclera
CORNEA_RADIUS = 0.75
IRIS_DEPTH = 0.74  # the iris sits this far in front of the eye's centre
RINGS, SEGMENTS = 36, 48
FRAMES = (1, 48)


def iris_image(size: int = 256) -> bpy.types.Image:
    """A painted iris: radial fibres in blue-green and amber, a dark limbal ring and a black pupil."""
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size * 2.0 - 1.0
    r, angle = np.hypot(x, y), np.arctan2(y, x)
    fibres = 0.5 + 0.5 * np.sin(angle * 61.0 + 3.0 * np.sin(angle * 7.0)) * np.sin(r * 23.0)
    colour = np.stack([0.10 + 0.25 * fibres, 0.30 + 0.25 * fibres, 0.35 + 0.20 * fibres], axis=-1)
    amber = np.clip(1.0 - (r - 0.30) / 0.15, 0.0, 1.0)[..., None]  # a warm collarette round the pupil
    colour = colour * (1 - amber) + np.array([0.55, 0.35, 0.10]) * amber * (0.6 + 0.4 * fibres[..., None])
    colour *= np.clip((1.0 - r) / 0.12, 0.25, 1.0)[..., None]  # the limbal ring darkens the edge
    colour[r < 0.30] = 0.015  # the pupil
    rgba = np.concatenate([colour, np.ones((size, size, 1))], axis=-1)
    image = bpy.data.images.new("Iris", size, size)
    image.pixels.foreach_set(rgba.astype(np.float32).reshape(-1))  # sRGB values, as a painted texture
    image.file_format = "PNG"
    image.pack()
    return image


def glass(name: str, ior: float) -> bpy.types.Material:
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    compat.principled_input(bsdf, "transmission").default_value = 1.0
    bsdf.inputs["IOR"].default_value = ior
    bsdf.inputs["Roughness"].default_value = 0.05
    return material


def opaque(name: str, colour, roughness: float = 0.6, image=None) -> bpy.types.Material:
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    if image is not None:
        texture = nodes.new("ShaderNodeTexImage")
        texture.image = image
        material.node_tree.links.new(texture.outputs["Color"], bsdf.inputs["Base Color"])
    return material


def eyeball_mesh(name: str) -> bpy.types.Mesh:
    """The sclera (unit sphere, open at the front) and the cornea's dome over the opening, one mesh.

    The eye looks down -Y. Rings run from the cornea's apex (ring 0) to the back
    of the eye; the rings within the limbus lie on the cornea's sphere, which
    meets the sclera at the limbus. Material 0 is the sclera, 1 the cornea.
    """
    opening = math.sin(LIMBUS)
    limbus_y = -math.cos(LIMBUS)
    centre_y = limbus_y + math.sqrt(CORNEA_RADIUS**2 - opening**2)
    cornea_angle = math.asin(opening / CORNEA_RADIUS)
    limbus_ring = RINGS // 4
    vertices = [(0.0, centre_y - CORNEA_RADIUS, 0.0)]
    for ring in range(1, RINGS):
        if ring <= limbus_ring:
            a = cornea_angle * ring / limbus_ring
            radius, y = CORNEA_RADIUS * math.sin(a), centre_y - CORNEA_RADIUS * math.cos(a)
        else:
            theta = LIMBUS + (math.pi - LIMBUS) * (ring - limbus_ring) / (RINGS - limbus_ring)
            radius, y = math.sin(theta), -math.cos(theta)
        for s in range(SEGMENTS):
            phi = 2 * math.pi * s / SEGMENTS
            vertices.append((radius * math.cos(phi), y, radius * math.sin(phi)))
    vertices.append((0.0, 1.0, 0.0))
    faces, materials = [], []
    ring_start = lambda ring: 1 + (ring - 1) * SEGMENTS  # noqa: E731
    for s in range(SEGMENTS):  # the cornea's apex fan
        faces.append((0, ring_start(1) + (s + 1) % SEGMENTS, ring_start(1) + s))
        materials.append(1)
    for ring in range(1, RINGS - 1):
        for s in range(SEGMENTS):
            a, b = ring_start(ring) + s, ring_start(ring) + (s + 1) % SEGMENTS
            c, d = ring_start(ring + 1) + (s + 1) % SEGMENTS, ring_start(ring + 1) + s
            faces.append((a, b, c, d))
            materials.append(1 if ring < limbus_ring else 0)
    back = len(vertices) - 1
    for s in range(SEGMENTS):
        faces.append((ring_start(RINGS - 1) + s, ring_start(RINGS - 1) + (s + 1) % SEGMENTS, back))
        materials.append(0)
    # Wound outwards: a renderer takes the side a face's winding points to as its outside. Wound
    # inwards, the cornea bent light as glass left for air, and rays through its edge left the
    # eye unseen: the dark crescent (the world) beside the iris, in Cycles as in snell.
    faces = [face[::-1] for face in faces]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.polygons.foreach_set("material_index", materials)
    mesh.polygons.foreach_set("use_smooth", [True] * len(faces))
    # The limbus is a crease: the cornea's normals and the sclera's do not blend across it.
    compat.keep_sharp_edges(mesh)
    limbus = set(range(ring_start(limbus_ring), ring_start(limbus_ring) + SEGMENTS))
    for edge in mesh.edges:
        edge.use_edge_sharp = edge.vertices[0] in limbus and edge.vertices[1] in limbus
    mesh.update()
    return mesh


def iris_mesh(name: str) -> bpy.types.Mesh:
    """A disc facing -Y just behind the limbus, UV-mapped to the iris texture (the pupil its centre).

    Its rim turns forward to meet the eyeball at the limbus, as a production
    eye's iris root does: a disc that stopped behind the limbus left a band of
    the eyeball's dark inside to show through the cornea as the eye turned (a
    dark crescent beside the iris, in Cycles as in snell).
    """
    limbus = math.sin(LIMBUS) * 0.99  # the texture's edge: the iris as seen through the cornea
    limbus_y = -math.cos(LIMBUS) * 0.995  # just inside the opening, so the rim meets the sclera's edge
    rings = [(limbus * ring / 12, -IRIS_DEPTH - 0.04 * (1 - ring / 12), ring / 12) for ring in range(1, 13)]
    rings += [(limbus, -IRIS_DEPTH + (limbus_y + IRIS_DEPTH) * k / 2, 1.0) for k in (1, 2)]  # the root, forward
    vertices, uvs = [(0.0, -IRIS_DEPTH - 0.04, 0.0)], [(0.5, 0.5)]
    for r, y, t in rings:
        for s in range(SEGMENTS):
            phi = 2 * math.pi * s / SEGMENTS
            vertices.append((r * math.cos(phi), y, r * math.sin(phi)))
            uvs.append((0.5 + 0.5 * t * math.cos(phi), 0.5 + 0.5 * t * math.sin(phi)))
    rings = len(rings)
    # Wound to face the cornea (-Y), as the eyeball's faces face out.
    faces = [(0, 1 + s, 1 + (s + 1) % SEGMENTS) for s in range(SEGMENTS)]
    for ring in range(1, rings):
        base = 1 + (ring - 1) * SEGMENTS
        for s in range(SEGMENTS):
            faces.append((base + SEGMENTS + s, base + SEGMENTS + (s + 1) % SEGMENTS, base + (s + 1) % SEGMENTS,
                          base + s))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    for polygon in mesh.polygons:
        for loop in polygon.loop_indices:
            layer.data[loop].uv = uvs[mesh.loops[loop].vertex_index]
    root = 2 * SEGMENTS  # the root's faces, last: flat, so the disc's normals do not bend round its edge
    mesh.polygons.foreach_set("use_smooth", [True] * (len(faces) - root) + [False] * root)
    mesh.update()
    return mesh, limbus


def add_dilation(obj, outer: float) -> None:
    """A "Dilate" shape key: the pupil (the texture's centre) opens to 1.7 times its width; from `outer` out
    nothing moves."""
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Dilate")
    for i, vertex in enumerate(obj.data.vertices):
        x, y, z = vertex.co
        r = math.hypot(x, z)
        if r > 0:
            grown = r + 0.7 * r * max(0.0, 1 - r / outer) ** 1.5  # the rim stays, the middle opens
            key.data[i].co = (x * grown / r, y, z * grown / r)


def build(scene=None) -> dict:
    """Builds the eye pair, its rig, camera, lights and animation into `scene` (empty it first)."""
    scene = scene or bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    iris_texture = iris_image()
    sclera = opaque("Sclera", (0.82, 0.78, 0.74), roughness=0.5)
    cornea = glass("Cornea", 1.376)
    iris = opaque("Iris", (1.0, 1.0, 1.0), roughness=0.8, image=iris_texture)

    armature_data = bpy.data.armatures.new("EyeRig")
    rig = bpy.data.objects.new("EyeRig", armature_data)
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    for side, x in (("L", EYE_SEPARATION), ("R", -EYE_SEPARATION)):
        bone = armature_data.edit_bones.new(f"Eye.{side}")
        bone.head, bone.tail = (x, 0.0, 0.0), (x, -1.5, 0.0)
    bpy.ops.object.mode_set(mode="OBJECT")

    objects = {}
    for side, x in (("L", EYE_SEPARATION), ("R", -EYE_SEPARATION)):
        ball = bpy.data.objects.new(f"Eyeball.{side}", eyeball_mesh(f"Eyeball.{side}"))
        ball.data.materials.append(sclera)
        ball.data.materials.append(cornea)
        iris_data, limbus = iris_mesh(f"Iris.{side}")
        disc = bpy.data.objects.new(f"Iris.{side}", iris_data)
        disc.data.materials.append(iris)
        for obj in (ball, disc):
            scene.collection.objects.link(obj)
            obj.location = (x, 0.0, 0.0)
            obj.parent = rig
            group = obj.vertex_groups.new(name=f"Eye.{side}")
            group.add(list(range(len(obj.data.vertices))), 1.0, "REPLACE")
            modifier = obj.modifiers.new("Armature", "ARMATURE")
            modifier.object = rig
        add_dilation(disc, limbus)
        objects[side] = (ball, disc)

    # The animation: the eyes look around, the pupils open and close.
    scene.frame_start, scene.frame_end = FRAMES
    scene.render.fps = 24
    looks = {1: (0, 0), 12: (-12, 18), 20: (8, 25), 30: (15, -10), 40: (-6, -20), 48: (0, 0)}
    for side in ("L", "R"):
        bone = rig.pose.bones[f"Eye.{side}"]
        bone.rotation_mode = "XYZ"
        for frame, (up, across) in looks.items():
            bone.rotation_euler = (math.radians(up), 0.0, math.radians(across))
            bone.keyframe_insert("rotation_euler", frame=frame)
        key = objects[side][1].data.shape_keys.key_blocks["Dilate"]
        for frame, value in {1: 0.0, 20: 1.0, 40: 0.2, 48: 0.0}.items():
            key.value = value
            key.keyframe_insert("value", frame=frame)

    # A face plate behind the eyes: it never deforms, so a frame change leaves it where it is.
    face = bpy.data.meshes.new("Face")
    face.from_pydata([(-4.5, 1.1, -2.2), (4.5, 1.1, -2.2), (4.5, 1.1, 2.2), (-4.5, 1.1, 2.2)], [], [(0, 1, 2, 3)])
    face.materials.append(opaque("Skin", (0.62, 0.42, 0.34), roughness=0.7))
    scene.collection.objects.link(bpy.data.objects.new("Face", face))

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 55.0
    camera.location = (0.0, -11.0, 0.6)
    camera.rotation_euler = (math.radians(87.0), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    for name, kind, energy, location, rotation in (
        ("Key", "POINT", 900.0, (3.0, -7.0, 4.0), (0.0, 0.0, 0.0)),
        ("Rim", "SPOT", 600.0, (-5.0, -6.0, 2.0), (math.radians(75), 0.0, math.radians(-40))),
        ("Sky", "SUN", 0.6, (0.0, 0.0, 8.0), (math.radians(30), 0.0, math.radians(15))),
    ):
        light = bpy.data.objects.new(name, bpy.data.lights.new(name, kind))
        light.data.energy = energy
        light.location, light.rotation_euler = location, rotation
        if kind == "SPOT":
            light.data.spot_size, light.data.spot_blend = math.radians(50), 0.3
        scene.collection.objects.link(light)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.035, 0.04, 0.05, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.render.resolution_x, scene.render.resolution_y = 960, 400
    scene.render.resolution_percentage = 100
    scene.frame_set(FRAMES[0])
    return {"rig": rig, "eyes": objects, "camera": camera}


def enable_addon() -> None:
    """Turns on the snell add-on from this checkout, and finds the module if it is not installed."""
    import addon_utils

    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    addon_utils.enable("snell_blender", default_set=True, persistent=True)
    try:
        import snell  # noqa: F401
    except ImportError:
        build = HERE.parent / "build" / "release" / "python"
        bpy.context.preferences.addons["snell_blender"].preferences.module_path = str(build)


def show_in_viewport() -> None:
    """Every 3D viewport in Rendered shading from the camera, and the animation playing."""
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                space = area.spaces.active
                space.shading.type = "RENDERED"
                space.region_3d.view_perspective = "CAMERA"
                with bpy.context.temp_override(window=window, area=area):
                    bpy.ops.view3d.view_center_camera()
    bpy.ops.screen.animation_play()


def main(argv: list) -> None:
    enable_addon()
    build()
    bpy.context.scene.render.engine = "SNELL"
    if "--save" in argv:
        bpy.ops.wm.save_as_mainfile(filepath=argv[argv.index("--save") + 1])
    if not bpy.app.background:
        bpy.app.timers.register(lambda: show_in_viewport() and None, first_interval=0.5)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
