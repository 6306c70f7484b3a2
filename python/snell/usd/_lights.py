"""UsdLux lights as snell's punctual lights (glTF KHR_lights_punctual: candela, lux).

UsdLux gives a light's luminance L = intensity · 2^exposure (nits), divided
by its size when `normalize` is on (the schema's sizeFactor: the world-space
area of an area light, π sin²θ for a distant light of angular radius θ).
snell's lights are points, spots and directional lights, so (docs/usd.md):

- an area light (sphere, rect, disk, cylinder) of area A emits the flux
  π L A of a Lambertian surface; a point light of the same flux has
  I = L A / 4 candela. For a sphere (A = 4π r²) that is its true intensity,
  L π r², in every direction; a rect, disk or cylinder becomes a point light
  of its power, and a message says so. A sphere light with ShapingAPI and a
  cone of 90 degrees or less is a spot (outer = the cone, inner = the cone ·
  (1 - softness), UsdLux's smoothstep start);
- a distant light of angular diameter α gives E = L π sin²(α/2) lux
  (UsdLux's sizeFactor; L itself when normalized, or when α is 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np
from pxr import Usd, UsdGeom, UsdLux

from .. import Light
from ._problems import Problems


@dataclass
class LightRecord:
    """A UsdLux light and what snell makes of it (None: nothing it can draw)."""

    path: str
    kind: str  #: the prim's type name
    light: Optional[Light]
    summary: str


def attribute_value(attribute: Usd.Attribute, time: Usd.TimeCode, fallback):
    """The attribute's value at a time code; `fallback` where it is missing or holds none."""
    value = attribute.Get(time) if attribute else None
    return fallback if value is None else value



def emission(api: UsdLux.LightAPI, time: Usd.TimeCode) -> tuple[float, np.ndarray]:
    """A UsdLux light's luminance (intensity x 2^exposure) and its linear RGB (colour x colour temperature)."""
    intensity = float(attribute_value(api.GetIntensityAttr(), time, 1.0))
    luminance = intensity * 2.0 ** float(attribute_value(api.GetExposureAttr(), time, 0.0))
    colour = np.array(attribute_value(api.GetColorAttr(), time, (1.0, 1.0, 1.0)), float)
    if attribute_value(api.GetEnableColorTemperatureAttr(), time, False):
        kelvin = float(attribute_value(api.GetColorTemperatureAttr(), time, 6500.0))
        colour *= np.array(UsdLux.BlackbodyTemperatureAsRgb(kelvin))
    return luminance, colour


def warn_if_animated(prim: Usd.Prim, inputs: tuple[str, ...], what: str, turns: str, time: Usd.TimeCode,
                     problems: Problems) -> None:
    """A warning for each of the light's `inputs` that is animated, and one where it `turns` over time:
    snell sets `what` (its lights, the environment) once, when the scene is built."""
    path = str(prim.GetPath())
    when = f"snell sets {what} when the scene is built (time code {time.GetValue():g})"
    for name in inputs:
        attribute = prim.GetAttribute(f"inputs:{name}")
        if attribute and attribute.ValueMightBeTimeVarying():
            problems.warn(path, f"inputs:{name} is animated; {when}")
    if UsdGeom.Xformable(prim).TransformMightBeTimeVarying():
        problems.warn(path, f"it {turns} over time; {when}")


def _distant_size(angle_degrees: float) -> float:
    """UsdLux's sizeFactor for a distant light: the solid angle's cosine-weighted size, π sin²θ (θ its radius)."""
    theta = min(max(math.radians(angle_degrees) / 2.0, 0.0), math.pi)
    if theta == 0.0:
        return 1.0
    s2 = math.sin(theta) ** 2
    return s2 * math.pi if theta <= math.pi / 2 else (2.0 - s2) * math.pi


def read_light(prim: Usd.Prim, time: Usd.TimeCode, to_snell: np.ndarray, xform_cache: UsdGeom.XformCache,
               problems: Problems) -> LightRecord:
    """The snell light of a UsdLux light prim at a time code."""
    path = str(prim.GetPath())
    kind = prim.GetTypeName() or "LightAPI"
    api = UsdLux.LightAPI(prim)
    world = to_snell @ np.array(xform_cache.GetLocalToWorldTransform(prim)).T
    axes = np.linalg.norm(world[:3, :3], axis=0)  # the light's scale along its x, y, z, in metres per unit
    position = world[:3, 3]
    direction = world[:3, :3] @ np.array([0.0, 0.0, -1.0])  # UsdLux lights shine down their -Z
    direction /= max(np.linalg.norm(direction), 1e-30)
    luminance, colour = emission(api, time)
    normalize = bool(attribute_value(api.GetNormalizeAttr(), time, False))
    warn_if_animated(prim, ("intensity", "exposure", "color"), "lights", "moves", time, problems)
    for name, fallback in (("diffuse", 1.0), ("specular", 1.0)):
        value = attribute_value(prim.GetAttribute(f"inputs:{name}"), time, fallback)
        if value != fallback:
            problems.warn(path, f"inputs:{name} is {value:g}; snell's lights light diffuse and specular alike")
    link = prim.GetAttribute("collection:lightLink:includeRoot")
    if link and link.Get() is False:
        problems.warn(path, "it is light-linked to some prims only; snell lights everything with it")
    colour_list = tuple(float(c) for c in colour)

    if prim.IsA(UsdLux.DistantLight):
        angle = float(attribute_value(UsdLux.DistantLight(prim).GetAngleAttr(), time, 0.53))
        lux = luminance if normalize else luminance * _distant_size(angle)
        light = Light(type="directional", color=colour_list, intensity=lux, direction=tuple(direction))
        return LightRecord(path, kind, light, f"directional, {lux:.4g} lux")

    area, shape = None, ""
    if prim.IsA(UsdLux.SphereLight):
        r = float(attribute_value(UsdLux.SphereLight(prim).GetRadiusAttr(), time, 0.5))
        area = 4.0 * math.pi * r * r * float(np.prod(axes)) ** (2.0 / 3.0)
    elif prim.IsA(UsdLux.RectLight):
        light = UsdLux.RectLight(prim)
        if attribute_value(light.GetTextureFileAttr(), time, None):
            problems.warn(path, "its texture is not drawn: snell's lights have one colour")
        width = float(attribute_value(light.GetWidthAttr(), time, 1.0))
        area = width * float(attribute_value(light.GetHeightAttr(), time, 1.0))
        area *= axes[0] * axes[1]
        shape = "rect"
    elif prim.IsA(UsdLux.DiskLight):
        r = float(attribute_value(UsdLux.DiskLight(prim).GetRadiusAttr(), time, 0.5))
        area, shape = math.pi * r * r * axes[0] * axes[1], "disk"
    elif prim.IsA(UsdLux.CylinderLight):
        light = UsdLux.CylinderLight(prim)
        r = float(attribute_value(light.GetRadiusAttr(), time, 0.5))
        length = float(attribute_value(light.GetLengthAttr(), time, 1.0)) * axes[0]  # along its x axis
        area = 2.0 * math.pi * r * math.sqrt(axes[1] * axes[2]) * length
        shape = "cylinder"
    else:
        return unsupported_light(prim, problems)

    if area > 0.0:
        candela = (luminance if normalize else luminance * area) / 4.0
    else:
        candela = luminance
        problems.warn(path, f"a {kind} of zero size: its intensity is taken as {candela:g} candela")
    if shape:
        problems.warn(path, f"a {kind} shines as a point light of the same power ({candela:.4g} cd): snell has no "
                            "area lights")
    elif area > 0.0:
        problems.warn(path, f"a SphereLight of radius {r:g} shines as a point light at its centre ({candela:.4g} cd, "
                            "its intensity in every direction): its highlights are points, not discs")
    shaping = UsdLux.ShapingAPI(prim)
    if prim.HasAPI(UsdLux.ShapingAPI):
        if attribute_value(shaping.GetShapingIesFileAttr(), time, None):
            problems.warn(path, "its IES profile is not drawn")
        if float(attribute_value(shaping.GetShapingFocusAttr(), time, 0.0)) != 0.0:
            problems.warn(path, "shaping:focus is not drawn")
        cone = float(attribute_value(shaping.GetShapingConeAngleAttr(), time, 90.0))
        softness = min(max(float(attribute_value(shaping.GetShapingConeSoftnessAttr(), time, 0.0)), 0.0), 1.0)
        if cone <= 90.0:
            outer = math.radians(max(cone, 0.0))
            light = Light(type="spot", color=colour_list, intensity=candela, position=tuple(position),
                          direction=tuple(direction), inner_cone_angle=outer * (1.0 - softness),
                          outer_cone_angle=outer)
            return LightRecord(path, kind, light, f"spot, {candela:.4g} cd, cone {cone:g} degrees")
        if cone < 180.0:
            problems.warn(path, f"a cone of {cone:g} degrees is wider than a spot's (90 at most): it shines as a "
                                "point light")
    light = Light(type="point", color=colour_list, intensity=candela, position=tuple(position))
    return LightRecord(path, kind, light, f"point, {candela:.4g} cd")


def unsupported_light(prim: Usd.Prim, problems: Problems) -> LightRecord:
    """A light snell has no counterpart for (a geometry light, a portal; a dome is _dome.py's)."""
    kind = prim.GetTypeName() or "LightAPI"
    what = {"PortalLight": "a portal only guides a dome light"}.get(
        kind, "snell draws points, spots and directional lights")
    problems.warn(prim.GetPath(), f"a {kind}: {what}: skipped")
    return LightRecord(str(prim.GetPath()), kind, None, "skipped")
