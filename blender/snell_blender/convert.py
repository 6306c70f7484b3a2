# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender data to snell's: materials from their node trees, lights, the world, images.

A material is read from the shader that feeds its output's Surface, as
Blender's glTF exporter would write it, so a scene drawn by the add-on and
the same scene exported and rendered by `snell render` agree. The shaders
read (docs: README "In Blender"):

- Principled BSDF: base colour, roughness, IOR, transmission (any weight
  above 0 is glass), emission colour times strength, alpha, normal map;
- Glass and Refraction BSDF: snell's glass, the colour tinting it;
- Emission: a face that gives off its colour times its strength;
- Diffuse and Glossy BSDF: an opaque face of that colour;
- Transparent BSDF: nothing there (alpha 0);
- Mix Shader of these: with a Transparent BSDF on one side, the other side
  with alpha = its weight (a factor from an image's alpha reads that alpha);
  otherwise the side the factor favours decides what the face is, and where
  both sides are opaque their colours blend by the factor.

On the output's Volume, a Volume Absorption absorbs as Cycles' does
(cycles_absorption); a Principled Volume's Color absorbs the same way, its
scattering undrawn (and named). Blender's glass shaders have no dispersion:
a glass disperses by the "Dispersion" input of the glTF add-on's "glTF
Material Output" group (KHR_materials_dispersion's 20 / Abbe number), which
also gives a volume's thickness.

A colour or a normal may come from an Image Texture, through a Mapping node
(location, Z rotation, scale) and a UV Map node, or a Normal Map node. Any
other node is named in a problem, with the material, and its input's own
value is used instead: the panel and the console show it.

Light units follow the exporter's 'COMPAT' (unitless) mode: a point light of
P watts shines P / (4 pi) candela, a sun of S W/m^2 gives S lux.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Optional

import numpy as np

from . import compat
from .runtime import AREA_LIGHT_NOTE

GLASS_NODES = ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction")
# Principled inputs that draw something snell does not: named in a problem when in use.
UNDRAWN_PRINCIPLED = {
    "Subsurface Weight": "subsurface", "Subsurface": "subsurface", "Coat Weight": "coat", "Clearcoat": "coat",
    "Sheen Weight": "sheen", "Sheen": "sheen", "Metallic": "metallic",
}


@dataclass
class TextureUse:
    """One Image Texture node as a snell texture slot: which texture and how its UVs are transformed."""

    index: int
    transform: object  # snell.TextureTransform
    image: object      # the Blender image it reads


@dataclass
class Surface:
    """What one shader (or a mix of them) draws, in snell's terms, before it becomes a snell.Material."""

    kind: str = "opaque"  # "opaque", "glass" or "transparent"
    colour: tuple = (0.8, 0.8, 0.8)
    colour_texture: Optional[TextureUse] = None
    alpha: float = 1.0
    alpha_texture: bool = False   # alpha also comes from the colour texture's alpha
    alpha_cutoff: Optional[float] = None  # a clip (mask) rather than a blend
    emissive: tuple = (0.0, 0.0, 0.0)
    emissive_texture: Optional[TextureUse] = None
    roughness: float = 0.5
    ior: float = 1.5
    transmission: float = 1.0  # glass's: any weight above 0 refracts, as the glTF exporter's would
    normal_texture: Optional[TextureUse] = None
    normal_scale: float = 1.0


@dataclass
class Textures:
    """The scene's snell textures, each Blender image (with its sampler and colour use) added once."""

    textures: list = field(default_factory=list)
    index: dict = field(default_factory=dict)

    def add(self, node, colour: bool) -> int:
        """The index of the Image Texture node's image as a colour (sRGB) or data texture; -1 if empty."""
        import snell

        image = node.image
        wraps = {"REPEAT": "repeat", "EXTEND": "clamp", "CLIP": "clamp", "MIRROR": "mirror"}
        wrap = wraps.get(node.extension, "repeat")
        nearest = node.interpolation == "Closest"
        key = (image.name, colour, wrap, nearest)
        if key in self.index:
            return self.index[key]
        width, height = image.size
        if width == 0 or height == 0:
            return -1
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
        rgba = pixels.reshape(height, width, 4)[::-1].astype(np.float64)  # Blender's row 0 is the bottom
        if image.is_float and colour:  # float images hold linear light; snell's colour textures are sRGB bytes
            c = np.clip(rgba[..., :3], 0.0, 1.0)
            rgba[..., :3] = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
        data = np.ascontiguousarray(np.rint(np.clip(rgba, 0.0, 1.0) * 255.0).astype(np.uint8))
        self.textures.append(snell.Texture(data, image.name, wrap_s=wrap, wrap_t=wrap, nearest=nearest))
        self.index[key] = len(self.textures) - 1
        return self.index[key]


def _linked(socket):
    """The (node, output socket) feeding an input socket, or (None, None)."""
    if socket is None or not socket.is_linked:
        return None, None
    link = socket.links[0]
    return link.from_node, link.from_socket


def _same_image(a: Optional[TextureUse], b: Optional[TextureUse]) -> bool:
    """Whether two texture slots read the same image the same way (or neither reads one)."""
    if a is None or b is None:
        return a is None and b is None

    def fields(t) -> tuple:
        return (*t.offset, t.rotation, *t.scale)

    return a.index == b.index and fields(a.transform) == fields(b.transform)


def _output_node(material):
    """The material's active Material Output node (for all renderers, or Cycles')."""
    outputs = [n for n in material.node_tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    for node in outputs:
        if node.is_active_output:
            return node
    return outputs[0] if outputs else None


def _gltf_settings_input(material, name: str):
    """An input of the glTF add-on's "glTF Material Output" (or older "glTF Settings") group node, found as the
    exporter finds it: by the start of its tree's name, in any case ("glTF Material Output.001" too)."""
    for node in material.node_tree.nodes:
        tree = getattr(node, "node_tree", None)
        if node.bl_idname == "ShaderNodeGroup" and tree is not None:
            if tree.name.lower().startswith(("gltf material output", "gltf settings")):
                found = node.inputs.get(name)
                if found is not None:
                    return found
    return None


class MaterialReader:
    """Reads one Blender material into a snell.Material; what it cannot map goes into `problems`."""

    def __init__(self, material, textures: Textures, render_uv: str, problems: list) -> None:
        self.material = material
        self.textures = textures
        self.render_uv = render_uv
        self.problems = problems

    def problem(self, node, what: str) -> None:
        text = f"material '{self.material.name}': node '{node.name}' ({node.bl_idname}) {what}"
        if text not in self.problems:
            self.problems.append(text)

    # ------------------------------------------------------------------ textures

    def _transform(self, node):
        """A Mapping node (or none) as snell's UV transform, flipped to snell's v, which runs down the image."""
        import snell

        if node.vector_type not in ("POINT", "TEXTURE", "VECTOR"):
            self.problem(node, f"of type {node.vector_type} is not read; its UVs are used as they are")
            return snell.TextureTransform()
        location = np.array(node.inputs["Location"].default_value[:2], np.float64)
        rotation = node.inputs["Rotation"].default_value
        scale = np.array(node.inputs["Scale"].default_value[:2], np.float64)
        for name in ("Location", "Rotation", "Scale"):
            if node.inputs[name].is_linked:
                self.problem(node, f"has a linked {name}, which is not read; its own value is used")
        if abs(rotation[0]) > 1e-6 or abs(rotation[1]) > 1e-6:
            self.problem(node, "rotates about X or Y, which a UV transform cannot; only its Z rotation is used")
        if node.vector_type == "VECTOR":
            location[:] = 0.0
        c, s = math.cos(rotation[2]), math.sin(rotation[2])
        m = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.diag([scale[0], scale[1], 1.0])
        m[:2, 2] = location
        if node.vector_type == "TEXTURE":
            if abs(np.linalg.det(m)) < 1e-12:
                self.problem(node, "scales to nothing; its UVs are used as they are")
                return snell.TextureTransform()
            m = np.linalg.inv(m)
        flip = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, 1.0]])
        k = flip @ m @ flip
        # KHR_texture_transform is translate * rotate * scale with rotate = [[c, s], [-s, c]].
        sx = math.hypot(k[0, 0], k[1, 0])
        angle = math.atan2(-k[1, 0], k[0, 0])
        c, s = math.cos(angle), math.sin(angle)
        sy = s * k[0, 1] + c * k[1, 1]
        if abs(c * k[0, 1] - s * k[1, 1]) > 1e-6 * max(1.0, abs(sy)):
            self.problem(node, "shears the UVs, which a UV transform cannot; the shear is left out")
        return snell.TextureTransform(offset=(k[0, 2], k[1, 2]), rotation=angle, scale=(sx, sy))

    def _texture(self, node, colour: bool) -> Optional[TextureUse]:
        """An Image Texture node as a texture slot (its Vector through a Mapping and a UV Map node)."""
        import snell

        if node.image is None:
            self.problem(node, "has no image; the input's own value is used")
            return None
        transform = snell.TextureTransform()
        source, output = _linked(node.inputs["Vector"])
        if source is not None and source.bl_idname == "ShaderNodeMapping":
            mapping = source
            transform = self._transform(mapping)
            source, output = _linked(mapping.inputs["Vector"])
            if source is None:  # Blender maps the Vector's own value: one point of the image everywhere
                self.problem(mapping, "has no coordinates linked to its Vector; snell maps the UV map through it")
        if source is not None:
            if source.bl_idname == "ShaderNodeUVMap":
                if source.uv_map not in ("", self.render_uv):
                    self.problem(source, f"names UV map '{source.uv_map}'; snell reads the render UV map "
                                         f"'{self.render_uv}'")
            elif not (source.bl_idname == "ShaderNodeTexCoord" and output.name == "UV"):
                self.problem(source, f"gives texture coordinates ({output.name}) snell does not read; "
                                     "the UV map is used")
        index = self.textures.add(node, colour)
        if not colour and node.image.colorspace_settings.name not in ("Non-Color", "Raw", "Linear"):
            self.problem(node, f"feeds a normal map from a {node.image.colorspace_settings.name} image; "
                               "its bytes are read as data, as a Non-Color image's")
        return TextureUse(index, transform, node.image) if index >= 0 else None

    def _colour(self, socket) -> tuple:
        """A colour input: (rgba, texture use or None); a texture's colour is white times the texture."""
        value = tuple(socket.default_value)
        node, _ = _linked(socket)
        if node is None:
            return value, None
        if node.bl_idname == "ShaderNodeTexImage":
            return (1.0, 1.0, 1.0, 1.0), self._texture(node, colour=True)
        if node.bl_idname == "ShaderNodeRGB":
            return tuple(node.outputs[0].default_value), None
        self.problem(node, f"on {socket.name} is not read; the input's own colour is used")
        return value, None

    def _value(self, socket, default: float = 0.0) -> float:
        """A number input; a linked one is a problem, and its own value is used."""
        if socket is None:
            return default
        node, _ = _linked(socket)
        if node is not None:
            self.problem(node, f"on {socket.name} is not read; the input's own value is used")
        return float(socket.default_value)

    def _normal(self, node, surface: Surface) -> None:
        """A shader's Normal input: a Normal Map node of a tangent-space image."""
        source, _ = _linked(node.inputs.get("Normal"))
        if source is None:
            return
        if source.bl_idname != "ShaderNodeNormalMap":
            self.problem(source, "on Normal is not read (snell reads a Normal Map node); the surface's own normal is "
                                 "used")
            return
        if source.space != "TANGENT":
            self.problem(source, f"is in {source.space} space; snell reads tangent-space maps only")
            return
        if source.uv_map not in ("", self.render_uv):
            self.problem(source, f"names UV map '{source.uv_map}'; snell reads the render UV map '{self.render_uv}'")
        image, _ = _linked(source.inputs["Color"])
        if image is None or image.bl_idname != "ShaderNodeTexImage":
            if image is not None:
                self.problem(image, "feeds a Normal Map but is not an Image Texture; no normal map is used")
            return
        surface.normal_texture = self._texture(image, colour=False)
        surface.normal_scale = self._value(source.inputs["Strength"], 1.0)

    def _alpha(self, node, surface: Surface) -> None:
        """A Principled BSDF's Alpha: a value, the colour texture's alpha, or that alpha through a 'greater than'."""
        socket = node.inputs["Alpha"]
        source, output = _linked(socket)
        clip = compat.alpha_clip_threshold(self.material)
        if source is None:
            surface.alpha = float(socket.default_value)
            surface.alpha_cutoff = clip if surface.alpha < 1.0 else None
            return
        if source.bl_idname == "ShaderNodeMath" and source.operation == "GREATER_THAN":
            clip = self._value(source.inputs[1], 0.5)
            source, output = _linked(source.inputs[0])
        base, _ = _linked(node.inputs["Base Color"])
        if (source is not None and source.bl_idname == "ShaderNodeTexImage" and output.name == "Alpha"
                and base is not None and base.bl_idname == "ShaderNodeTexImage" and base.image == source.image):
            surface.alpha_texture = True
            surface.alpha_cutoff = clip
            return
        if source is not None:
            self.problem(source, "on Alpha is not read (snell reads the base colour image's alpha); alpha is 1")

    # ------------------------------------------------------------------ shaders

    def shader(self, node) -> Surface:
        """What a shader node draws."""
        kind = node.bl_idname
        if kind == "ShaderNodeBsdfPrincipled":
            return self._principled(node)
        if kind in GLASS_NODES:
            colour, texture = self._colour(node.inputs["Color"])
            surface = Surface("glass", colour[:3], texture, roughness=self._value(node.inputs["Roughness"], 0.0),
                              ior=max(1.0, self._value(node.inputs["IOR"], 1.45)))
            self._normal(node, surface)
            return surface
        if kind == "ShaderNodeEmission":
            colour, texture = self._colour(node.inputs["Color"])
            strength = self._value(node.inputs["Strength"], 1.0)
            return Surface("opaque", (0.0, 0.0, 0.0), None, emissive=tuple(strength * c for c in colour[:3]),
                           emissive_texture=texture)
        if kind == "ShaderNodeBsdfDiffuse" or kind in compat.GLOSSY_NODES:
            colour, texture = self._colour(node.inputs["Color"])
            surface = Surface("opaque", colour[:3], texture, roughness=self._value(node.inputs["Roughness"], 0.5))
            self._normal(node, surface)
            return surface
        if kind == "ShaderNodeBsdfTransparent":
            return Surface("transparent", alpha=0.0)
        if kind == "ShaderNodeMixShader":
            return self._mix(node)
        self.problem(node, "is a shader snell does not draw; the material's viewport colour is used")
        return Surface("opaque", tuple(self.material.diffuse_color[:3]))

    def _surface_of(self, socket) -> Surface:
        node, _ = _linked(socket)
        if node is None:
            return Surface("transparent", alpha=0.0) if socket is not None else Surface()
        return self.shader(node)

    def _principled(self, node) -> Surface:
        colour, texture = self._colour(node.inputs["Base Color"])
        transmission = self._value(compat.principled_input(node, "transmission"), 0.0)
        surface = Surface("glass" if transmission > 0.0 else "opaque", colour[:3], texture,
                          roughness=self._value(node.inputs["Roughness"], 0.5),
                          ior=max(1.0, self._value(node.inputs["IOR"], 1.45)), transmission=min(transmission, 1.0))
        if 0.0 < transmission < 1.0:
            self.problem(node, f"has transmission {transmission:g}; snell's glass is all or nothing, so it is glass")
        emission, emission_texture = self._colour(compat.principled_input(node, "emission"))
        strength = self._value(node.inputs.get("Emission Strength"), 1.0)
        surface.emissive = tuple(strength * c for c in emission[:3])
        surface.emissive_texture = emission_texture
        self._alpha(node, surface)
        self._normal(node, surface)
        for name, what in UNDRAWN_PRINCIPLED.items():
            socket = node.inputs.get(name)
            if socket is not None and (socket.is_linked or float(socket.default_value) > 0.0):
                self.problem(node, f"uses {what} ({name}), which snell does not draw")
        return surface

    def _mix(self, node) -> Surface:
        factor_socket = compat.mix_factor(node)
        first, second = self._surface_of(node.inputs[1]), self._surface_of(node.inputs[2])
        factor_node, factor_output = _linked(factor_socket)
        factor = float(factor_socket.default_value)
        if factor_node is not None:
            # Blender's cut-out: the image's alpha chooses between a Transparent
            # BSDF (factor 0) and a surface showing that image (factor 1).
            carrier = second.colour_texture or second.emissive_texture
            if (first.kind == "transparent" and second.kind != "transparent" and carrier is not None
                    and factor_node.bl_idname == "ShaderNodeTexImage" and factor_output.name == "Alpha"
                    and factor_node.image == carrier.image):
                surface = replace(second, alpha_texture=True, alpha_cutoff=compat.alpha_clip_threshold(self.material))
                if surface.colour_texture is None:  # an Emission's image: its black base carries the alpha
                    surface.colour_texture = carrier
                return surface
            self.problem(factor_node, "on a Mix Shader's factor is not read; the factor's own value is used")
        if first.kind == "transparent" and second.kind != "transparent":
            return replace(second, alpha=second.alpha * factor)
        if second.kind == "transparent" and first.kind != "transparent":
            return replace(first, alpha=first.alpha * (1.0 - factor))
        dominant = second if factor >= 0.5 else first
        if first.kind == second.kind == "opaque" and _same_image(first.colour_texture, second.colour_texture) \
                and _same_image(first.emissive_texture, second.emissive_texture):
            # Colours times one texture (or none) blend exactly: mix the factors.
            blend = lambda a, b: tuple((1.0 - factor) * x + factor * y for x, y in zip(a, b))  # noqa: E731
            return replace(dominant, colour=blend(first.colour, second.colour),
                           emissive=blend(first.emissive, second.emissive),
                           roughness=(1.0 - factor) * first.roughness + factor * second.roughness)
        if 0.0 < factor < 1.0:
            self.problem(node, f"mixes a {first.kind} and a {second.kind} surface (or two textures) at {factor:g}; "
                               f"snell draws the side the factor favours, the {'second' if factor >= 0.5 else 'first'}")
        return dominant

    # ------------------------------------------------------------------ the material

    def read(self):
        """The snell.Material this Blender material draws as."""
        import snell

        material = self.material
        out = snell.Material(name=material.name, base_color=tuple(material.diffuse_color), roughness=material.roughness,
                             double_sided=not material.use_backface_culling)
        if not compat.uses_nodes(material):
            return out
        output = _output_node(material)
        if output is None:
            self.problems.append(f"material '{material.name}' has no Material Output node; its viewport colour is used")
            return out
        surface = self._surface_of(output.inputs["Surface"])
        out.base_color = (*surface.colour[:3], surface.alpha)
        if surface.colour_texture is not None:
            out.base_color_texture = surface.colour_texture.index
            out.base_color_transform = surface.colour_texture.transform
        if surface.kind == "transparent" or surface.alpha < 1.0 or surface.alpha_texture:
            out.alpha_mode = "mask" if surface.alpha_cutoff is not None else "blend"
            if surface.alpha_cutoff is not None:
                out.alpha_cutoff = surface.alpha_cutoff
        if surface.kind == "glass":
            out.transmission = surface.transmission
            out.ior = surface.ior
            # No glass shader of Blender 3.4 to 5.2 has a Dispersion input; the glTF add-on's group carries
            # KHR_materials_dispersion's value (20 / Abbe number), and from 5.2 it exports that input.
            out.dispersion = max(0.0, self._value(_gltf_settings_input(material, "Dispersion"), 0.0))
        out.roughness = surface.roughness
        out.emissive = surface.emissive
        if surface.emissive_texture is not None:
            out.emissive_texture = surface.emissive_texture.index
            out.emissive_transform = surface.emissive_texture.transform
        if surface.normal_texture is not None:
            out.normal_texture = surface.normal_texture.index
            out.normal_transform = surface.normal_texture.transform
            out.normal_scale = surface.normal_scale
        self._volume(out, output)
        return out

    def _volume(self, out, output) -> None:
        """Volume Absorption (or a Principled Volume) on the output's Volume, absorbing as Cycles absorbs."""
        volume, _ = _linked(output.inputs["Volume"])
        if volume is None:
            return
        if volume.bl_idname not in ("ShaderNodeVolumeAbsorption", "ShaderNodeVolumePrincipled"):
            self.problem(volume, "on Volume is not read; the glass has no volume")
            return
        if volume.bl_idname == "ShaderNodeVolumePrincipled":
            self.problem(volume, "scatters light, which snell does not draw; its Color absorbs as a Volume "
                                 "Absorption's would")
        colour = volume.inputs["Color"]
        if colour.is_linked:
            self.problem(_linked(colour)[0], "on Color is not read; the input's own colour is used")
        density = self._value(volume.inputs["Density"], 1.0)
        out.attenuation_color, out.attenuation_distance = cycles_absorption(colour.default_value[:3], density)
        # snell's trace measures the distance each ray travels inside; the thickness factor only makes the
        # material a volume rather than thin-walled. The exporter's group keeps its own value, for a glTF round trip.
        thickness = _gltf_settings_input(self.material, "Thickness")
        out.thickness = float(thickness.default_value) if thickness is not None and thickness.default_value > 0 else 1.0


def cycles_absorption(colour, density: float) -> tuple:
    """glTF's (attenuationColor, attenuationDistance) that absorb as Cycles' Volume Absorption of `colour` and
    `density` does.

    Cycles absorbs with the coefficient (1 - Color) x Density (svm_node_closure_volume), so light crossing a
    length d keeps exp(-(1 - C) Density d) of each channel. KHR_materials_volume keeps
    attenuationColor^(d / attenuationDistance); with the distance 1 / Density and the colour exp(C - 1) that is
    exp(-(1 - C) Density d) for every d, exactly. (Blender's glTF exporter writes C itself, which keeps
    C^(Density d): darker, 0.33 of red where Cycles keeps 0.55 through a slab of colour 0.25, density 1.6 and
    half a unit thick.) A colour beyond [0, 1] is clamped, as glTF's is.
    """
    if not density > 0.0:
        return (1.0, 1.0, 1.0), math.inf
    return tuple(math.exp(min(max(float(c), 0.0), 1.0) - 1.0) for c in colour), 1.0 / density


def material_of(material, textures: Textures, render_uv: str, problems: list):
    """A snell.Material from a Blender material (None: snell's grey default); problems gain what is not mapped."""
    import snell

    if material is None:
        return snell.Material(name="default", base_color=(0.8, 0.8, 0.8, 1.0))
    return MaterialReader(material, textures, render_uv, problems).read()


def light_of(light_object, matrix: np.ndarray) -> tuple:
    """A snell.Light from a Blender light at `matrix` (its world matrix, 4x4), and a note if inexact."""
    import snell

    data = light_object.data
    position = tuple(matrix[:3, 3].tolist())
    direction = -matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])  # a light shines down its -Z
    direction = tuple(direction.tolist())
    colour = tuple(data.color)
    power = compat.light_power(data)
    note = None
    if data.type == "SUN":
        return snell.Light(type="directional", color=colour, intensity=power, direction=direction), note
    intensity = power / (4.0 * math.pi)
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
    if compat.uses_nodes(world):
        for node in world.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBackground":
                colour = np.array(node.inputs["Color"].default_value[:3]) * node.inputs["Strength"].default_value
                return tuple(colour.tolist())
    return tuple(world.color)
