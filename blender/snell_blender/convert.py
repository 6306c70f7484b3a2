# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender data to snell's: Principled BSDF materials, lights, the world, images.

Each function reads Blender's data the way its glTF exporter does (Blender
3.4, io_scene_gltf2), so a scene drawn by the add-on and the same scene
exported and rendered by `snell render` agree. Light units follow the
exporter's "Standard" lighting mode without the 683 lm/W factor (its
'COMPAT' mode): a point light of P watts shines P / (4 pi) candela, a sun of
S W/m^2 gives S lux, which keeps Blender's brightness in snell's shading.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from .runtime import AREA_LIGHT_NOTE


def _linked_node(socket) -> Optional[object]:
    """The node feeding an input socket, or None."""
    if socket is None or not socket.is_linked:
        return None
    return socket.links[0].from_node


def _output_node(material):
    """The material's active Material Output node."""
    for node in material.node_tree.nodes:
        if node.bl_idname == "ShaderNodeOutputMaterial" and node.is_active_output:
            return node
    return None


def _principled(material):
    """The Principled BSDF that feeds the material's surface output, or None."""
    output = _output_node(material)
    node = _linked_node(output.inputs["Surface"]) if output else None
    if node is not None and node.bl_idname == "ShaderNodeBsdfPrincipled":
        return node
    for node in material.node_tree.nodes:  # as the exporter: any Principled BSDF will do
        if node.bl_idname == "ShaderNodeBsdfPrincipled":
            return node
    return None


def _gltf_settings_input(material, name: str):
    """An input of the exporter's "glTF Material Output" (or older "glTF Settings") group node."""
    for node in material.node_tree.nodes:
        tree = getattr(node, "node_tree", None)
        if node.bl_idname == "ShaderNodeGroup" and tree is not None:
            if tree.name.lower() in ("gltf material output", "gltf settings"):
                return node.inputs.get(name)
    return None


def texture_of(image, cache: dict, textures: list) -> int:
    """The index of `image` in `textures` (snell.Texture, 8-bit sRGB, row 0 at the top), added once."""
    import snell

    if image.name in cache:
        return cache[image.name]
    width, height = image.size
    if width == 0 or height == 0:
        return -1
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)  # the file's own values: sRGB for an sRGB image
    rgba = pixels.reshape(height, width, 4)[::-1]  # Blender's row 0 is the bottom
    texture = snell.Texture(np.ascontiguousarray(np.rint(np.clip(rgba, 0, 1) * 255).astype(np.uint8)), image.name)
    textures.append(texture)
    cache[image.name] = len(textures) - 1
    return cache[image.name]


def material_of(material, image_cache: dict, textures: list):
    """A snell.Material from a Blender material's Principled BSDF (or its viewport colour)."""
    import snell

    if material is None:
        return snell.Material(name="default", base_color=(0.8, 0.8, 0.8, 1.0))
    out = snell.Material(name=material.name, base_color=tuple(material.diffuse_color),
                         roughness=material.roughness)
    if not material.use_nodes or material.node_tree is None:
        return out
    bsdf = _principled(material)
    if bsdf is None:
        return out
    base = bsdf.inputs["Base Color"]
    out.base_color = tuple(base.default_value)
    image_node = _linked_node(base)
    if image_node is not None and image_node.bl_idname == "ShaderNodeTexImage" and image_node.image is not None:
        out.base_color = (1.0, 1.0, 1.0, 1.0)  # a linked colour is the texture alone
        out.base_color_texture = texture_of(image_node.image, image_cache, textures)
    out.transmission = float(bsdf.inputs["Transmission"].default_value)
    out.ior = max(1.0, float(bsdf.inputs["IOR"].default_value))
    out.roughness = float(bsdf.inputs["Roughness"].default_value)
    emission = np.array(bsdf.inputs["Emission"].default_value[:3], np.float64)
    strength = bsdf.inputs["Emission Strength"].default_value if "Emission Strength" in bsdf.inputs else 1.0
    out.emissive = tuple((emission * strength).tolist())
    out.double_sided = not material.use_backface_culling
    # Volume absorption into the output's Volume: glTF's attenuation, as the exporter writes it.
    output = _output_node(material)
    volume = _linked_node(output.inputs["Volume"]) if output else None
    if volume is not None and volume.bl_idname in ("ShaderNodeVolumeAbsorption", "ShaderNodeVolumePrincipled"):
        colour = volume.inputs.get("Color")
        density = volume.inputs.get("Density")
        if colour is not None:
            out.attenuation_color = tuple(colour.default_value[:3])
        if density is not None and density.default_value > 0:
            out.attenuation_distance = 1.0 / density.default_value
        thickness = _gltf_settings_input(material, "Thickness")
        out.thickness = float(thickness.default_value) if thickness is not None else 1.0
    return out


def light_of(light_object, matrix: np.ndarray) -> tuple:
    """A snell.Light from a Blender light at `matrix` (its world matrix, 4x4), and a note if inexact."""
    import snell

    data = light_object.data
    position = tuple(matrix[:3, 3].tolist())
    direction = -matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])  # a light shines down its -Z
    direction = tuple(direction.tolist())
    colour = tuple(data.color)
    note = None
    if data.type == "SUN":
        return snell.Light(type="directional", color=colour, intensity=data.energy, direction=direction), note
    intensity = data.energy / (4.0 * math.pi)
    if data.type == "SPOT":
        outer = data.spot_size * 0.5
        inner = outer - outer * data.spot_blend
        return snell.Light(type="spot", color=colour, intensity=intensity, position=position, direction=direction,
                           inner_cone_angle=inner, outer_cone_angle=outer), note
    if data.type == "AREA":
        note = AREA_LIGHT_NOTE
    return snell.Light(type="point", color=colour, intensity=intensity, position=position), note


def background_of(world) -> tuple:
    """The world's colour (its Background node's colour times strength), linear RGB."""
    if world is None:
        return (0.05, 0.05, 0.05)
    if world.use_nodes and world.node_tree is not None:
        for node in world.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBackground":
                colour = np.array(node.inputs["Color"].default_value[:3]) * node.inputs["Strength"].default_value
                return tuple(colour.tolist())
    return tuple(world.color)
