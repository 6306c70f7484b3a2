"""A UsdLux DomeLight as snell's environment: what the glass reflects (snell.Environment).

The dome's radiance is L = color · intensity · 2^exposure (· its colour
temperature's RGB when enabled), times its lat-long texture where it has one
(UsdLux ignores `normalize` for a dome). snell's environment is a lat-long
map in snell's world (+Y up, the middle column looking down -Z); the dome's
follows OpenEXR's (the middle column looks down +Z) in the dome's own frame,
which its transform, its `poleAxis` (DomeLight_1) and the stage's up axis
turn. So each texel of snell's map looks up the dome's texture along the
same world direction (bilinear, wrapping around the poles' axis): for an
unturned dome on a Y-up stage that is the texture turned half a revolution,
texel for texel.

A texture snell cannot read (a format neither snell's decoder nor an
installed OpenImageIO reads, such as EXR in a plain venv, a file that is not
there, a mirroredBall or angular map) is a warning naming the file, and the
dome's colour is drawn instead, as a uniform environment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
import numpy as np
from pxr import Usd, UsdGeom, UsdLux

from ._lights import attribute_value, emission, warn_if_animated
from ._problems import Problems
from ._textures import TextureReadError, _decoded, _local_file, _usd_channels, is_srgb, srgb_to_linear

#: DomeLight_1's poleAxis Z: the dome turned +90 degrees about X, so its top pole (+Y) points up +Z and its
#: longitude 0 (+Z) down -Y, as the schema says.
_POLE_Z = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
MAX_WIDTH = 4096  #: snell's widest environment (scene::kMaxEnvironmentWidth)


@dataclass
class Dome:
    """A DomeLight as snell draws it: its radiance map in snell's orientation and what it came from."""

    path: str
    radiance: np.ndarray  #: (height, width, 3) float32, snell's lat-long (a 1x1 map for a dome without texture)
    summary: str

    def environment(self):
        """The snell.Environment of this dome."""
        from .. import Environment

        return Environment(self.radiance, name=f"{self.path} (DomeLight)")



def _rotation(matrix: np.ndarray) -> np.ndarray:
    """The rotation of a 3x3 linear map (its polar factor): the dome's turn, without its scale or shear."""
    u, _, vt = np.linalg.svd(matrix)
    rotation = u @ vt
    if np.linalg.det(rotation) < 0.0:  # a mirrored dome: keep the turn, the mirror has no lat-long meaning
        rotation = u @ np.diag([1.0, 1.0, -1.0]) @ vt
    return rotation


def _snell_directions(width: int, height: int) -> np.ndarray:
    """The world direction of each texel centre of snell's lat-long map (the inverse of the trace's lookup:
    u = 0.5 + atan(x, -z) / 2pi, v = acos(y) / pi), (height, width, 3)."""
    phi = (np.arange(width) + 0.5) / width * 2.0 * math.pi - math.pi
    theta = (np.arange(height) + 0.5) / height * math.pi
    s, c = np.sin(theta)[:, None], np.cos(theta)[:, None]
    return np.stack([s * np.sin(phi)[None, :], np.broadcast_to(c, (height, width)),
                     -s * np.cos(phi)[None, :]], axis=-1)


def _sample_latlong(image: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """The OpenEXR lat-long image (row 0: latitude +pi/2; column 0: longitude +pi; longitude 0 looks down +Z,
    pi/2 down +X) seen along each direction, bilinear, wrapping in longitude and clamped at the poles."""
    height, width = image.shape[:2]
    d = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    u = (math.pi - np.arctan2(d[..., 0], d[..., 2])) / (2.0 * math.pi)
    v = np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / math.pi
    x, y = u * width - 0.5, v * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    xs = (x0 % width, (x0 + 1) % width)
    ys = (np.clip(y0, 0, height - 1), np.clip(y0 + 1, 0, height - 1))
    top = image[ys[0], xs[0]] * (1.0 - fx) + image[ys[0], xs[1]] * fx
    bottom = image[ys[1], xs[0]] * (1.0 - fx) + image[ys[1], xs[1]] * fx
    return top * (1.0 - fy) + bottom * fy


def _halved(image: np.ndarray) -> np.ndarray:
    """The image box-filtered to half its size (an odd last row or column is repeated)."""
    if image.shape[0] % 2:
        image = np.concatenate([image, image[-1:]], axis=0)
    if image.shape[1] % 2:
        image = np.concatenate([image, image[:, -1:]], axis=1)
    return 0.25 * (image[0::2, 0::2] + image[1::2, 0::2] + image[0::2, 1::2] + image[1::2, 1::2])


def _read_texture(path: str) -> np.ndarray:
    """A dome texture's linear RGB, (height, width, 3) float32: 8-bit colour files decoded from sRGB."""
    with _local_file(path) as local:
        pixels, file_says = _decoded(local, path)
    height, width, channels = pixels.shape
    bits8 = pixels.dtype == np.uint8
    scale = {np.dtype(np.uint8): 255.0, np.dtype(np.uint16): 65535.0}.get(pixels.dtype, 1.0)
    rgb = _usd_channels(pixels.astype(np.float64) / scale)[..., :3]
    if is_srgb("auto", bits8, channels, file_says):
        rgb = srgb_to_linear(rgb)
    return rgb.astype(np.float32)


def read_dome(prim: Usd.Prim, time: Usd.TimeCode, to_snell: np.ndarray, up_axis: str,
              xform_cache: UsdGeom.XformCache, problems: Problems, load_texture: bool = True) -> Dome:
    """The environment of a DomeLight or DomeLight_1 prim at a time code (see the module's docstring)."""
    path = str(prim.GetPath())
    api = UsdLux.LightAPI(prim)
    luminance, colour = emission(api, time)
    radiance = np.maximum(colour * luminance, 0.0)
    warn_if_animated(prim, ("intensity", "exposure", "color", "texture:file"), "the environment", "turns", time,
                     problems)
    if prim.GetRelationship("portals") and prim.GetRelationship("portals").GetTargets():
        problems.warn(path, "its portals only guide sampling, which snell's environment does not need: ignored")
    shown = "(" + ", ".join(f"{c:.4g}" for c in radiance) + ")"
    uniform = Dome(path, radiance.astype(np.float32).reshape(1, 1, 3), f"snell's environment, uniform {shown}")

    dome = UsdLux.DomeLight_1(prim) if prim.IsA(UsdLux.DomeLight_1) else UsdLux.DomeLight(prim)
    asset = attribute_value(dome.GetTextureFileAttr(), time, None)
    if asset is None or not asset.path:
        return uniform
    fallback = f"the dome's colour {shown} is drawn instead"
    layout = str(attribute_value(dome.GetTextureFormatAttr(), time, "automatic"))
    if layout not in ("automatic", "latlong"):
        problems.warn(path, f"texture {asset.path} is a {layout} map; snell reads lat-long maps: {fallback}")
        return uniform
    if not asset.resolvedPath:
        problems.strict_error(path, f"texture file {asset.path} not found: {fallback}")
        return uniform
    if not load_texture:
        return Dome(path, uniform.radiance, f"snell's environment, texture {asset.path} x {shown}")
    try:
        texture = _read_texture(asset.resolvedPath)
    except TextureReadError as e:
        problems.strict_error(path, f"texture {e}: {fallback}")
        return uniform

    # World directions to the dome's own (OpenEXR's) frame: snell's world back to the stage's, then the
    # dome's transform and pole axis undone. Only the turn counts: a dome is infinitely far.
    pole = str(prim.GetAttribute("poleAxis").Get() or "scene") if prim.IsA(UsdLux.DomeLight_1) else "Y"
    turn = _POLE_Z if pole == "Z" or (pole == "scene" and up_axis == "Z") else np.eye(3)
    world = np.array(xform_cache.GetLocalToWorldTransform(prim)).T[:3, :3]
    dome_to_snell = _rotation(to_snell[:3, :3] @ world) @ turn
    while texture.shape[1] > MAX_WIDTH:  # snell keeps at most this many columns: box-filter first, as it would
        texture = _halved(texture)
    height, width = texture.shape[:2]
    directions = _snell_directions(width, height).astype(np.float32) @ dome_to_snell.astype(np.float32)  # R^T d
    texels = _sample_latlong(texture, directions) * radiance
    bad = ~np.isfinite(texels) | (texels < 0.0)
    if bad.any():
        problems.warn(path, f"texture {asset.path} has {int(bad.any(axis=-1).sum())} negative or non-finite texels: "
                            "drawn black")
        texels[bad] = 0.0
    return Dome(path, texels.astype(np.float32),
                f"snell's environment, texture {asset.path} ({width}x{height}) x {shown}")
