"""UsdUVTexture images as snell textures: decoded by snell (OpenImageIO for other formats), converted on the CPU.

snell's textures are 8-bit RGBA, row 0 at the top (snell.Texture): sRGB
colour in the base colour and emissive slots, data (bytes / 255) in the
normal slot; alpha is bytes / 255 everywhere. A UsdUVTexture's result is
`linear(texel) * scale + bias` (UsdPreviewSurface spec: the colour-space
decode comes first), so the conversion decodes the file's colour space,
applies scale and bias, and encodes the result for its slot:

- colour: 8-bit sRGB; an 8-bit sRGB file with scale 1 and bias 0 passes
  through byte for byte, so it reads as glTF's loader reads the same file;
- emission: as colour, divided per channel by a gain (the largest value, when
  above 1) that the material's emissive factor multiplies back, so emission
  brighter than 1 survives 8 bits;
- normal: snell decodes a normal map as 2 byte / 255 - 1, so the tangent-space
  normal v is stored as (v + 1) / 2; the usual raw file with scale 2 and bias
  -1 passes through byte for byte.

Alpha is the coverage snell multiplies into the base colour's alpha: one
channel of the file after its own scale and bias (never colour-decoded when it
is the file's alpha), or opaque.
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
    """One snell texture made from a UsdUVTexture's file: how its texels become the slot's bytes."""

    path: str  #: the resolved file
    color_space: str  #: 'sRGB', 'raw' or 'auto'
    scale: tuple[float, float, float, float] = IDENTITY_SCALE
    bias: tuple[float, float, float, float] = NO_BIAS
    output: str = "rgb"  #: what gives the colour: rgb, one of r, g, b, a (as grey), or '' (white)
    kind: str = "colour"  #: colour (sRGB), emission (sRGB over a gain) or normal (data)
    alpha: str = ""  #: the channel that gives alpha (r, g, b or a), '' for opaque
    alpha_scale: float = 1.0  #: the alpha channel's own scale and bias (its shader's)
    alpha_bias: float = 0.0


@dataclass
class TextureImage:
    """A converted texture: its bytes and the gain its slot's factor multiplies back (emission only)."""

    rgba: np.ndarray  #: (height, width, 4) uint8, row 0 at the top
    gain: tuple[float, float, float] = (1.0, 1.0, 1.0)


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c: np.ndarray) -> np.ndarray:
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def _decoded(path: str, shown: str) -> tuple[np.ndarray, str]:
    """The file's samples (height, width, channels: uint8, uint16 or float32) and what it says of its colour
    space: decoded by snell itself (stb_image, as its glTF loader decodes textures), or for other formats (EXR,
    TIFF) by OpenImageIO's Python module where it is installed."""
    from .. import Error, read_image_file

    try:
        return read_image_file(path), ""
    except Error as e:
        snell_says = str(e).replace(path, shown, 1)
    try:
        import OpenImageIO as oiio
    except ImportError:
        raise TextureReadError(f"{snell_says} (other formats need OpenImageIO's Python module: "
                               "Debian's python3-openimageio, or pip's OpenImageIO)") from None
    # The file's own values: OpenImageIO would otherwise premultiply colour by alpha.
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    image = oiio.ImageInput.open(path, config)
    if image is None:
        raise TextureReadError(f"{shown}: not an image snell or OpenImageIO reads ({oiio.geterror()})")
    try:
        spec = image.spec()
        kind = "uint8" if spec.format == oiio.UINT8 else "float"
        pixels = image.read_image(0, 0, 0, spec.nchannels, kind)
        if pixels is None:
            raise TextureReadError(f"{shown}: {image.geterror()}")
        said = spec.get_string_attribute("oiio:ColorSpace", "")
    finally:
        image.close()
    return np.asarray(pixels).reshape(spec.height, spec.width, spec.nchannels), said


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


def read_texture(request: TextureRequest) -> TextureImage:
    """The texture as snell takes it for the request's slot (see the module's docstring)."""
    with _local_file(request.path) as path:
        return _read_texture(request, path)


def _passes_through(request: TextureRequest, bits8: bool, srgb: bool, channels: int) -> bool:
    """Whether the file's bytes are already what snell's slot reads: 8-bit sRGB colour, unscaled."""
    identity = request.scale == IDENTITY_SCALE and request.bias == NO_BIAS
    plain_alpha = request.alpha == "" or (request.alpha == "a" and request.alpha_scale == 1.0
                                          and request.alpha_bias == 0.0)
    return (bits8 and srgb and identity and plain_alpha and request.kind in ("colour", "emission")
            and request.output == "rgb" and channels >= 3)


def _read_texture(request: TextureRequest, path: str) -> TextureImage:
    pixels, file_says = _decoded(path, request.path)
    height, width, channels = pixels.shape
    bits8 = pixels.dtype == np.uint8
    srgb = is_srgb(request.color_space, bits8, channels, file_says)
    if _passes_through(request, bits8, srgb, channels):
        rgba = np.full((height, width, 4), 255, np.uint8)
        rgba[..., :3] = pixels[..., :3]
        if request.alpha == "a" and channels >= 4:
            rgba[..., 3] = pixels[..., 3]
        return TextureImage(rgba)
    scale = {np.dtype(np.uint8): 255.0, np.dtype(np.uint16): 65535.0}.get(pixels.dtype, 1.0)
    pixels = pixels.astype(np.float64) / scale
    texels = _usd_channels(pixels)
    if srgb:
        texels[..., :3] = srgb_to_linear(texels[..., :3])
    values = texels * np.asarray(request.scale) + np.asarray(request.bias)
    if request.output == "rgb":
        colour = values[..., :3]
    elif request.output in ("r", "g", "b", "a"):
        colour = np.repeat(values[..., "rgba".index(request.output), None], 3, axis=2)
    else:  # alpha alone: white, so the base colour factor is the colour
        colour = np.ones(values.shape[:2] + (3,))
    out = np.empty(values.shape[:2] + (4,), np.uint8)
    gain = (1.0, 1.0, 1.0)
    if request.kind == "normal":
        out[..., :3] = np.rint(np.clip((colour + 1.0) * 0.5, 0.0, 1.0) * 255.0)
    else:
        if request.kind == "emission":
            # Emission above 1 would clip in 8 bits: each channel is stored over its largest value.
            colour = np.maximum(colour, 0.0)
            gain = tuple(max(1.0, float(colour[..., c].max(initial=0.0))) for c in range(3))
            colour = colour / np.asarray(gain)
        out[..., :3] = np.rint(linear_to_srgb(colour) * 255.0)
    if request.alpha:
        alpha = texels[..., "rgba".index(request.alpha)] * request.alpha_scale + request.alpha_bias
        out[..., 3] = np.rint(np.clip(alpha, 0.0, 1.0) * 255.0)
    else:
        out[..., 3] = 255
    return TextureImage(out, gain)


def _usd_channels(pixels: np.ndarray) -> np.ndarray:
    """The four channels UsdUVTexture sees: grey files fill r, g and b; a missing alpha is 1."""
    channels = pixels.shape[2]
    if channels == 1:
        return np.concatenate([np.repeat(pixels, 3, axis=2), np.ones_like(pixels)], axis=2)
    if channels == 2:
        return np.concatenate([np.repeat(pixels[..., :1], 3, axis=2), pixels[..., 1:2]], axis=2)
    if channels == 3:
        return np.concatenate([pixels, np.ones_like(pixels[..., :1])], axis=2)
    return pixels[..., :4].copy()
