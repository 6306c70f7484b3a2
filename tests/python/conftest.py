"""Fixtures of the module's tests: one device, snell's command line, and the lens scene.

ctest runs each test on its own (tests/CMakeLists.txt) with SNELL_VALIDATION=1,
PYTHONPATH at the built module and SNELL_BINARY at the built command line.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import snell
from support import checker, primitive, quad, uv_sphere

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from gltf_writer import GltfWriter  # noqa: E402 (tests/, shared with tests/usd)
from snell_session import VALIDATION, device  # noqa: E402,F401 (device: a fixture, found by its name)


@pytest.fixture(scope="session")
def snell_binary() -> Path:
    path = Path(os.environ.get("SNELL_BINARY", "build/release/snell"))
    if not path.exists():
        pytest.fail(f"snell's command line is not at {path} (set SNELL_BINARY)")
    return path


def run_snell(binary: Path, *args: str) -> None:
    """Runs snell; a non-zero exit fails the test with its standard error."""
    done = subprocess.run([str(binary), "--quiet", *map(str, args)], capture_output=True, text=True, timeout=300)
    if done.returncode != 0:
        pytest.fail(f"snell {' '.join(map(str, args))} exited {done.returncode}: {done.stderr}")


# The lens: a glass sphere in front of a checkered wall, seen by a camera on +Z.
# Its one morph target squashes the sphere (y shrinks, x and z swell); an
# animation drives the weight from 0 at 0 s to 1 at 1 s.
SPHERE = uv_sphere(0.5, 24, 32)


def squash_target():
    """The morph target's (position deltas, normal deltas) for SPHERE."""
    positions, normals, _, _ = SPHERE
    squashed = positions * np.array([1.25, 0.6, 1.25], np.float32)
    # A squashed sphere's normals: the gradient of x²/a² + y²/b² + z²/c², normalised.
    n = squashed / np.array([1.25, 0.6, 1.25], np.float32) ** 2
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return (squashed - positions).astype(np.float32), (n - normals).astype(np.float32)


WALL = quad(3.0, -1.0)
CAMERA_Z = 3.0
YFOV = 0.6


@pytest.fixture(scope="session")
def lens_gltf(tmp_path_factory) -> Path:
    """The lens scene as glTF: what `snell render` and Scene.load read."""
    g = GltfWriter()
    wall = g.material(texture=checker())
    glass = g.material(base_color=(0.95, 1.0, 0.97, 1.0), transmission=1.0, ior=1.45)
    g.node(mesh=g.mesh([primitive(*WALL, material=wall)]))
    sphere = g.node(mesh=g.mesh([primitive(*SPHERE[:3], material=glass, targets=[squash_target()])], weights=[0.0]))
    g.animate(sphere, "weights", [0.0, 1.0], [0.0, 1.0])
    g.camera(YFOV, None, (0.0, 0.0, CAMERA_Z), znear=0.01)
    return g.write(tmp_path_factory.mktemp("lens") / "lens.gltf")


def lens_arrays() -> snell.Scene:
    """The same lens from numpy arrays, unmorphed; the test moves its vertices."""
    positions, normals, indices, uvs = WALL
    wall = snell.Mesh(positions, normals, indices, uvs, material=0, name="wall")
    glass = snell.Mesh(*SPHERE[:3], material=1, name="lens")
    return snell.Scene.from_arrays(
        [wall, glass],
        materials=[
            snell.Material(base_color_texture=0, roughness=1.0),
            snell.Material(base_color=(0.95, 1.0, 0.97, 1.0), transmission=1.0, ior=1.45, roughness=1.0),
        ],
        textures=[snell.Texture(checker())],
        cameras=[snell.Camera(transform=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, CAMERA_Z], [0, 0, 0, 1]]),
                              yfov=YFOV)],
        name="lens arrays",
    )
