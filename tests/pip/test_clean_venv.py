"""`pip install .[usd]` into a plain venv, one that sees none of Debian's packages, gives a working snell-usd.

scripts/bootstrap test makes that venv (build/venv/pip-clean: /usr/bin/python3 -m venv, no
--system-site-packages, numpy and usd-core from PyPI) and ctest names its python in
SNELL_PIP_CLEAN_PYTHON. These tests run in the other pip venv, whose pxr writes the stages and whose
OpenImageIO reads the pictures back; the plain venv only runs its own snell-usd, as a user would.
"""

from __future__ import annotations

import os
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade
from usd_card import define_card

CLEAN = Path(os.environ.get("SNELL_PIP_CLEAN_PYTHON", ""))
CLEAN_BIN = CLEAN.parent
TEXELS = np.uint8([[[230, 20, 20], [20, 230, 20]],      # the top row: red, green
                   [[20, 20, 230], [230, 230, 230]]])   # the bottom row: blue, white


def run_clean(*args: object) -> subprocess.CompletedProcess:
    """Runs a program of the plain venv (its snell-usd, its python) with nothing of this one's environment."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=300, env=env)


def write_png(path: Path, rgb: np.ndarray) -> None:
    """An 8-bit RGB PNG, written with zlib alone (no image library of either venv)."""
    height, width, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) +
                     chunk(b"IEND", b""))


def textured_card(folder: Path, texture: str = "checker.png") -> Path:
    """A 2 m card facing +Z whose UsdPreviewSurface reads a texture (a 2x2 checker PNG, written here) through
    st, no camera."""
    write_png(folder / "checker.png", TEXELS)
    path = folder / "card.usda"
    stage = Usd.Stage.CreateNew(str(path))
    card = define_card(stage)
    st = UsdGeom.PrimvarsAPI(card).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
    st.Set([(0, 0), (1, 0), (1, 1), (0, 1)])
    material = UsdShade.Material.Define(stage, "/World/checker")
    surface = UsdShade.Shader.Define(stage, "/World/checker/surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    reader = UsdShade.Shader.Define(stage, "/World/checker/st")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("st")
    image = UsdShade.Shader.Define(stage, "/World/checker/image")
    image.CreateIdAttr("UsdUVTexture")
    image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(f"./{texture}")
    image.CreateInput("fallback", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(0.9, 0.1, 0.9, 1.0))
    image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    rgb = image.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(rgb)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(card.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()
    return path


def test_the_plain_venv_sees_none_of_debians_packages():
    config = (CLEAN.parent.parent / "pyvenv.cfg").read_text()
    assert "include-system-site-packages = false" in config, config
    done = run_clean(CLEAN, "-c", "import numpy, pxr, snell; print(numpy.__file__); print(pxr.__file__); "
                                  "print(snell.__file__)")
    assert done.returncode == 0, done.stderr
    prefix = str(CLEAN.parent.parent.resolve())
    for module in done.stdout.split():
        assert str(Path(module).resolve()).startswith(prefix), f"{module} is not the plain venv's own"
    missing = run_clean(CLEAN, "-c", "import OpenImageIO")
    assert missing.returncode != 0 and "No module named 'OpenImageIO'" in missing.stderr, missing.stderr


def test_the_plain_venvs_snell_decodes_an_image_as_stored_under_its_numpy(tmp_path):
    """The plain venv's numpy is PyPI's newest (2.x); the module must hand it every sample, not the first's."""
    write_png(tmp_path / "checker.png", TEXELS)
    done = run_clean(CLEAN, "-c", "import numpy, snell; print(numpy.__version__); "
                                  f"print(snell.read_image_file({str(tmp_path / 'checker.png')!r}).tolist())")
    assert done.returncode == 0, done.stderr
    numpy_version, samples = done.stdout.splitlines()
    assert samples == str(TEXELS.tolist()), f"numpy {numpy_version}: {samples}"


def test_snell_usd_of_the_plain_venv_renders_a_textured_stage_to_png(tmp_path):
    out = tmp_path / "card.png"
    done = run_clean(CLEAN_BIN / "snell-usd", "render", textured_card(tmp_path), "-o", out, "--size", "64x64")
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr, done.stderr  # the texture was read: no fallback drawn
    buf = oiio.ImageBuf(str(out))
    pixels = buf.get_pixels(oiio.FLOAT)
    assert pixels.shape == (64, 64, 4) and np.all(pixels[..., 3] == 1.0), pixels.shape  # opaque RGBA, as snell's
    # The framed view shows the card's quadrants around the middle: each its texel's hue, lit.
    quadrants = {"red": pixels[21, 21], "green": pixels[21, 43], "blue": pixels[43, 21], "white": pixels[43, 43]}
    for name, (channel, rgb) in zip(("red", "green", "blue"), enumerate(quadrants.values())):
        others = [rgb[c] for c in range(3) if c != channel]
        assert rgb[channel] > 2 * max(others), f"the {name} quadrant is {rgb}"
    white = quadrants["white"]
    assert white.min() > 0.5 * white.max() and white.max() > 0.3, f"the white quadrant is {white}"


def test_exr_in_the_plain_venv_is_refused_naming_openimageio_and_writes_nothing(tmp_path):
    out = tmp_path / "card.exr"
    done = run_clean(CLEAN_BIN / "snell-usd", "render", textured_card(tmp_path), "-o", out, "--size", "16x16")
    assert done.returncode == 1, done.stderr
    assert "EXR needs OpenImageIO's Python module" in done.stderr and str(out) in done.stderr, done.stderr
    assert "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["card.usda", "checker.png"], "nothing was written"


def test_an_exr_dome_in_the_plain_venv_is_a_warning_naming_it_and_the_dome_colour_is_drawn(tmp_path):
    sky = tmp_path / "sky.exr"
    out = oiio.ImageOutput.create(str(sky))
    assert out is not None and out.open(str(sky), oiio.ImageSpec(8, 4, 3, "half"))
    assert out.write_image(np.full((4, 8, 3), 2.0, np.float32)) and out.close()
    path = textured_card(tmp_path)
    stage = Usd.Stage.Open(str(path))
    dome = UsdLux.DomeLight.Define(stage, "/World/Dome")
    dome.CreateTextureFileAttr(Sdf.AssetPath("./sky.exr"))
    dome.CreateColorAttr(Gf.Vec3f(0.5, 0.5, 1.0))
    stage.GetRootLayer().Save()
    done = run_clean(CLEAN_BIN / "snell-usd", "render", path, "-o", tmp_path / "card.png", "--size", "16x16")
    assert done.returncode == 0, done.stderr
    warning = next((line for line in done.stderr.splitlines() if "/World/Dome: texture" in line), "")
    assert str(sky) in warning and "OpenImageIO's Python module" in warning, done.stderr
    assert "the dome's colour (0.5, 0.5, 1) is drawn instead" in warning, warning
    assert (tmp_path / "card.png").is_file()


def test_an_exr_texture_in_the_plain_venv_is_a_warning_naming_it_and_its_fallback_is_drawn(tmp_path):
    exr = tmp_path / "checker.exr"
    out = oiio.ImageOutput.create(str(exr))
    assert out is not None and out.open(str(exr), oiio.ImageSpec(2, 2, 3, "half"))
    assert out.write_image(TEXELS.astype(np.float32) / 255.0) and out.close()
    picture = tmp_path / "card.png"
    done = run_clean(CLEAN_BIN / "snell-usd", "render", textured_card(tmp_path, "checker.exr"), "-o", picture,
                     "--size", "16x16")
    assert done.returncode == 0, done.stderr
    warning = next((line for line in done.stderr.splitlines() if "/World/checker/image" in line), "")
    assert str(exr) in warning and "OpenImageIO's Python module" in warning, done.stderr
    assert "the input's fallback is drawn" in warning, warning
    middle = oiio.ImageBuf(str(picture)).get_pixels(oiio.FLOAT)[8, 8]
    assert middle[1] < 0.75 * min(middle[0], middle[2]), f"the fallback's magenta, lit: {middle}"
    strict = run_clean(CLEAN_BIN / "snell-usd", "render", tmp_path / "card.usda", "-o", tmp_path / "strict.png",
                       "--size", "16x16", "--strict")
    assert strict.returncode == 1 and str(exr) in strict.stderr, strict.stderr
    assert not (tmp_path / "strict.png").exists()
