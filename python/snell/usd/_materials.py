"""UsdPreviewSurface materials as snell materials, bound with a material purpose.

The binding is UsdShade's own resolution (ComputeBoundMaterial): the purpose
asked for (preview, by default) first, the all-purpose binding otherwise.
usd-core carries no shader definitions, so an unauthored input takes the
fallback of the UsdPreviewSurface specification (PREVIEW_FALLBACKS). The
refractive case: a surface whose opacity is below 1, in the 'transparent'
opacity mode and without an opacityThreshold, is glass; snell's transmission
is 1 - opacity (any value above 0 refracts), its IOR is `ior` and its
diffuseColor tints the light through it (docs/usd.md). Everything else snell
cannot draw is a warning that names the shader and the input.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from pxr import Usd, UsdGeom, UsdShade

from .. import Material
from ._problems import Problems
from ._textures import TextureReadError, TextureRequest, read_texture

# UsdPreviewSurface's fallbacks (usdImaging/plugin/usdShaders/shaders/shaderDefs.usda,
# which usd-core does not ship) and UsdUVTexture's.
PREVIEW_FALLBACKS: dict[str, Any] = {
    "diffuseColor": (0.18, 0.18, 0.18), "emissiveColor": (0.0, 0.0, 0.0), "useSpecularWorkflow": 0,
    "specularColor": (0.0, 0.0, 0.0), "metallic": 0.0, "roughness": 0.5, "clearcoat": 0.0,
    "clearcoatRoughness": 0.01, "opacity": 1.0, "opacityMode": "transparent", "opacityThreshold": 0.0,
    "ior": 1.5, "normal": (0.0, 0.0, 1.0), "displacement": 0.0, "occlusion": 1.0,
}
TEXTURE_FALLBACKS: dict[str, Any] = {
    "wrapS": "useMetadata", "wrapT": "useMetadata", "fallback": (0.0, 0.0, 0.0, 1.0), "scale": (1.0, 1.0, 1.0, 1.0),
    "bias": (0.0, 0.0, 0.0, 0.0), "sourceColorSpace": "auto",
}
PURPOSES = {"preview": UsdShade.Tokens.preview, "full": UsdShade.Tokens.full, "all": UsdShade.Tokens.allPurpose}


@dataclass
class Source:
    """A shader output an input is connected to."""

    shader: UsdShade.Shader
    output: str

    @property
    def id(self) -> str:
        return self.shader.GetShaderId() or ""

    @property
    def path(self) -> str:
        return str(self.shader.GetPath())


@dataclass
class MaterialRecord:
    """One snell material and what the meshes using it must provide (their st primvar, transformed)."""

    path: str  #: the material prim, '' for a mesh without one
    fields: dict[str, Any]  #: snell.Material's keyword arguments, base_color_texture left out
    texture: Optional[TextureRequest] = None  #: the diffuse texture, if any
    texture_fallback: tuple[float, float, float] = (0.0, 0.0, 0.0)
    st_primvar: str = "st"
    st_transform: Optional[np.ndarray] = None  #: UsdTransform2d as a 3x3 on (s, t, 1)
    wraps: tuple[str, str] = ("repeat", "repeat")
    texture_prim: str = ""
    summary: str = ""
    texture_index: int = -1
    double_sided: bool = False

    def snell_material(self) -> Material:
        return Material(name=self.path, base_color_texture=self.texture_index, double_sided=self.double_sided,
                        **self.fields)


class MaterialTable:
    """The stage's materials as snell indices, each read once per (material, double-sidedness)."""

    def __init__(self, time: Usd.TimeCode, purpose: str, problems: Problems, load_textures: bool = True) -> None:
        if purpose not in PURPOSES:
            raise ValueError(f"material purpose must be one of {', '.join(PURPOSES)}, got '{purpose}'")
        self.time = time
        self.purpose = purpose
        self.problems = problems
        self.load_textures = load_textures
        self.records: list[MaterialRecord] = []
        self.textures: list[np.ndarray] = []
        self.texture_paths: list[str] = []
        self._read: dict[str, MaterialRecord] = {}
        self._index: dict[tuple, int] = {}
        self._texture_index: dict[TextureRequest, int] = {}

    def bound_material(self, prim: Usd.Prim) -> Optional[UsdShade.Material]:
        """The material bound to prim (or a GeomSubset) for the purpose, else its all-purpose one."""
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(materialPurpose=PURPOSES[self.purpose])
        return material if material and material.GetPrim().IsValid() else None

    def index_for(self, prim: Usd.Prim, mesh: Usd.Prim, double_sided: bool) -> int:
        """The snell material of prim (a mesh or one of its subsets), made on first use."""
        material = self.bound_material(prim)
        if material is None:
            colour = _display_color(mesh, self.time, self.problems)
            key: tuple = ("", colour, double_sided)
            if key not in self._index:
                fields = _surface_fields({})
                fields["base_color"] = (*colour, 1.0)
                record = MaterialRecord(path="", fields=fields, double_sided=double_sided,
                                        summary=f"no material: UsdPreviewSurface fallbacks, colour {_fmt(colour)}")
                self._index[key] = self._append(record)
            return self._index[key]
        path = str(material.GetPath())
        key = (path, None, double_sided)
        if key not in self._index:
            if path not in self._read:
                self._read[path] = self._read_material(material)
            template = self._read[path]
            record = MaterialRecord(**{**template.__dict__, "fields": dict(template.fields),
                                       "double_sided": double_sided})
            self._index[key] = self._append(record)
        return self._index[key]

    def _append(self, record: MaterialRecord) -> int:
        if record.texture is not None:
            record.texture_index = self._texture(record)
        self.records.append(record)
        return len(self.records) - 1

    def _texture(self, record: MaterialRecord) -> int:
        request = record.texture
        if request in self._texture_index:
            return self._texture_index[request]
        if self.load_textures:
            try:
                rgba = read_texture(request)
            except TextureReadError as e:
                self.problems.fail(record.texture_prim, str(e))
                record.fields["base_color"] = (*record.texture_fallback, 1.0)
                record.texture = None
                return -1
        else:
            rgba = np.zeros((1, 1, 4), np.uint8)
        self.textures.append(rgba)
        self.texture_paths.append(request.path)
        self._texture_index[request] = len(self.textures) - 1
        return self._texture_index[request]

    # ------------------------------------------------------------------ reading

    def _read_material(self, material: UsdShade.Material) -> MaterialRecord:
        path = str(material.GetPath())
        shader, _, _ = material.ComputeSurfaceSource()
        if not shader:
            contexts = [o.GetBaseName() for o in material.GetOutputs() if o.GetBaseName().endswith(":surface")]
            more = f" (only for render contexts: {', '.join(contexts)})" if contexts else ""
            self.problems.warn(path, f"has no universal surface output{more}: drawn with UsdPreviewSurface's fallbacks")
            return MaterialRecord(path=path, fields=_surface_fields({}), summary="no surface: fallbacks")
        shader_id = shader.GetShaderId()
        if shader_id != "UsdPreviewSurface":
            what = f"id '{shader_id}'" if shader_id else "no info:id (its implementation is a source or asset)"
            self.problems.warn(shader.GetPath(), f"the surface has {what}, not UsdPreviewSurface: "
                                                 "drawn with UsdPreviewSurface's fallbacks")
            return MaterialRecord(path=path, fields=_surface_fields({}), summary=f"unsupported surface {shader_id}")
        return self._read_preview_surface(path, shader)

    def _input(self, shader: UsdShade.Shader, name: str) -> tuple[Any, Optional[Source]]:
        """An input's value (None: unauthored) or the shader output it is connected to, through interfaces."""
        given = shader.GetInput(name)
        if not given:
            return None, None
        attributes = given.GetValueProducingAttributes()
        if not attributes:
            return None, None
        attribute = attributes[0]
        base, kind = UsdShade.Utils.GetBaseNameAndType(attribute.GetName())
        if kind == UsdShade.AttributeType.Output:
            return None, Source(UsdShade.Shader(attribute.GetPrim()), base)
        if attribute.ValueMightBeTimeVarying():
            self.problems.warn(shader.GetPath(), f"inputs:{name} is animated; snell reads it once, at time code "
                                                 f"{_time_text(self.time)}")
        return attribute.Get(self.time), None

    def _value(self, shader: UsdShade.Shader, name: str, fallbacks: dict[str, Any], connected_note: str = "") -> Any:
        value, source = self._input(shader, name)
        if source is not None:
            note = connected_note or f"snell reads only a constant here: its fallback {_fmt(fallbacks[name])} is used"
            self.problems.warn(shader.GetPath(), f"inputs:{name} is connected to {source.path} "
                                                 f"({source.id or 'no id'}); {note}")
            return fallbacks[name]
        return fallbacks[name] if value is None else value

    def _read_preview_surface(self, path: str, shader: UsdShade.Shader) -> MaterialRecord:
        where = shader.GetPath()
        values = {name: self._value(shader, name, PREVIEW_FALLBACKS)
                  for name in ("roughness", "ior", "metallic", "opacityThreshold", "useSpecularWorkflow", "clearcoat",
                               "opacityMode")}
        values["opacity"] = self._value(shader, "opacity", PREVIEW_FALLBACKS,
                                        "snell cannot vary opacity across a surface: drawn opaque (opacity 1)")
        emissive, emissive_source = self._input(shader, "emissiveColor")
        if emissive_source is not None:
            self.problems.warn(where, f"inputs:emissiveColor is connected to {emissive_source.path} "
                                      f"({emissive_source.id or 'no id'}); snell's materials take no emissive texture "
                                      "yet: no emission")
            emissive = None
        values["emissiveColor"] = PREVIEW_FALLBACKS["emissiveColor"] if emissive is None else emissive
        normal, normal_source = self._input(shader, "normal")
        if normal_source is not None:
            self.problems.warn(where, f"inputs:normal is connected to {normal_source.path} "
                                      f"({normal_source.id or 'no id'}); snell's materials take no normal map yet: "
                                      "ignored")
        elif normal is not None and not np.allclose(tuple(normal), PREVIEW_FALLBACKS["normal"]):
            self.problems.warn(where, f"inputs:normal is {_fmt(normal)}; snell shades with the mesh's normals")
        for name, note in (("occlusion", "ignored"), ("displacement", "ignored: the mesh is drawn undisplaced"),
                           ("clearcoatRoughness", "ignored")):
            value, source = self._input(shader, name)
            if source is not None or (name == "displacement" and value not in (None, 0.0)):
                target = f"connected to {source.path}" if source is not None else f"{_fmt(value)}"
                self.problems.warn(where, f"inputs:{name} is {target}; {note}")
        if values["metallic"] > 0:
            self.problems.warn(where, f"inputs:metallic is {values['metallic']:g}; snell shades dielectrics: ignored")
        if values["useSpecularWorkflow"]:
            self.problems.warn(where, "useSpecularWorkflow is on; snell shades the metallic workflow's dielectric: "
                                      "specularColor is ignored")
        if values["clearcoat"] > 0:
            self.problems.warn(where, f"inputs:clearcoat is {values['clearcoat']:g}; snell has no clear coat: ignored")

        record = MaterialRecord(path=path, fields={})
        diffuse, diffuse_source = self._input(shader, "diffuseColor")
        colour = tuple(PREVIEW_FALLBACKS["diffuseColor"] if diffuse is None else diffuse)
        if diffuse_source is not None:
            if diffuse_source.id == "UsdUVTexture" and diffuse_source.output in ("rgb", "rgba", "r", "g", "b", "a"):
                colour = self._read_texture(record, diffuse_source)
            else:
                self.problems.warn(where, f"inputs:diffuseColor is connected to {diffuse_source.path} "
                                          f"({diffuse_source.id or 'no id'}, output {diffuse_source.output}), which "
                                          f"snell cannot evaluate: its fallback {_fmt(colour)} is used")
        opacity = float(values["opacity"])
        threshold = float(values["opacityThreshold"])
        transmission = 0.0
        if opacity < 1.0:
            if threshold > 0.0:
                if opacity < threshold:
                    self.problems.warn(where, f"opacity {opacity:g} under opacityThreshold {threshold:g} cuts the "
                                              "surface out; snell has no cut-outs: drawn opaque")
            elif values["opacityMode"] == "presence":
                self.problems.warn(where, f"opacity {opacity:g} in opacityMode 'presence' is coverage, not glass; "
                                          "snell has no partial coverage: drawn opaque")
            else:
                transmission = 1.0 - max(opacity, 0.0)
        record.fields = _surface_fields(values)
        record.fields["base_color"] = (*(float(c) for c in colour), 1.0) if record.texture is None else (1, 1, 1, 1)
        record.fields["transmission"] = transmission
        kind = f"glass (opacity {opacity:g}, ior {float(values['ior']):g})" if transmission > 0 else "opaque"
        colour_text = f"texture {record.texture.path}" if record.texture is not None else f"colour {_fmt(colour)}"
        record.summary = f"UsdPreviewSurface, {kind}, {colour_text}, roughness {float(values['roughness']):g}"
        return record

    def _read_texture(self, record: MaterialRecord, source: Source) -> tuple:
        """Fills record's texture from a UsdUVTexture; returns the colour to use when there is none."""
        texture = source.shader
        where = texture.GetPath()
        record.texture_prim = str(where)
        fallback = self._value(texture, "fallback", TEXTURE_FALLBACKS)
        scale = tuple(float(c) for c in self._value(texture, "scale", TEXTURE_FALLBACKS))
        bias = tuple(float(c) for c in self._value(texture, "bias", TEXTURE_FALLBACKS))
        # What the shader sees when the file cannot be read: the fallback, scaled and biased.
        seen = np.asarray(tuple(fallback)[:4], float) * np.asarray(scale) + np.asarray(bias)
        channel = "rgba".index(source.output) if source.output in "rgba" and len(source.output) == 1 else None
        record.texture_fallback = tuple(float(seen[channel]) for _ in range(3)) if channel is not None else \
            tuple(float(c) for c in seen[:3])
        asset = self._value(texture, "file", {"file": None})
        if asset is None or not asset.path:
            self.problems.warn(where, "inputs:file is not set: the texture's fallback is used")
            return record.texture_fallback
        if "<UDIM>" in asset.path.upper():
            self.problems.warn(where, f"inputs:file {asset.path} is a UDIM set; snell reads single images: the "
                                      "texture's fallback is used")
            return record.texture_fallback
        if not asset.resolvedPath:
            self.problems.fail(where, f"texture file {asset.path} not found (it resolves to nothing from "
                                      f"{_layer_of(texture, 'file')})")
            return record.texture_fallback
        wraps = tuple(str(self._value(texture, name, TEXTURE_FALLBACKS)) for name in ("wrapS", "wrapT"))
        color_space = str(self._value(texture, "sourceColorSpace", TEXTURE_FALLBACKS))
        if color_space not in ("auto", "raw", "sRGB"):
            self.problems.warn(where, f"sourceColorSpace '{color_space}' is not auto, raw or sRGB: read as auto")
            color_space = "auto"
        record.texture = TextureRequest(asset.resolvedPath, color_space, scale, bias, source.output)
        record.wraps = wraps
        record.st_primvar, record.st_transform = self._st_of(texture)
        return (1.0, 1.0, 1.0)

    def _st_of(self, texture: UsdShade.Shader) -> tuple[str, Optional[np.ndarray]]:
        """The primvar a texture's st reads, through a UsdTransform2d if there is one."""
        where = texture.GetPath()
        value, source = self._input(texture, "st")
        transform = None
        if source is not None and source.id == "UsdTransform2d":
            transform = self._transform2d(source.shader)
            value, source = self._input(source.shader, "in")
        if source is None:
            if value is not None:
                self.problems.warn(where, f"inputs:st is the constant {_fmt(value)}; snell reads primvars:st instead")
            else:
                self.problems.warn(where, "inputs:st is not connected to a primvar reader: snell reads primvars:st")
            return "st", transform
        if not source.id.startswith("UsdPrimvarReader_"):
            self.problems.warn(where, f"inputs:st comes from {source.path} ({source.id or 'no id'}), not a "
                                      "UsdPrimvarReader_float2: snell reads primvars:st")
            return "st", transform
        name, _ = self._input(source.shader, "varname")
        if not name:
            self.problems.warn(source.path, "inputs:varname is not set: snell reads primvars:st")
            return "st", transform
        return str(name), transform

    def _transform2d(self, shader: UsdShade.Shader) -> np.ndarray:
        # UsdTransform2d: result = in * scale, rotated counter-clockwise by rotation degrees, + translation.
        rotation = math.radians(float(self._value(shader, "rotation", {"rotation": 0.0})))
        scale = self._value(shader, "scale", {"scale": (1.0, 1.0)})
        translation = self._value(shader, "translation", {"translation": (0.0, 0.0)})
        c, s = math.cos(rotation), math.sin(rotation)
        return np.array([[c * scale[0], -s * scale[1], translation[0]],
                         [s * scale[0], c * scale[1], translation[1]],
                         [0.0, 0.0, 1.0]])


def _surface_fields(values: dict[str, Any]) -> dict[str, Any]:
    """snell.Material's keyword arguments from UsdPreviewSurface values (fallbacks where missing)."""
    v = {**PREVIEW_FALLBACKS, **values}
    return {"roughness": float(v["roughness"]), "ior": float(v["ior"]),
            "emissive": tuple(float(c) for c in v["emissiveColor"]), "transmission": 0.0,
            "base_color": (*(float(c) for c in v["diffuseColor"]), 1.0)}


def _display_color(mesh: Usd.Prim, time: Usd.TimeCode, problems: Problems) -> tuple[float, float, float]:
    """An unbound mesh's colour: its displayColor when it has a single value, else the preview fallback."""
    primvar = UsdGeom.Gprim(mesh).GetDisplayColorPrimvar()
    if primvar and primvar.HasAuthoredValue():
        values = primvar.ComputeFlattened(time)
        if values is not None and len(values) >= 1:
            if len(values) > 1 and primvar.GetInterpolation() != UsdGeom.Tokens.constant:
                problems.warn(mesh.GetPath(), f"primvars:displayColor varies ({primvar.GetInterpolation()}); snell "
                                              "has no vertex colours: its first value is used")
            return tuple(float(c) for c in values[0])
    return tuple(PREVIEW_FALLBACKS["diffuseColor"])


def _layer_of(shader: UsdShade.Shader, name: str) -> str:
    """The layer that authored an input: relative asset paths resolve from there."""
    attribute = shader.GetInput(name).GetAttr()
    for spec in attribute.GetPropertyStack(Usd.TimeCode.Default()):
        if spec.HasDefaultValue() or spec.layer.ListTimeSamplesForPath(spec.path):
            return spec.layer.identifier
    return shader.GetPrim().GetStage().GetRootLayer().identifier


def _fmt(value: Any) -> str:
    if isinstance(value, (tuple, list)) or hasattr(value, "__len__") and not isinstance(value, str):
        return "(" + ", ".join(f"{float(c):g}" for c in value) + ")"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _time_text(time: Usd.TimeCode) -> str:
    return "default" if time.IsDefault() else f"{time.GetValue():g}"


