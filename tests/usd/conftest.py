"""Fixtures of snell.usd's tests: one device, the eye pair, snell-usd as a command, sRGB.

Run with the usd-core venv's python (build/venv/usd/bin/python -m pytest tests/usd),
PYTHONPATH at the built snell package (with its usd subpackage); the command
line runs as `python -m snell.usd` with the same interpreter and path.
SNELL_VALIDATION=1 turns the Khronos validation layer on, as in tests/python.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from eye_stage import EyeStage, write_eye_stage  # noqa: E402 (its glTF twin's writer is in tests/)
from snell_session import VALIDATION, device  # noqa: E402,F401 (device: a fixture, found by its name)


@pytest.fixture(scope="session")
def eyes(tmp_path_factory) -> EyeStage:
    """The rigged eye pair (USD and its glTF twin), written once per session."""
    return write_eye_stage(tmp_path_factory.mktemp("eyes"))


#: The approximation every SphereLight is warned about (docs/usd.md, Lights): the stages of the tests light
#: themselves with sphere lights, whose point-light warning is expected.
SPHERE_AS_POINT = "shines as a point light at its centre"


def unexpected(warnings) -> list[str]:
    """The warnings other than a SphereLight drawn as a point, as text."""
    return [str(w) for w in warnings if SPHERE_AS_POINT not in str(w)]


def srgb8(linear: np.ndarray) -> np.ndarray:
    """Linear RGB floats to 8-bit sRGB as snell's PNG writer encodes them, as ints for differences."""
    c = np.clip(linear[..., :3].astype(np.float64), 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.rint(s * 255.0).astype(np.int32)


def snell_usd(*args: object, timeout: float = 120) -> subprocess.CompletedProcess:
    """Runs `python -m snell.usd ARGS` with this interpreter; returns the finished process (text output)."""
    return subprocess.run([sys.executable, "-m", "snell.usd", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def snell_usd_ok(*args: object, timeout: float = 120) -> subprocess.CompletedProcess:
    """snell_usd that must succeed: exit code 0, else the assertion shows its standard error."""
    done = snell_usd(*args, timeout=timeout)
    assert done.returncode == 0, done.stderr
    return done


def read_image(path: Path) -> np.ndarray:
    """An image file as float32 (height, width, channels), through OpenImageIO."""
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    assert image is not None, oiio.geterror()
    pixels = image.read_image("float")
    image.close()
    return np.asarray(pixels)
