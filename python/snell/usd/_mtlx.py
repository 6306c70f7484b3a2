"""MaterialX surfaces (standard_surface, OpenPBR's open_pbr_surface) read for snell's material.

Two ways a stage gives them:

- inline, as UsdShade shaders in the `mtlx` render context (outputs:mtlx:surface
  connected to a shader of id ND_standard_surface_surfaceshader or
  ND_open_pbr_surface_surfaceshader): read with pxr alone;
- in a .mtlx document a prim references. usd-core has no MaterialX file format
  plugin, so USD cannot compose the reference and every binding into it
  targets a prim that does not exist. The binding's target is then mapped into
  the document as USD's own plugin lays it out (the document's root is
  /MaterialX, its materials /MaterialX/Materials/NAME) and the material read
  with the MaterialX Python package (PyPI's MaterialX, an optional extra like
  OpenImageIO).

Either way each input is a constant, an image (an `image` or `tiledimage`
node, directly or through a nodegraph's output), or a connection snell cannot
evaluate (its default is used, with a warning). MaterialSurface.fields then
maps them onto snell's material (docs/usd.md, MaterialX).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Optional

from pxr import Ar, Sdf, Usd, UsdShade

#: snell's render contexts, in priority order: a Material with an mtlx surface draws it, else its universal one.
RENDER_CONTEXT = "mtlx"

# The defaults of MaterialX 1.39's nodedefs (libraries/bxdf), for the inputs snell maps or warns about.
STANDARD_SURFACE: dict[str, Any] = {
    "base": 1.0, "base_color": (0.8, 0.8, 0.8), "diffuse_roughness": 0.0, "metalness": 0.0, "specular": 1.0,
    "specular_color": (1.0, 1.0, 1.0), "specular_roughness": 0.2, "specular_IOR": 1.5, "specular_anisotropy": 0.0,
    "transmission": 0.0, "transmission_color": (1.0, 1.0, 1.0), "transmission_depth": 0.0,
    "transmission_scatter": (0.0, 0.0, 0.0), "transmission_dispersion": 0.0, "transmission_extra_roughness": 0.0,
    "subsurface": 0.0, "sheen": 0.0, "coat": 0.0, "thin_film_thickness": 0.0, "emission": 0.0,
    "emission_color": (1.0, 1.0, 1.0), "opacity": (1.0, 1.0, 1.0), "thin_walled": False,
}
OPEN_PBR_SURFACE: dict[str, Any] = {
    "base_weight": 1.0, "base_color": (0.8, 0.8, 0.8), "base_diffuse_roughness": 0.0, "base_metalness": 0.0,
    "specular_weight": 1.0, "specular_color": (1.0, 1.0, 1.0), "specular_roughness": 0.3, "specular_ior": 1.5,
    "specular_roughness_anisotropy": 0.0, "transmission_weight": 0.0, "transmission_color": (1.0, 1.0, 1.0),
    "transmission_depth": 0.0, "transmission_scatter": (0.0, 0.0, 0.0), "transmission_dispersion_scale": 0.0,
    "transmission_dispersion_abbe_number": 20.0, "subsurface_weight": 0.0, "fuzz_weight": 0.0, "coat_weight": 0.0,
    "thin_film_weight": 0.0, "emission_luminance": 0.0, "emission_color": (1.0, 1.0, 1.0), "geometry_opacity": 1.0,
    "geometry_thin_walled": False,
}
# MaterialX's own UsdPreviewSurface node (libraries/bxdf/usd_preview_surface.mtlx), as UsdShade's.
PREVIEW_SURFACE: dict[str, Any] = {
    "diffuseColor": (0.18, 0.18, 0.18), "emissiveColor": (0.0, 0.0, 0.0), "useSpecularWorkflow": 0,
    "specularColor": (0.0, 0.0, 0.0), "metallic": 0.0, "roughness": 0.5, "clearcoat": 0.0,
    "clearcoatRoughness": 0.01, "opacity": 1.0, "opacityThreshold": 0.0, "ior": 1.5, "displacement": 0.0,
    "occlusion": 1.0,
}
# Each surface's inputs by what they mean to snell (None: not an input of that surface; its neutral value).
_MEANINGS = {
    "standard_surface": dict(weight="base", colour="base_color", roughness="specular_roughness", ior="specular_IOR",
                             transmission="transmission", tint="transmission_color", depth="transmission_depth",
                             thin="thin_walled", opacity="opacity", emission="emission",
                             emission_colour="emission_color"),
    "open_pbr_surface": dict(weight="base_weight", colour="base_color", roughness="specular_roughness",
                             ior="specular_ior", transmission="transmission_weight", tint="transmission_color",
                             depth="transmission_depth", thin="geometry_thin_walled", opacity="geometry_opacity",
                             emission="emission_luminance", emission_colour="emission_color"),
    # Glass by snell's UsdPreviewSurface rule (docs/usd.md): opacity below 1 transmits, diffuseColor tints.
    "UsdPreviewSurface": dict(weight=None, colour="diffuseColor", roughness="roughness", ior="ior",
                              transmission=None, tint="diffuseColor", depth=None, thin=None, opacity="opacity",
                              emission=None, emission_colour="emissiveColor"),
}
_NEUTRAL = {"weight": 1.0, "transmission": 0.0, "depth": 0.0, "thin": False, "emission": 1.0}
SURFACES = {"standard_surface": ("MaterialX standard_surface", STANDARD_SURFACE),
            "open_pbr_surface": ("OpenPBR", OPEN_PBR_SURFACE),
            "UsdPreviewSurface": ("MaterialX UsdPreviewSurface", PREVIEW_SURFACE)}
_SHADER_IDS = {f"ND_{name}_surfaceshader": name for name in SURFACES}
_IMAGE_CATEGORIES = ("image", "tiledimage")
_SRGB_SPACES = ("srgb_texture", "srgb_displayp3")
_LINEAR_SPACES = ("lin_rec709", "lin_srgb", "raw", "acescg", "lin_ap1")


class MtlxError(Exception):
    """A MaterialX document or material snell cannot read (the message says which and why)."""


@dataclass
class Image:
    """An image node an input reads: its file as authored and as resolved, and its colour space."""

    where: str  #: the node, for messages
    file: str
    resolved: str
    color_space: str  #: UsdUVTexture's terms: sRGB, raw or auto


@dataclass
class Input:
    """One input of the surface: a constant, an image, or what it is connected to that snell cannot evaluate."""

    value: Any = None
    image: Optional[Image] = None
    unsupported: str = ""


@dataclass
class Surface:
    """A MaterialX surface shader's authored inputs."""

    kind: str  #: standard_surface or open_pbr_surface
    where: str  #: the shader, for messages
    inputs: dict[str, Input] = field(default_factory=dict)

    @property
    def label(self) -> str:
        return SURFACES[self.kind][0]

    def value(self, meaning: str) -> Any:
        """The constant of the input that means `meaning` to snell (its default where unauthored or connected)."""
        name = _MEANINGS[self.kind][meaning]
        return _NEUTRAL[meaning] if name is None else self.constant(name)

    def constant(self, name: str) -> Any:
        """An input's constant, its default where unauthored or connected."""
        given = self.inputs.get(name)
        return SURFACES[self.kind][1][name] if given is None or given.value is None else given.value

    def dispersion(self) -> float:
        """snell's dispersion (KHR_materials_dispersion: 20 / Abbe number) of the surface's glass."""
        if self.kind == "open_pbr_surface":
            scale = float(self.constant("transmission_dispersion_scale"))
            abbe = float(self.constant("transmission_dispersion_abbe_number"))
        elif self.kind == "standard_surface":  # its transmission_dispersion is an Abbe number, 0 for none
            scale, abbe = 1.0, float(self.constant("transmission_dispersion"))
        else:
            return 0.0
        return scale * 20.0 / abbe if scale > 0.0 and abbe > 0.0 else 0.0

    def image(self, meaning: str) -> Optional[Image]:
        given = self.inputs.get(_MEANINGS[self.kind][meaning] or "")
        return given.image if given is not None else None

    def unmapped(self) -> list[str]:
        """What snell leaves out: each authored input it does not map that differs from its default, and each
        connection it cannot evaluate (images are mapped on the base colour alone)."""
        mapped = set(_MEANINGS[self.kind].values()) - {None}
        dispersion = {"transmission_dispersion", "transmission_dispersion_scale", "transmission_dispersion_abbe_number"}
        defaults = SURFACES[self.kind][1]
        said = []
        for name, given in sorted(self.inputs.items()):
            if given.unsupported:
                said.append(f"inputs:{name} ({given.unsupported}): its default is used")
            elif given.image is not None and name != _MEANINGS[self.kind]["colour"]:
                said.append(f"inputs:{name} reads the image {given.image.file}, which snell maps on the base colour "
                            "only: its default is used")
            elif name not in mapped and name not in dispersion and given.value is not None \
                    and not _same(given.value, defaults.get(name)):
                said.append(f"inputs:{name} is {_text(given.value)}, which snell does not draw: ignored")
        return said


def surface_of_shader(shader: UsdShade.Shader, time: Usd.TimeCode) -> Optional[Surface]:
    """An inline MaterialX surface shader (its id ND_<surface>_surfaceshader) and its inputs; None for other ids."""
    kind = _SHADER_IDS.get(shader.GetShaderId() or "")
    if kind is None:
        return None
    surface = Surface(kind, str(shader.GetPath()))
    for given in shader.GetInputs():
        attributes = given.GetValueProducingAttributes()
        if not attributes:
            continue
        attribute = attributes[0]
        base, kind_of = UsdShade.Utils.GetBaseNameAndType(attribute.GetName())
        if kind_of != UsdShade.AttributeType.Output:
            surface.inputs[given.GetBaseName()] = Input(value=_plain(attribute.Get(time)))
            continue
        node = UsdShade.Shader(attribute.GetPrim())
        node_id = node.GetShaderId() or ""
        if any(node_id.startswith(f"ND_{c}_") for c in _IMAGE_CATEGORIES):
            file_input = node.GetInput("file")
            asset = file_input.Get(time) if file_input else None
            if asset is not None and asset.path:
                space = file_input.GetAttr().GetColorSpace() if file_input else ""
                surface.inputs[given.GetBaseName()] = Input(image=Image(
                    str(node.GetPath()), asset.path, asset.resolvedPath or "", _color_space(space)))
                continue
        surface.inputs[given.GetBaseName()] = Input(unsupported=f"connected to {node.GetPath()}, "
                                                                f"{node_id or 'no id'}")
    return surface


def referenced_document(stage: Usd.Stage, target: Sdf.Path) -> Optional[tuple[str, str, str]]:
    """Where a binding's missing target lies in a .mtlx document a prim above it references: (the document as
    authored, as resolved, the material's name); None where no ancestor references one."""
    path = target
    while path != Sdf.Path.absoluteRootPath and not path.isEmpty:
        prim = stage.GetPrimAtPath(path)
        if prim and prim.IsValid():
            for spec in prim.GetPrimStack():
                for reference in spec.referenceList.GetAddedOrExplicitItems():
                    if os.path.splitext(reference.assetPath)[1].lower() != ".mtlx":
                        continue
                    inner = reference.primPath if not reference.primPath.isEmpty else Sdf.Path("/MaterialX")
                    inside = inner.AppendPath(target.MakeRelativePath(path)) if target != path else inner
                    resolved = Ar.GetResolver().Resolve(
                        Sdf.ComputeAssetPathRelativeToLayer(spec.layer, reference.assetPath))
                    return reference.assetPath, str(resolved), inside.name
        path = path.GetParentPath()
    return None


def surface_of_document(document_path: str, shown: str, material_name: str) -> Surface:
    """The surface shader of a material in a .mtlx document, read with the MaterialX package."""
    try:
        import MaterialX as mx
    except ImportError:
        raise MtlxError(f"{shown} is a MaterialX document, which needs the MaterialX Python package "
                        "(pip install MaterialX, or snell's 'mtlx' extra)") from None
    document = mx.createDocument()
    try:
        mx.readFromXmlFile(document, document_path)
    except Exception as e:  # MaterialX raises its own ExceptionParseError and plain OSErrors
        raise MtlxError(f"{shown}: not a MaterialX document snell can read ({e})") from None
    material = document.getNode(material_name)
    if material is None or material.getType() != "material":
        names = ", ".join(m.getName() for m in document.getMaterialNodes()) or "none"
        raise MtlxError(f"{shown} has no material '{material_name}' (its materials: {names})")
    shaders = [s for s in mx.getShaderNodes(material) if s.getCategory() in SURFACES]
    if not shaders:
        found = ", ".join(s.getCategory() for s in mx.getShaderNodes(material)) or "none"
        raise MtlxError(f"{shown}: material '{material_name}' has no standard_surface or open_pbr_surface shader "
                        f"(its surface: {found})")
    shader = shaders[0]
    folder = os.path.dirname(document_path)
    surface = Surface(shader.getCategory(), f"{shown}: material {material_name}, shader {shader.getName()}")
    for given in shader.getInputs():
        node = given.getConnectedNode()
        if node is None and not given.getNodeName() and not given.getNodeGraphString() and not given.getOutputString():
            surface.inputs[given.getName()] = Input(value=_plain(given.getValue()))
        elif node is not None and node.getCategory() in _IMAGE_CATEGORIES and node.getInput("file") is not None:
            file_input = node.getInput("file")
            authored = file_input.getValueString()
            resolved = os.path.join(folder, file_input.getResolvedValueString())
            surface.inputs[given.getName()] = Input(image=Image(
                f"{shown}: {node.getName()}", authored, resolved if os.path.isfile(resolved) else "",
                _color_space(file_input.getActiveColorSpace())))
        else:
            what = node.getCategory() if node is not None else "a nodegraph"
            surface.inputs[given.getName()] = Input(unsupported=f"connected to {what}, which snell cannot evaluate")
    return surface


def _color_space(space: str) -> str:
    space = (space or "").lower()
    return "sRGB" if space in _SRGB_SPACES else "raw" if space in _LINEAR_SPACES else "auto"


def _plain(value: Any) -> Any:
    """USD's and MaterialX's values as floats, tuples and bools."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)):
        return float(value)
    if hasattr(value, "asTuple"):
        return tuple(float(c) for c in value.asTuple())
    try:
        return tuple(float(c) for c in value)
    except TypeError:
        return value


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(abs(x - y) < 1e-9 for x, y in zip(a, b))
    return a == b


def _text(value: Any) -> str:
    if isinstance(value, tuple):
        return "(" + ", ".join(f"{c:g}" for c in value) + ")"
    return f"{value:g}" if isinstance(value, float) else str(value)
