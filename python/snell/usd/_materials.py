"""UsdPreviewSurface materials as snell materials, bound with a material purpose.

The binding is UsdShade's own resolution (ComputeBoundMaterial): the purpose
asked for (preview, by default) first, the all-purpose binding otherwise.
usd-core carries no shader definitions, so an unauthored input takes the
fallback of the UsdPreviewSurface specification (PREVIEW_FALLBACKS). The
refractive case: a surface whose opacity is below 1, in the 'transparent'
opacity mode and without an opacityThreshold, is glass; snell's transmission
is 1 - opacity (any value above 0 refracts), its IOR is `ior` and its
diffuseColor tints the light through it (docs/usd.md). An opacityThreshold
above 0 is a cut-out (alpha mask) and opacityMode 'presence' is coverage
(alpha blend); a textured opacity is the alpha of the base colour texture.
UsdUVTextures feed diffuseColor, emissiveColor and normal, each with its own
wraps and UsdTransform2d (as the slot's KHR_texture_transform). Everything
else snell cannot draw is a warning that names the shader and the input.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Optional

import numpy as np
from pxr import Usd, UsdShade

from .. import Material, Texture, TextureTransform
from ._mtlx import RENDER_CONTEXT, MtlxError, Surface, referenced_document, surface_of_document, surface_of_shader
from ._problems import Problems
from ._textures import IDENTITY_SCALE, NO_BIAS, TextureImage, TextureReadError, TextureRequest, read_texture

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
TEXTURE_OUTPUTS = ("rgb", "rgba", "r", "g", "b", "a")
SNELL_WRAPS = ("repeat", "clamp", "mirror")  # UsdUVTexture's 'black' has no snell sampler
# The primvar readers a colour or an opacity reads a mesh's primvar through, and the values each gives.
_PRIMVAR_READER_SIZES = {"UsdPrimvarReader_float": 1, "UsdPrimvarReader_float3": 3, "UsdPrimvarReader_float4": 4}
PURPOSES = {"preview": UsdShade.Tokens.preview, "full": UsdShade.Tokens.full, "all": UsdShade.Tokens.allPurpose}

Transform = tuple[tuple[float, float], float, tuple[float, float]]  # KHR_texture_transform: offset, rotation, scale


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

    @property
    def is_texture(self) -> bool:
        """A UsdUVTexture output snell can read (the float4 rgba reads as its rgb or alpha, as connected)."""
        return self.id == "UsdUVTexture" and self.output in TEXTURE_OUTPUTS


@dataclass
class TextureSlot:
    """One texture of a material: how snell's texture is made from a UsdUVTexture and how it is sampled."""

    request: TextureRequest
    prim: str  #: the UsdUVTexture, for messages
    file: str  #: its file as authored, for summaries
    wraps: tuple[str, str]  #: wrapS, wrapT as authored
    st_primvar: str  #: the primvar its st reads
    transform: Optional[Transform] = None  #: its UsdTransform2d in snell's UV space (KHR_texture_transform)
    fallback: tuple[float, float, float] = (1.0, 1.0, 1.0)  #: the colour it gives when the file cannot be read
    fallback_alpha: float = 1.0  #: and its alpha (coverage), where it gives alpha
    factor: tuple[float, float, float] = (1.0, 1.0, 1.0)  #: emission: the scale folded into the emissive factor
    index: int = -1  #: snell's texture

    @property
    def snell_wraps(self) -> tuple[str, str]:
        """The sampler snell draws: 'black' and 'useMetadata' (black in files without wrap metadata) repeat."""
        return tuple(w if w in SNELL_WRAPS else "repeat" for w in self.wraps)

    def uv_matrix(self) -> np.ndarray:
        """The transform as a 3x3 on snell's (u, v, 1), as snell applies it."""
        return _khr_matrix(self.transform) if self.transform is not None else np.eye(3)


@dataclass(frozen=True)
class TextureRecord:
    """One snell texture of the stage: its texels, the name it goes by (its file) and its wraps."""

    rgba: np.ndarray  #: height x width x 4 bytes
    name: str
    wraps: tuple[str, str] = ("clamp", "clamp")  #: snell.Texture's wrap_s, wrap_t

    def snell_texture(self) -> Texture:
        return Texture(self.rgba, name=self.name, wrap_s=self.wraps[0], wrap_t=self.wraps[1])


@dataclass
class MaterialRecord:
    """One snell material and what the meshes using it must provide (the st primvar its textures read)."""

    path: str  #: the material prim, '' for a mesh without one
    fields: dict[str, Any]  #: snell.Material's keyword arguments but the textures and their transforms
    slots: dict[str, TextureSlot] = field(default_factory=dict)  #: 'base_color', 'emissive', 'normal'
    summary: str = ""
    double_sided: bool = False
    #: diffuseColor and opacity read from the mesh (a UsdPrimvarReader, or an unbound mesh's displayColor):
    #: (primvar name, the reader's fallback); each mesh resolves them (_colours.py)
    colour_primvar: Optional[tuple[str, tuple[float, float, float]]] = None
    opacity_primvar: Optional[tuple[str, float]] = None

    @property
    def st_primvar(self) -> Optional[str]:
        """The primvar the material's textures read (one UV set per snell mesh), None without textures."""
        return next(iter(self.slots.values())).st_primvar if self.slots else None

    def snell_material(self) -> Material:
        arguments = dict(self.fields)
        for name, slot in self.slots.items():
            arguments[f"{name}_texture"] = slot.index
            if slot.transform is not None:
                offset, rotation, scale = slot.transform
                arguments[f"{name}_transform"] = TextureTransform(offset=offset, rotation=rotation, scale=scale)
        return Material(name=self.path, double_sided=self.double_sided, **arguments)


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
        self.textures: list[TextureRecord] = []  # snell's texture i is textures[i]
        self._read: dict[str, MaterialRecord] = {}
        self._index: dict[tuple, int] = {}
        self._texture_index: dict[tuple, tuple[int, tuple[float, float, float]]] = {}

    def snell_textures(self) -> list[Texture]:
        return [texture.snell_texture() for texture in self.textures]

    def bound_material(self, prim: Usd.Prim) -> Optional[UsdShade.Material]:
        """The material bound to prim (or a GeomSubset) for the purpose, else its all-purpose one."""
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(materialPurpose=PURPOSES[self.purpose])
        return material if material and material.GetPrim().IsValid() else None

    def mtlx_binding(self, prim: Usd.Prim) -> Optional[tuple[str, str, str]]:
        """Where prim's binding leads into a .mtlx document USD could not compose: (the document as authored, as
        resolved, the material's name); None where it binds a prim or no document."""
        material, relationship = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(
            materialPurpose=PURPOSES[self.purpose])
        if (material and material.GetPrim().IsValid()) or not relationship:
            return None
        targets = relationship.GetTargets()
        return referenced_document(prim.GetStage(), targets[0]) if targets else None

    def index_for(self, prim: Usd.Prim, mesh: Usd.Prim, double_sided: bool) -> int:
        """The snell material of prim (a mesh or one of its subsets), made on first use."""
        material = self.bound_material(prim)
        document = self.mtlx_binding(prim) if material is None else None
        if document is not None:
            authored, resolved, name = document
            path = f"{authored}:{name}"
            key = (path, None, double_sided)
            if key not in self._index:
                if path not in self._read:
                    self._read[path] = self._read_mtlx_document(prim, authored, resolved, name)
                self._index[key] = self._append(self._copy(self._read[path], double_sided))
            return self._index[key]
        if material is None:
            key: tuple = ("", None, double_sided)
            if key not in self._index:
                fallback = tuple(PREVIEW_FALLBACKS["diffuseColor"])
                record = MaterialRecord(path="", fields=_surface_fields({}), double_sided=double_sided,
                                        summary="no material: UsdPreviewSurface fallbacks, colour from "
                                                f"primvars:displayColor (else {_fmt(fallback)})",
                                        colour_primvar=("displayColor", fallback))
                self._index[key] = self._append(record)
            return self._index[key]
        path = str(material.GetPath())
        key = (path, None, double_sided)
        if key not in self._index:
            if path not in self._read:
                self._read[path] = self._read_material(material)
            self._index[key] = self._append(self._copy(self._read[path], double_sided))
        return self._index[key]

    @staticmethod
    def _copy(template: MaterialRecord, double_sided: bool) -> MaterialRecord:
        return replace(template, fields=dict(template.fields), double_sided=double_sided,
                       slots={name: replace(slot) for name, slot in template.slots.items()})

    def variant(self, index: int, base_color: tuple, texture: int = -1) -> int:
        """Material `index` with a mesh's own base colour (a constant primvar) or colour texture (a varying one,
        _colours.py), made once per (material, colour, texture)."""
        key = ("variant", index, tuple(float(c) for c in base_color), texture)
        if key not in self._index:
            template = self.records[index]
            fields = dict(template.fields, base_color=tuple(float(c) for c in base_color))
            if texture >= 0:
                fields["base_color_texture"] = texture
            slots = {name: replace(slot) for name, slot in template.slots.items()
                     if texture < 0 or name != "base_color"}
            record = replace(template, fields=fields, slots=slots, colour_primvar=None, opacity_primvar=None)
            self.records.append(record)
            self._index[key] = len(self.records) - 1
        return self._index[key]

    def add_texture(self, rgba: np.ndarray, name: str, wraps: tuple[str, str] = ("clamp", "clamp")) -> int:
        """A texture snell's reader made itself (a mesh's colours), by index."""
        self.textures.append(TextureRecord(rgba, name, wraps))
        return len(self.textures) - 1

    def _append(self, record: MaterialRecord) -> int:
        for name, slot in list(record.slots.items()):
            index, gain = self._texture(slot)
            if index < 0:  # unreadable (an error already): what the shader gives without its file
                del record.slots[name]
                if name == "base_color":
                    r, g, b, a = record.fields["base_color"]
                    record.fields["base_color"] = (r * slot.fallback[0], g * slot.fallback[1], b * slot.fallback[2],
                                                   a * slot.fallback_alpha)
                elif name == "emissive":
                    record.fields["emissive"] = slot.fallback
                continue
            slot.index = index
            if name == "emissive":
                record.fields["emissive"] = tuple(f * g for f, g in zip(slot.factor, gain))
        self.records.append(record)
        return len(self.records) - 1

    def _texture(self, slot: TextureSlot) -> tuple[int, tuple[float, float, float]]:
        """snell's texture for a slot (one per conversion and sampler) and its emission gain; -1 if unreadable."""
        key = (slot.request, slot.snell_wraps)
        if key in self._texture_index:
            return self._texture_index[key]
        if self.load_textures:
            try:
                image = read_texture(slot.request)
            except TextureReadError as e:
                # As a missing file: the input's fallback is drawn; strict readers (--strict) refuse the stage.
                self.problems.strict_error(slot.prim, f"{e}: the input's fallback is drawn")
                return -1, (1.0, 1.0, 1.0)
        else:
            image = TextureImage(np.zeros((1, 1, 4), np.uint8))
        self.textures.append(TextureRecord(image.rgba, slot.request.path, slot.snell_wraps))
        self._texture_index[key] = (len(self.textures) - 1, image.gain)
        return self._texture_index[key]

    # ------------------------------------------------------------------ reading

    def _read_material(self, material: UsdShade.Material) -> MaterialRecord:
        path = str(material.GetPath())
        shader, _, _ = material.ComputeSurfaceSource(RENDER_CONTEXT)  # snell's context first, then universal
        if not shader:
            contexts = [o.GetBaseName() for o in material.GetOutputs() if o.GetBaseName().endswith(":surface")]
            more = f" (only for render contexts: {', '.join(contexts)})" if contexts else ""
            self.problems.warn(path, f"has no universal surface output{more}: drawn with UsdPreviewSurface's fallbacks")
            return MaterialRecord(path=path, fields=_surface_fields({}), summary="no surface: fallbacks")
        shader_id = shader.GetShaderId()
        surface = surface_of_shader(shader, self.time)
        if surface is not None:
            return self._read_mtlx_surface(path, surface)
        if shader_id != "UsdPreviewSurface":
            what = f"id '{shader_id}'" if shader_id else "no info:id (its implementation is a source or asset)"
            self.problems.warn(shader.GetPath(), f"the surface has {what}, not UsdPreviewSurface: "
                                                 "drawn with UsdPreviewSurface's fallbacks")
            return MaterialRecord(path=path, fields=_surface_fields({}), summary=f"unsupported surface {shader_id}")
        return self._read_preview_surface(path, shader)

    def _read_mtlx_document(self, prim: Usd.Prim, authored: str, resolved: str, name: str) -> MaterialRecord:
        path = f"{authored}:{name}"
        try:
            if not resolved:
                raise MtlxError(f"MaterialX document {authored} not found")
            surface = surface_of_document(resolved, authored, name)
        except MtlxError as e:
            # As a texture snell cannot read: the material's fallback is drawn; --strict refuses the stage.
            self.problems.strict_error(prim.GetPath(), f"binds material '{name}' of {e}: drawn with "
                                                       "UsdPreviewSurface's fallbacks")
            return MaterialRecord(path=path, fields=_surface_fields({}), summary=f"MaterialX {path}: unread")
        record = self._read_mtlx_surface(path, surface)
        record.summary += f", from {authored}"
        return record

    def _read_mtlx_surface(self, path: str, surface: Surface) -> MaterialRecord:
        """A MaterialX surface as snell's material (docs/usd.md, MaterialX): base colour and weight, specular
        IOR and roughness, emission; transmission as glass, its colour a tint at the surface, or with a depth
        (and not thin-walled) the colour at that distance through the volume; opacity as coverage."""
        for said in surface.unmapped():
            self.problems.warn(surface.where, said)
        weight = float(surface.value("weight"))
        colour = tuple(weight * float(c) for c in surface.value("colour"))
        opacity_value = surface.value("opacity")
        opacity = float(sum(opacity_value) / len(opacity_value) if isinstance(opacity_value, tuple) else opacity_value)
        emissive = tuple(float(surface.value("emission")) * float(c) for c in surface.value("emission_colour"))
        record = MaterialRecord(path=path, fields=_surface_fields({}))
        record.fields.update(roughness=float(surface.value("roughness")), ior=float(surface.value("ior")),
                             emissive=emissive, base_color=(*colour, 1.0))
        transmission = float(surface.value("transmission"))
        if surface.kind == "UsdPreviewSurface" and opacity < 1.0:  # as UsdShade's UsdPreviewSurface: glass
            transmission, opacity = 1.0 - max(opacity, 0.0), 1.0
        image = surface.image("colour")
        if image is not None and transmission <= 0.0:
            if image.resolved:
                request = TextureRequest(image.resolved, image.color_space, output="rgb", kind="colour")
                record.slots["base_color"] = TextureSlot(request, image.where, image.file, ("repeat", "repeat"), "st")
                record.fields["base_color"] = (weight, weight, weight, 1.0)
            else:
                self.problems.strict_error(image.where, f"texture file {image.file} not found: the base colour "
                                                        f"{_fmt(colour)} is used")
        tint = tuple(float(c) for c in surface.value("tint"))
        depth, thin = float(surface.value("depth")), bool(surface.value("thin"))
        if transmission > 0.0:
            record.fields["transmission"] = min(transmission, 1.0)
            if depth > 0.0 and not thin:
                record.fields.update(base_color=(1.0, 1.0, 1.0, 1.0), thickness=depth, attenuation_color=tint,
                                     attenuation_distance=depth)
            else:
                record.fields["base_color"] = (*tint, 1.0)
            record.fields["dispersion"] = surface.dispersion()
            volume = f", absorbing to {_fmt(tint)} at {depth:g}" if "thickness" in record.fields else ""
            kind = (f"glass (transmission {transmission:g}, ior {record.fields['ior']:g}) transmitting "
                    f"{_fmt(tint)}{volume}{', thin-walled' if thin else ''}")
        elif opacity < 1.0:
            record.fields["base_color"] = (*record.fields["base_color"][:3], max(opacity, 0.0))
            record.fields["alpha_mode"] = "blend"
            kind = f"coverage: opacity {opacity:g} blends"
        else:
            kind = "opaque"
        colour_text = ("" if transmission > 0.0 else
                       f", texture {image.file}" if "base_color" in record.slots else f", colour {_fmt(colour)}")
        record.summary = f"{surface.label}, {kind}{colour_text}, roughness {record.fields['roughness']:g}"
        return record

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

    def _cannot_evaluate(self, where: Any, name: str, source: Source, fallback: Any) -> None:
        self.problems.warn(where, f"inputs:{name} is connected to {source.path} ({source.id or 'no id'}, output "
                                  f"{source.output}), which snell cannot evaluate: its fallback {_fmt(fallback)} "
                                  "is used")

    def _read_preview_surface(self, path: str, shader: UsdShade.Shader) -> MaterialRecord:
        where = shader.GetPath()
        values = {name: self._value(shader, name, PREVIEW_FALLBACKS)
                  for name in ("roughness", "ior", "metallic", "opacityThreshold", "useSpecularWorkflow", "clearcoat",
                               "opacityMode")}
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
        colour, colour_authored = self._diffuse(record, shader)
        values["emissiveColor"] = self._emissive(record, shader)
        normal_scale = self._normal(record, shader)
        threshold = float(values["opacityThreshold"])
        # UsdPreviewSurface: a threshold above 0 makes opacity a cut-out mask; 'presence' makes it coverage, and
        # so does an opacity that varies over the surface (a texture or a primvar: how exporters write alpha
        # blending, glTF's BLEND); otherwise a constant opacity below 1 is a translucent (here refractive) surface.
        _, opacity_source = self._input(shader, "opacity")
        coverage = ("mask" if threshold > 0.0 else
                    "blend" if values["opacityMode"] == "presence" or opacity_source is not None else None)
        opacity, alpha_varies = self._opacity(record, shader)
        record.fields = _surface_fields(values)
        record.fields["base_color"] = (*(float(c) for c in colour), opacity if coverage else 1.0)
        if coverage is not None and (alpha_varies or opacity < 1.0):
            record.fields["alpha_mode"] = coverage
            if coverage == "mask":
                record.fields["alpha_cutoff"] = threshold
        elif coverage is None and opacity < 1.0:
            record.fields["transmission"] = 1.0 - max(opacity, 0.0)
            if not colour_authored:
                # The transmission rule (docs/usd.md): an authored diffuseColor tints the light through glass
                # (the talk's cornea); unauthored, its 0.18 fallback is a surface's grey, not a tint: clear.
                record.fields["base_color"] = (1.0, 1.0, 1.0, 1.0)
                colour = (1.0, 1.0, 1.0)
        if "normal" in record.slots:
            record.fields["normal_scale"] = normal_scale
        record.summary = self._summary(record, colour, opacity, colour_authored)
        self._one_uv_set(record)
        return record

    def _colour(self, record: MaterialRecord, shader: UsdShade.Shader, name: str, kind: str,
                slot_name: str) -> tuple:
        """A colour input: its constant, or (a texture) the record's slot `slot_name` and the slot."""
        value, source = self._input(shader, name)
        constant = tuple(PREVIEW_FALLBACKS[name] if value is None else value)
        if source is None:
            return constant, None
        if not source.is_texture:
            self._cannot_evaluate(shader.GetPath(), name, source, constant)
            return constant, None
        slot, seen = self._texture_slot(source, kind)
        if slot is None:
            return _channel_colour(seen, source.output), None
        record.slots[slot_name] = slot
        return constant, slot

    def _diffuse(self, record: MaterialRecord, shader: UsdShade.Shader) -> tuple[tuple[float, float, float], bool]:
        """diffuseColor: the base colour factor (a texture goes into record's base colour slot, factor 1; a
        primvar reader into record.colour_primvar, each mesh's own), and whether the stage authored it."""
        value, source = self._input(shader, "diffuseColor")
        reader = self._primvar_reader(source)
        if reader is not None:
            record.colour_primvar = (reader[0], tuple(reader[1][:3]))
            return tuple(reader[1][:3]), True
        colour, slot = self._colour(record, shader, "diffuseColor", "colour", "base_color")
        return ((1.0, 1.0, 1.0) if slot is not None else colour), value is not None or source is not None

    def _primvar_reader(self, source: Optional[Source]) -> Optional[tuple[str, tuple[float, ...]]]:
        """A UsdPrimvarReader of a float or colour: (its varname, its fallback as a tuple); None otherwise."""
        if source is None or source.id not in _PRIMVAR_READER_SIZES:
            return None
        name, _ = self._input(source.shader, "varname")
        size = _PRIMVAR_READER_SIZES[source.id]
        fallback, _ = self._input(source.shader, "fallback")
        values = (0.0,) * size if fallback is None else tuple(np.atleast_1d(np.asarray(fallback, float)))
        if not name:
            self.problems.warn(source.path, "inputs:varname is not set: its fallback "
                                            f"{_fmt(values)} is used")
            return "", values
        return str(name), values

    def _emissive(self, record: MaterialRecord, shader: UsdShade.Shader) -> tuple[float, float, float]:
        """emissiveColor: the emissive factor; a texture goes into the emissive slot (factor set on reading)."""
        constant, slot = self._colour(record, shader, "emissiveColor", "emission", "emissive")
        return slot.factor if slot is not None else constant

    def _normal(self, record: MaterialRecord, shader: UsdShade.Shader) -> float:
        """normal: a texture goes into the normal slot; returns snell's normal_scale for it."""
        where = shader.GetPath()
        normal, source = self._input(shader, "normal")
        if source is None:
            if normal is not None and not np.allclose(tuple(normal), PREVIEW_FALLBACKS["normal"]):
                self.problems.warn(where, f"inputs:normal is {_fmt(normal)}; snell shades with the mesh's normals")
            return 1.0
        if not (source.is_texture and source.output in ("rgb", "rgba")):
            self.problems.warn(where, f"inputs:normal is connected to {source.path} ({source.id or 'no id'}, output "
                                      f"{source.output}), which snell cannot evaluate: the mesh's normals are used")
            return 1.0
        slot, _ = self._texture_slot(source, "normal")
        if slot is None:
            self.problems.warn(where, f"inputs:normal's texture {source.path} has no file to read: the mesh's "
                                      "normals are used")
            return 1.0
        record.slots["normal"] = slot
        # snell reads m = (2 byte/255 - 1) * (k, k, 1). A texture scaled (2k, 2k, 2) and biased (-k, -k, -1) is
        # k times the usual one in x and y: stored as the usual one, with normal_scale k, nothing clips.
        request = slot.request
        k = request.scale[0] / 2.0
        if (k != 0.0 and request.scale[1] == request.scale[0] and request.scale[2] == 2.0
                and request.bias[:3] == (-k, -k, -1.0)):
            slot.request = replace(request, scale=(2.0, 2.0, 2.0, 1.0), bias=(-1.0, -1.0, -1.0, 0.0))
            return k
        return 1.0

    def _opacity(self, record: MaterialRecord, shader: UsdShade.Shader) -> tuple[float, bool]:
        """opacity: its constant value, or True where it varies: a texture's channel became the base colour's
        alpha (the value then 1), or a primvar reader's (record.opacity_primvar; the value its fallback)."""
        where = shader.GetPath()
        value, source = self._input(shader, "opacity")
        opacity = float(PREVIEW_FALLBACKS["opacity"] if value is None else value)
        if source is None:
            return opacity, False
        reader = self._primvar_reader(source)
        if reader is not None:
            record.opacity_primvar = (reader[0], float(reader[1][0]))
            return float(reader[1][0]), True
        if not (source.is_texture and source.output in ("r", "g", "b", "a")):
            self._cannot_evaluate(where, "opacity", source, 1.0)
            return 1.0, False
        slot, seen = self._texture_slot(source, "colour")
        channel = "rgba".index(source.output)
        if slot is None:
            return float(seen[channel]), False
        alpha = dict(alpha=source.output, alpha_scale=slot.request.scale[channel],
                     alpha_bias=slot.request.bias[channel])
        base = record.slots.get("base_color")
        if base is None:
            # A constant diffuseColor leaves the base colour texture free: white, with the opacity as its alpha.
            record.slots["base_color"] = replace(slot, request=replace(slot.request, output="", scale=IDENTITY_SCALE,
                                                                       bias=NO_BIAS, **alpha),
                                                 fallback=(1.0, 1.0, 1.0), fallback_alpha=float(seen[channel]))
            return 1.0, True
        differs = _sampling_differs(base, slot, source.output)
        if differs:
            self.problems.warn(where, f"inputs:opacity reads {slot.prim} ({slot.file}), {differs} than the diffuse "
                                      f"texture {base.prim} ({base.file}); snell's alpha is its base colour texture's "
                                      "alpha: drawn opaque (opacity 1)")
            return 1.0, False
        base.request = replace(base.request, **alpha)
        base.fallback_alpha = float(seen[channel])
        return 1.0, True

    def _texture_slot(self, source: Source, kind: str) -> tuple[Optional[TextureSlot], np.ndarray]:
        """A UsdUVTexture as a slot of this kind (colour, emission or normal), and what it gives without its file
        (its fallback, scaled and biased); no slot where there is no file to read (said as a warning or error)."""
        texture = source.shader
        where = texture.GetPath()
        fallback = self._value(texture, "fallback", TEXTURE_FALLBACKS)
        scale = tuple(float(c) for c in self._value(texture, "scale", TEXTURE_FALLBACKS))
        bias = tuple(float(c) for c in self._value(texture, "bias", TEXTURE_FALLBACKS))
        seen = np.asarray(tuple(fallback)[:4], float) * np.asarray(scale) + np.asarray(bias)
        asset = self._value(texture, "file", {"file": None})
        if asset is None or not asset.path:
            self.problems.warn(where, "inputs:file is not set: the texture's fallback is used")
            return None, seen
        if "<UDIM>" in asset.path.upper():
            self.problems.warn(where, f"inputs:file {asset.path} is a UDIM set; snell reads single images: the "
                                      "texture's fallback is used")
            return None, seen
        if not asset.resolvedPath:
            # As usdview: the texture's fallback, scaled and biased; strict readers (--strict) refuse the stage.
            self.problems.strict_error(where, f"texture file {asset.path} not found (it resolves to nothing from "
                                              f"{_layer_of(texture, 'file')}): the texture's fallback "
                                              f"{_fmt(seen)} is used")
            return None, seen
        wraps = tuple(str(self._value(texture, name, TEXTURE_FALLBACKS)) for name in ("wrapS", "wrapT"))
        color_space = str(self._value(texture, "sourceColorSpace", TEXTURE_FALLBACKS))
        if color_space not in ("auto", "raw", "sRGB"):
            self.problems.warn(where, f"sourceColorSpace '{color_space}' is not auto, raw or sRGB: read as auto")
            color_space = "auto"
        if kind == "normal":
            if color_space == "sRGB":
                self.problems.warn(where, "sourceColorSpace is sRGB on a normal map: decoded from sRGB as the stage "
                                          "says (normal maps are data, usually raw)")
            else:
                color_space = "raw"  # 'auto' guesses colour from 8-bit RGB files; a normal map is data
        output = "rgb" if source.output == "rgba" else source.output
        factor = (1.0, 1.0, 1.0)
        if kind == "emission":
            # Emission is factor x texture: with no bias the scale is folded into the factor (any size, and the
            # file's bytes unchanged); otherwise the texture holds scale x texel + bias over a gain (see _textures).
            used = range(3) if output == "rgb" else ["rgba".index(output)] * 3
            if all(bias[c] == 0.0 and scale[c] >= 0.0 for c in used):
                factor = tuple(scale[c] for c in used)
                scale, bias = IDENTITY_SCALE, NO_BIAS
        request = TextureRequest(asset.resolvedPath, color_space, scale, bias, output, kind)
        st_primvar, transform = self._st_of(texture)
        slot = TextureSlot(request, str(where), asset.path, wraps, st_primvar, transform,
                           fallback=_channel_colour(seen, source.output), factor=factor)
        return slot, seen

    def _st_of(self, texture: UsdShade.Shader) -> tuple[str, Optional[Transform]]:
        """The primvar a texture's st reads, and the UsdTransform2d between them if there is one."""
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

    def _transform2d(self, shader: UsdShade.Shader) -> Transform:
        rotation = float(self._value(shader, "rotation", {"rotation": 0.0}))
        scale = tuple(float(c) for c in self._value(shader, "scale", {"scale": (1.0, 1.0)}))
        translation = tuple(float(c) for c in self._value(shader, "translation", {"translation": (0.0, 0.0)}))
        return transform2d_as_khr(rotation, scale, translation)

    def _one_uv_set(self, record: MaterialRecord) -> None:
        """A snell mesh carries one UV set: every texture of the material reads the first one's primvar."""
        first = record.st_primvar
        for slot in record.slots.values():
            if slot.st_primvar != first:
                self.problems.warn(slot.prim, f"reads primvars:{slot.st_primvar}, but the material's other textures "
                                              f"read primvars:{first}; snell's meshes carry one UV set: "
                                              f"primvars:{first} is used")
                slot.st_primvar = first

    def _summary(self, record: MaterialRecord, colour: tuple, opacity: float, colour_authored: bool = True) -> str:
        fields = record.fields
        base = record.slots.get("base_color")
        alpha_file = f"{base.file} ({base.request.alpha})" if base is not None and base.request.alpha else ""
        if fields.get("transmission", 0.0) > 0:
            tint = (f"the texture {base.file}" if base is not None and base.request.output else
                    f"primvars:{record.colour_primvar[0]}" if record.colour_primvar else _fmt(colour))
            clear = "" if colour_authored else " (diffuseColor unset: clear)"
            kind = f"glass (opacity {opacity:g}, ior {fields['ior']:g}) transmitting {tint}{clear}"
        elif fields.get("alpha_mode") == "mask":
            kind = f"cut out where opacity < {fields['alpha_cutoff']:g}"
        elif fields.get("alpha_mode") == "blend":
            kind = "coverage: opacity blends" if alpha_file else f"coverage: opacity {opacity:g} blends"
        else:
            kind = "opaque"
        colour_text = (f"texture {base.file}" if base is not None and base.request.output else
                       f"colour primvars:{record.colour_primvar[0]} (else {_fmt(colour)})" if record.colour_primvar
                       else f"colour {_fmt(colour)}")
        parts = [f"UsdPreviewSurface, {kind}, {colour_text}, roughness {fields['roughness']:g}"]
        if alpha_file:
            parts.append(f"opacity from {alpha_file}")
        if record.opacity_primvar:
            parts.append(f"opacity from primvars:{record.opacity_primvar[0]} (else {record.opacity_primvar[1]:g})")
        if "emissive" in record.slots:
            parts.append(f"emissive texture {record.slots['emissive'].file}")
        if "normal" in record.slots:
            parts.append(f"normal map {record.slots['normal'].file}")
        return ", ".join(parts)


def transform2d_as_khr(rotation: float, scale: tuple[float, float], translation: tuple[float, float]) -> Transform:
    """A UsdTransform2d as KHR_texture_transform's (offset, rotation, scale) in snell's UV space.

    UsdTransform2d maps st to A st = T(translation) R(rotation, counter-clockwise, degrees) S(scale) st. snell's
    UV is F st, F (s, t) = (s, 1 - t) (st's origin is the image's lower left, snell's v runs down), so snell
    must read M = F A F. Its linear part diag(1, -1) R(a) S diag(1, -1) = R(-a) S is KHR's rotate(a) scale(S)
    (KHR rotates clockwise in st's sense, as v runs down); its offset is M (0, 0) = F A (0, 1). Exact.
    """
    a = math.radians(rotation)
    offset = (translation[0] - scale[1] * math.sin(a), 1.0 - translation[1] - scale[1] * math.cos(a))
    return offset, a, (scale[0], scale[1])


def _khr_matrix(transform: Transform) -> np.ndarray:
    """KHR_texture_transform's matrix: translate(offset) rotate(rotation) scale(scale), as snell builds it."""
    (ox, oy), rotation, (sx, sy) = transform
    c, s = math.cos(rotation), math.sin(rotation)
    return np.array([[c * sx, s * sy, ox], [-s * sx, c * sy, oy], [0.0, 0.0, 1.0]])


def _sampling_differs(base: TextureSlot, other: TextureSlot, channel: str) -> str:
    """Why another texture's channel is not the base colour texture's as snell samples it ('' if it is)."""
    if other.request.path != base.request.path:
        return "another file"
    if (other.st_primvar, other.transform, other.snell_wraps) != (base.st_primvar, base.transform, base.snell_wraps):
        return "the same file through another st, transform or wrap"
    if channel != "a" and other.request.color_space != base.request.color_space:
        return "the same file in another colour space"
    return ""


def _channel_colour(values: np.ndarray, output: str) -> tuple[float, float, float]:
    """What a texture output gives a colour input: rgb, or one channel as grey."""
    if output in ("r", "g", "b", "a"):
        return (float(values["rgba".index(output)]),) * 3
    return tuple(float(c) for c in values[:3])


def _surface_fields(values: dict[str, Any]) -> dict[str, Any]:
    """snell.Material's keyword arguments from UsdPreviewSurface values (fallbacks where missing)."""
    v = {**PREVIEW_FALLBACKS, **values}
    return {"roughness": float(v["roughness"]), "ior": float(v["ior"]),
            "emissive": tuple(float(c) for c in v["emissiveColor"]), "transmission": 0.0,
            "base_color": (*(float(c) for c in v["diffuseColor"]), 1.0)}


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
