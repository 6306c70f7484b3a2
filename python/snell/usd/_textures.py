"""UsdUVTexture images as snell textures: read with OpenImageIO, converted on the CPU.

snell's textures are 8-bit sRGB RGBA, row 0 at the top (snell.Texture). A
UsdUVTexture's result is `linear(texel) * scale + bias` (UsdPreviewSurface
spec: the colour-space decode comes first), so the conversion decodes the
file's colour space, applies scale and bias in linear light, and encodes the
result back to 8-bit sRGB. An 8-bit sRGB file with scale 1 and bias 0 passes
through byte for byte, so it reads as glTF's loader reads the same file.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from dataclasses import dataclass
from typing import Iterator

import numpy as np

IDENTITY_SCALE = (1.0, 1.0, 1.0, 1.0)
NO_BIAS = (0.0, 0.0, 0.0, 0.0)


class TextureReadError(Exception):
    """A texture file that exists but cannot be read as an image."""


@dataclass(frozen=True)
class TextureRequest:
    """One UsdUVTexture output as a snell texture: the file, how its texels become colour, and which output."""

    path: str  #: the resolved file
    color_space: str  #: 'sRGB', 'raw' or 'auto'
    scale: tuple[float, float, float, float] = IDENTITY_SCALE
    bias: tuple[float, float, float, float] = NO_BIAS
    output: str = "rgb"  #: the UsdUVTexture output connected: rgb, rgba, r, g, b or a


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c: np.ndarray) -> np.ndarray:
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def _oiio():
    try:
        import OpenImageIO
    except ImportError as e:  # the module is optional for stages without textures
        raise TextureReadError("reading textures needs OpenImageIO's Python module "
                               "(Debian: python3-openimageio; pip: OpenImageIO)") from e
    return OpenImageIO


def is_srgb(color_space: str, bits8: bool, channels: int, file_says: str) -> bool:
    """UsdUVTexture's sourceColorSpace: 'auto' trusts the file's metadata, else 8-bit RGB(A) files are sRGB."""
    if color_space == "sRGB":
        return True
    if color_space == "raw":
        return False
    said = file_says.lower()
    if "srgb" in said:
        return True
    if said in ("linear", "scene_linear", "lin_srgb", "lin_rec709", "raw"):
        return False
    return bits8 and channels in (3, 4)


@contextlib.contextmanager
def _local_file(resolved: str) -> Iterator[str]:
    """A file OpenImageIO can open for a resolved asset path: itself, or (a texture inside a .usdz
    package, 'shot.usdz[tex/iris.png]', or another resolver's asset) its bytes in a temporary file."""
    if os.path.isfile(resolved):
        yield resolved
        return
    from pxr import Ar

    asset = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved))
    if asset is None:
        raise TextureReadError(f"{resolved}: the asset cannot be opened")
    inner = resolved[:-1].rsplit("[", 1)[-1] if resolved.endswith("]") else resolved
    handle, temporary = tempfile.mkstemp(suffix=os.path.splitext(inner)[1])
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(bytes(asset.GetBuffer()))
        yield temporary
    finally:
        os.unlink(temporary)


def read_texture(request: TextureRequest) -> np.ndarray:
    """The texture as snell takes it: (height, width, 4) uint8 sRGB, alpha 255 unless the output is rgba."""
    with _local_file(request.path) as path:
        return _read_texture(request, path)


def _read_texture(request: TextureRequest, path: str) -> np.ndarray:
    oiio = _oiio()
    # The file's own values: OpenImageIO would otherwise premultiply a PNG's colour by its alpha.
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    image = oiio.ImageInput.open(path, config)
    if image is None:
        raise TextureReadError(f"{request.path}: not an image OpenImageIO reads ({oiio.geterror()})")
    try:
        spec = image.spec()
        channels = spec.nchannels
        bits8 = spec.format == oiio.UINT8
        srgb = is_srgb(request.color_space, bits8, channels, spec.get_string_attribute("oiio:ColorSpace", ""))
        identity = request.scale == IDENTITY_SCALE and request.bias == NO_BIAS
        if bits8 and srgb and identity and request.output in ("rgb", "rgba") and channels >= 3:
            pixels = image.read_image(0, 0, 0, channels, "uint8")
            if pixels is None:
                raise TextureReadError(f"{request.path}: {image.geterror()}")
            rgba = np.full((spec.height, spec.width, 4), 255, np.uint8)
            rgba[..., :3] = pixels[..., :3]
            if request.output == "rgba" and channels >= 4:
                rgba[..., 3] = pixels[..., 3]
            return rgba
        pixels = image.read_image(0, 0, 0, channels, "float")
        if pixels is None:
            raise TextureReadError(f"{request.path}: {image.geterror()}")
    finally:
        image.close()
    pixels = np.asarray(pixels, np.float64).reshape(spec.height, spec.width, channels)
    # The four channels UsdUVTexture sees: grey files fill r, g and b; a missing alpha is 1.
    if channels == 1:
        rgba = np.concatenate([np.repeat(pixels, 3, axis=2), np.ones_like(pixels)], axis=2)
    elif channels == 2:
        rgba = np.concatenate([np.repeat(pixels[..., :1], 3, axis=2), pixels[..., 1:2]], axis=2)
    elif channels == 3:
        rgba = np.concatenate([pixels, np.ones_like(pixels[..., :1])], axis=2)
    else:
        rgba = pixels[..., :4].copy()
    if srgb:
        rgba[..., :3] = srgb_to_linear(rgba[..., :3])
    rgba = rgba * np.asarray(request.scale) + np.asarray(request.bias)
    if request.output in ("r", "g", "b", "a"):
        grey = rgba[..., "rgba".index(request.output)]
        rgba = np.stack([grey, grey, grey, np.ones_like(grey)], axis=2)
    out = np.empty(rgba.shape, np.uint8)
    out[..., :3] = np.rint(linear_to_srgb(rgba[..., :3]) * 255.0)
    out[..., 3] = np.rint(np.clip(rgba[..., 3], 0.0, 1.0) * 255.0) if request.output == "rgba" else 255
    return out
