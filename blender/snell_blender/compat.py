# SPDX-License-Identifier: GPL-3.0-or-later
"""Every difference between the Blender versions the add-on runs in (3.4 to 5.2), in one place.

The rest of the add-on never tests a version: it asks this module. Each gate
says which release changed what, as read in Blender's sources and release
notes, so that the day a version leaves the supported range its gates can go.
"""

from __future__ import annotations

from typing import Optional

import bpy

VERSION = bpy.app.version

# 4.0 renamed the Principled BSDF's sockets; these are looked up by either name.
PRINCIPLED_SOCKETS = {
    "transmission": ("Transmission Weight", "Transmission"),
    "emission": ("Emission Color", "Emission"),
}

# 4.0 folded the Glossy BSDF into the Anisotropic node (its bl_idname), 3.x has its own.
GLOSSY_NODES = ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic")

# EEVEE's engine id: BLENDER_EEVEE up to 4.1, BLENDER_EEVEE_NEXT in 4.2 to 4.5, BLENDER_EEVEE again in 5.0.
EEVEE_IDS = ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT")


def socket(node, *names: str):
    """The node's input of the first of `names` it has, or None."""
    for name in names:
        found = node.inputs.get(name)
        if found is not None:
            return found
    return None


def principled_input(node, key: str):
    """A Principled BSDF input by its 4.0+ or older name (PRINCIPLED_SOCKETS), or by its unchanged name."""
    return socket(node, *PRINCIPLED_SOCKETS.get(key, (key,)))


def mix_factor(node):
    """A Mix Shader's factor: "Fac" until 4.5, "Factor" from 5.0 (it is the first input in both)."""
    return node.inputs[0]


def uses_nodes(idblock) -> bool:
    """Whether a material or world draws from its node tree: 5.0 deprecates use_nodes (always on)."""
    return bool(getattr(idblock, "use_nodes", True)) and idblock.node_tree is not None


def light_power(light) -> float:
    """A light's power: 4.5 added exposure, so power is energy x 2^exposure (as its glTF exporter writes)."""
    return float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))


def alpha_clip_threshold(material) -> Optional[float]:
    """The threshold of a material clipped by its blend mode (3.x-4.1 'CLIP'), or None.

    From 4.2 a clip is a Math node on the Alpha socket instead (convert.py reads that).
    """
    if getattr(material, "blend_method", "") == "CLIP":
        return float(material.alpha_threshold)
    return None


def prepare_corner_normals(mesh) -> None:
    """Makes a mesh's corner (loop) normals readable: 4.1 removed calc_normals_split (they are always current)."""
    calc = getattr(mesh, "calc_normals_split", None)
    if calc is not None:
        calc()


def read_corner_normals(mesh, out) -> None:
    """A mesh's corner normals into a flat float32 array: 4.1+ has corner_normals, older versions the loops."""
    if hasattr(mesh, "corner_normals"):
        mesh.corner_normals.foreach_get("vector", out)
    else:
        mesh.loops.foreach_get("normal", out)


def keep_sharp_edges(mesh) -> None:
    """Makes a smooth-shaded mesh keep its edges marked sharp: 4.1 removed auto smooth, as sharp
    edges are always kept from then on; before, auto smooth (at 180 degrees: only marked edges) did it."""
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = True
        mesh.auto_smooth_angle = 3.14159265


def write_pass(render_pass, block) -> None:
    """Writes a (pixels, channels) float32 block into a render result's pass: 3.x's foreach_set takes
    the block as it is, 4.x's (seen in 4.5 and 5.0) its floats flat; each refuses the other's with a TypeError."""
    try:
        render_pass.rect.foreach_set(block)
    except TypeError:
        render_pass.rect.foreach_set(block.reshape(-1))


def blf_size(font: int, points: float) -> None:
    """The font size: 4.0 dropped blf.size's dpi argument."""
    import blf

    if VERSION >= (4, 0, 0):
        blf.size(font, points)
    else:
        blf.size(font, points, 72)
