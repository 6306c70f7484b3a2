"""Each texture mapping of snell.usd renders as its glTF twin does, and changes the picture.

The mappings: an emissive texture, a normal map, a cut-out from the diffuse
texture's alpha or from an opacity texture, presence coverage, clamp and
mirror wraps, and a UsdTransform2d per texture. Each case is a quad (with a
wall behind it where something shows through) seen from above and to the
right, lit by the headlight, so a normal bent up differs from one bent down.
The twin is written by hand from glTF's own definitions, not from snell.usd's
code: UV sets baked through UsdTransform2d's formula, a KHR_texture_transform
derived by hand where it is written. Both sides render in one device at 64 x 48: cheap
on lavapipe.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import numpy as np
import pytest
from pxr import Usd, UsdShade

import snell
import snell.usd
from conftest import srgb8
from gltf_writer import GltfWriter
from stages import bind, connect, new_stage, preview_material, quad, texture, transform2d, write_rgba_png

WIDTH, HEIGHT = 64, 48
VIEW = {"eye": (0.6, 0.9, 3.2), "target": (0.0, 0.0, 0.0), "yfov": 0.75}
QUAD_POINTS = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], np.float32)  # stages.quad's
QUAD_ST = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float64)
WALL_Z, WALL_COLOUR = -0.6, (0.15, 0.45, 0.9)
DIFFUSE_2D = {"rotation": 30.0, "scale": (1.5, 2.0), "translation": (0.1, 0.3)}
EMISSIVE_2D = {"rotation": -50.0, "scale": (0.75, 1.25), "translation": (0.2, -0.1)}


# ---------------------------------------------------------------- textures


def pattern() -> np.ndarray:
    """16 x 16 RGB, red across and green down, so a turn or a flip of the UVs shows."""
    y, x = np.mgrid[0:16, 0:16]
    return np.stack([x * 16 + 8, y * 16 + 8, np.where((x // 4 + y // 4) % 2, 200, 40)], -1).astype(np.uint8)


def checker() -> np.ndarray:
    y, x = np.mgrid[0:8, 0:8]
    on = ((x + y) % 2).astype(bool)[..., None]
    return np.where(on, np.uint8([230, 190, 60]), np.uint8([40, 70, 160])).astype(np.uint8)


def ripples() -> np.ndarray:
    """A 16 x 16 tangent-space normal map (glTF's bytes): ripples across, and a slope up the image at the top
    and down it at the bottom, so reading +Y the wrong way round changes the light."""
    y, x = (np.mgrid[0:16, 0:16] + 0.5) / 16
    n = np.stack([-0.6 * np.cos(4 * np.pi * x), 0.5 * np.cos(np.pi * y), np.ones_like(x)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.rint((n + 1) / 2 * 255).astype(np.uint8)


def holes(colour=(200, 120, 80)) -> np.ndarray:
    """8 x 8 RGBA of one colour whose alpha is 0 on every other square."""
    y, x = np.mgrid[0:8, 0:8]
    rgba = np.empty((8, 8, 4), np.uint8)
    rgba[..., :3] = colour
    rgba[..., 3] = np.where((x + y) % 2, 255, 0)
    return rgba


def write_textures(folder: Path) -> None:
    for name, image in (("pattern", pattern()), ("checker", checker()), ("ripples", ripples()),
                        ("holes", holes()), ("holes_white", holes((255, 255, 255)))):
        write_rgba_png(folder / f"{name}.png", image)


# ---------------------------------------------------------------- the twin's UVs


def usd_transform2d(st: np.ndarray, rotation: float, scale, translation) -> np.ndarray:
    """UsdTransform2d as its specification states it: scale, rotate counter-clockwise (degrees), translate."""
    a = math.radians(rotation)
    rotate = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return (st * np.asarray(scale)) @ rotate.T + np.asarray(translation)


def gltf_uvs(st: np.ndarray) -> np.ndarray:
    """glTF's UVs of USD's st: st (0, 0) is the image's lower left, glTF's (0, 0) its upper left."""
    return np.stack([st[:, 0], 1.0 - st[:, 1]], axis=1).astype(np.float32)


# ---------------------------------------------------------------- the cases


@dataclass
class Case:
    """A quad's material with a mapping (or without it: mapped False), and its glTF twin's."""

    usd: Callable[[Usd.Stage, bool], UsdShade.Material]
    gltf: Callable[[GltfWriter], int]
    wall: bool = False  #: a wall behind the quad, for what shows through
    uvs: Optional[np.ndarray] = None  #: the twin's TEXCOORD_0 (default: the quad's st)
    uvs1: Optional[np.ndarray] = None  #: and its TEXCOORD_1


def _emissive(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Lamp", diffuseColor=(0.05, 0.05, 0.05))
    if mapped:
        texture(stage, material, "./checker.png", input_name="emissiveColor", sourceColorSpace="sRGB",
                scale=(0.9, 0.7, 1.0, 1.0))
    return material


def _normal(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Bumps", diffuseColor=(0.8, 0.8, 0.8))
    if mapped:  # the specification's convention for an 8-bit normal map
        texture(stage, material, "./ripples.png", input_name="normal", sourceColorSpace="raw",
                scale=(2.0, 2.0, 2.0, 1.0), bias=(-1.0, -1.0, -1.0, 0.0))
    return material


def _cut_out(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Leaf", opacityThreshold=0.5)
    image = texture(stage, material, "./holes.png", sourceColorSpace="sRGB")
    if mapped:
        connect(material, "opacity", image, "a")
    return material


def _cut_out_of_a_colour(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Stencil", diffuseColor=(0.9, 0.5, 0.3), opacityThreshold=0.5)
    if mapped:
        texture(stage, material, "./holes.png", input_name="opacity", output="a")
    return material


def _coverage(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    return preview_material(stage, "/World/Veil", diffuseColor=(0.9, 0.3, 0.2), opacityMode="presence",
                            opacity=0.4 if mapped else 1.0)


def _wraps(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Tiles")
    wraps = ("clamp", "mirror") if mapped else ("repeat", "repeat")
    image = texture(stage, material, "./pattern.png", sourceColorSpace="sRGB", wrapS=wraps[0], wrapT=wraps[1])
    transform2d(image, scale=(2.0, 2.0), translation=(-0.5, -0.5))  # st' in [-0.5, 1.5]: the wraps show
    return material


def _wraps_twin(g: GltfWriter) -> int:
    # USD: s' = 2s - 0.5, t' = 2t - 0.5. glTF: u = s, v = 1 - t, so v' = 1 - t' = 2(1 - t) - 0.5 = 2v - 0.5:
    # KHR_texture_transform scale 2 and offset -0.5 on both axes.
    transform = {"offset": [-0.5, -0.5], "scale": [2.0, 2.0]}
    info = g.texture_info(g.texture("pattern.png", "clamp", "mirror"), transform=transform)
    return g.material(roughness=0.5, base_info=info)


def _transforms(stage: Usd.Stage, mapped: bool) -> UsdShade.Material:
    material = preview_material(stage, "/World/Poster")
    diffuse = texture(stage, material, "./pattern.png", sourceColorSpace="sRGB", wrapS="repeat", wrapT="repeat")
    emissive = texture(stage, material, "./checker.png", input_name="emissiveColor", sourceColorSpace="sRGB",
                       scale=(0.5, 0.5, 0.5, 1.0), wrapS="repeat", wrapT="repeat")
    if mapped:
        transform2d(diffuse, **DIFFUSE_2D)
        transform2d(emissive, **EMISSIVE_2D)
    return material


CASES = {
    "emissive texture": Case(_emissive, lambda g: g.material(
        base_color=(0.05, 0.05, 0.05, 1.0), roughness=0.5, emissive=(0.9, 0.7, 1.0),
        emissive_info=g.texture_info(g.texture("checker.png")))),
    "normal map": Case(_normal, lambda g: g.material(
        base_color=(0.8, 0.8, 0.8, 1.0), roughness=0.5, normal_info=g.texture_info(g.texture("ripples.png")))),
    "cut-out from the diffuse alpha": Case(_cut_out, lambda g: g.material(
        roughness=0.5, base_info=g.texture_info(g.texture("holes.png")), alpha_mode="MASK", alpha_cutoff=0.5),
        wall=True),
    "cut-out from an opacity texture": Case(_cut_out_of_a_colour, lambda g: g.material(
        base_color=(0.9, 0.5, 0.3, 1.0), roughness=0.5, base_info=g.texture_info(g.texture("holes_white.png")),
        alpha_mode="MASK", alpha_cutoff=0.5), wall=True),
    "presence coverage": Case(_coverage, lambda g: g.material(
        base_color=(0.9, 0.3, 0.2, 0.4), roughness=0.5, alpha_mode="BLEND"), wall=True),
    "clamp and mirror wraps": Case(_wraps, _wraps_twin),
    "a UsdTransform2d per texture": Case(_transforms, lambda g: g.material(
        roughness=0.5, base_info=g.texture_info(g.texture("pattern.png")), emissive=(0.5, 0.5, 0.5),
        emissive_info=g.texture_info(g.texture("checker.png"), tex_coord=1)),
        uvs=gltf_uvs(usd_transform2d(QUAD_ST, **DIFFUSE_2D)), uvs1=gltf_uvs(usd_transform2d(QUAD_ST, **EMISSIVE_2D))),
}


# ---------------------------------------------------------------- scenes and pictures


def usd_scene(folder: Path, case: Case, mapped: bool) -> Path:
    path = folder / f"{'mapped' if mapped else 'plain'}.usda"
    stage = new_stage(path)
    bind(quad(stage, "/World/Quad").GetPrim(), case.usd(stage, mapped))
    if case.wall:
        wall = quad(stage, "/World/Wall", size=3.0, z=WALL_Z, st=False)
        bind(wall.GetPrim(), preview_material(stage, "/World/WallPaint", diffuseColor=WALL_COLOUR))
    stage.GetRootLayer().Save()
    return path


def gltf_scene(folder: Path, case: Case) -> Path:
    g = GltfWriter()
    normals = [(0.0, 0.0, 1.0)] * 4
    indices = [(0, 1, 2), (0, 2, 3)]  # the fan USD's quad face makes
    uvs = case.uvs if case.uvs is not None else gltf_uvs(QUAD_ST)
    g.node(mesh=g.mesh([{"positions": QUAD_POINTS, "normals": normals, "indices": indices, "uvs": uvs,
                         "uvs1": case.uvs1, "material": case.gltf(g)}]))
    if case.wall:
        paint = g.material(base_color=(*WALL_COLOUR, 1.0), roughness=0.5)
        wall = QUAD_POINTS * np.float32([1.5, 1.5, 0]) + np.float32([0, 0, WALL_Z])
        g.node(mesh=g.mesh([{"positions": wall, "normals": normals, "indices": indices, "material": paint}]))
    return g.write(folder / "twin.gltf")


def render(device: snell.Device, path: Path) -> tuple[np.ndarray, list[str]]:
    """The picture (8-bit sRGB as ints) of a stage or a glTF file, and what snell.usd warned of."""
    view = snell.View(WIDTH, HEIGHT, **VIEW)
    if path.suffix == ".gltf":
        with snell.Scene.load(str(path)) as scene, snell.Renderer(device, scene) as renderer:
            return srgb8(renderer.render(view)), []
    with snell.usd.open(path, device=device) as stage:
        return srgb8(stage.renderer.render(view)), [str(w) for w in stage.warnings]


# ---------------------------------------------------------------- the tests


@pytest.mark.parametrize("name", CASES)
def test_each_mapping_renders_as_its_gltf_twin(device, tmp_path, name):
    case = CASES[name]
    write_textures(tmp_path)
    ours, warnings = render(device, usd_scene(tmp_path, case, mapped=True))
    twin, _ = render(device, gltf_scene(tmp_path, case))
    assert not warnings, f"{name}: snell.usd warned: {warnings}"
    difference = np.abs(ours - twin).max(axis=2)
    worst = np.unravel_index(np.argmax(difference), difference.shape)
    agree = (difference <= 1).mean()
    assert agree >= 0.99, (f"{name}: {agree:.1%} of pixels within 1/255 of the glTF twin; worst at (x, y) = "
                           f"({worst[1]}, {worst[0]}): glTF {twin[worst].tolist()}, USD {ours[worst].tolist()}")


@pytest.mark.parametrize("name", CASES)
def test_each_mapping_changes_the_picture(device, tmp_path, name):
    """So that the comparison with the twin cannot pass by both sides ignoring the mapping."""
    case = CASES[name]
    write_textures(tmp_path)
    mapped, _ = render(device, usd_scene(tmp_path, case, mapped=True))
    plain, _ = render(device, usd_scene(tmp_path, case, mapped=False))
    moved = (np.abs(mapped - plain).max(axis=2) > 8).mean()
    assert moved > 0.05, f"{name}: the mapping moved {moved:.1%} of the pixels"
