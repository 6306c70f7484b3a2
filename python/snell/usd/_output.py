"""Pictures to files as `snell render` writes them: EXR linear (half or float), PNG 8-bit sRGB; atomically.

PNG is snell's own (snell.write_png); EXR goes through OpenImageIO's Python module, since snell's own EXR
writer (src/io/image_file.cpp) is OpenImageIO's C++ library, which the pip package does not carry.

A file appears only once it is complete: the image is written to a hidden
temporary file in the same folder and renamed over the name asked for, so a
farm's retry or `--skip-existing` never takes a half-written frame for a
finished one.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping, Union

import numpy as np

EXTENSIONS = (".exr", ".png")


class OutputError(Exception):
    """An image that cannot be written; the message names the file."""


def _oiio(path: Path):
    try:
        import OpenImageIO
    except ImportError:
        raise OutputError(f"{path}: writing EXR needs OpenImageIO's Python module, which is not installed "
                          "(Debian: python3-openimageio; pip: OpenImageIO); snell writes .png without it") from None
    return OpenImageIO


def check_format(path: Union[str, os.PathLike]) -> None:
    """Fails early, naming the file, where its format needs what is not installed: EXR needs OpenImageIO's
    Python module (snell's own EXR writer is its command line's, through OpenImageIO's C++ library, which a
    pip install does not carry); PNG needs nothing."""
    path = Path(path)
    if path.suffix.lower() == ".exr":
        _oiio(path)


def check_writable(path: Union[str, os.PathLike]) -> None:
    """Fails early, naming the file, where the frames could not be written."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise OutputError(f"{path}: is a folder, not a file")
    if not folder.is_dir():
        raise OutputError(f"{path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: cannot write in the folder {folder}")


def write_image(path: Union[str, os.PathLike], rgba: np.ndarray, float_pixels: bool = False,
                metadata: Mapping[str, object] = ()) -> None:
    """Writes a (height, width, 4) float32 scene-linear picture; the extension picks EXR or PNG (8-bit sRGB,
    written by snell itself, as `snell render` writes it; the metadata is EXR's alone)."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in EXTENSIONS:
        raise OutputError(f"{path}: unsupported image type '{path.suffix}' (use .exr or .png)")
    if ext == ".png":
        from .. import Error, write_png

        try:
            write_png(str(path), np.ascontiguousarray(rgba, np.float32))
        except Error as e:
            raise OutputError(str(e)) from None
        return
    oiio = _oiio(path)
    height, width = rgba.shape[:2]
    kind = "float" if float_pixels else "half"
    pixels, spec = np.ascontiguousarray(rgba, np.float32), oiio.ImageSpec(width, height, 4, kind)
    spec.attribute("compression", "zip")
    spec.attribute("oiio:ColorSpace", "Linear")
    spec.channelnames = ("R", "G", "B", "A")
    spec.alpha_channel = 3
    for name, value in dict(metadata).items():
        if isinstance(value, np.ndarray):
            spec.attribute(name, "matrix", tuple(float(v) for v in value.reshape(-1)))
        else:
            spec.attribute(name, value)
    temp = path.with_name(f".{path.stem}.partial-{os.getpid()}{path.suffix}")
    try:
        out = oiio.ImageOutput.create(str(temp))
        if out is None:
            raise OutputError(f"{path}: cannot write {ext[1:].upper()} ({oiio.geterror()})")
        if not out.open(str(temp), spec) or not out.write_image(pixels) or not out.close():
            raise OutputError(f"{path}: {out.geterror() or 'the image could not be written'}")
        os.replace(temp, path)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
