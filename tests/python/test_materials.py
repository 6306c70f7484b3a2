"""Materials from arrays take what glTF materials take: emissive and normal textures, alpha, samplers, UV transforms."""

from __future__ import annotations

import numpy as np
import pytest

import snell
from conftest import CAMERA_Z, YFOV
from gltf_writer import GltfWriter
from support import checker, holes, primitive, quad, ripples, srgb8, uv_sphere

WIDTH, HEIGHT = 160, 120
SPHERE = uv_sphere(0.5, 24, 32)
CARD = quad(1.2, 0.0)
SMALL_CARD = quad(0.5, 0.0)
WALL = quad(3.0, -1.0)
WALL_TRANSFORM = {"offset": [0.25, 0.0], "scale": [2.0, 2.0], "rotation": 0.3}
PLACES = {"card": (-0.75, 0.0, 0.3), "sphere": (0.7, 0.0, 0.0), "small card": (0.0, 0.8, 0.6)}


def translation(x: float, y: float, z: float) -> np.ndarray:
    return np.array([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]], np.float64)


def every_feature_gltf(path) -> None:
    """An emissive wall (transformed, clamped, nearest), a masked and normal-mapped card, a
    normal-mapped glass sphere and a blended card, as glTF."""
    g = GltfWriter()
    wall = g.material(base_color=(0, 0, 0, 1), emissive=(1, 1, 1),
                      emissive_info=g.texture_info(g.texture(checker(), "clamp", nearest=True),
                                                   transform=WALL_TRANSFORM))
    card = g.material(base_color=(0.9, 0.5, 0.3, 1), base_info=g.texture_info(g.texture(holes(), nearest=True)),
                      normal_info=g.texture_info(g.texture(ripples(64, 1.0)), scale=0.8), alpha_mode="MASK",
                      alpha_cutoff=0.4)
    glass = g.material(base_color=(0.95, 1.0, 0.97, 1.0), transmission=1.0, ior=1.45,
                       normal_info=g.texture_info(g.texture(ripples(64, 0.5), "mirror")))
    blended = g.material(base_color=(0.2, 0.8, 0.3, 0.35), alpha_mode="BLEND")
    g.node(mesh=g.mesh([primitive(*WALL, material=wall)]))
    g.node(mesh=g.mesh([primitive(*CARD, material=card)]), translation=list(PLACES["card"]))
    g.node(mesh=g.mesh([primitive(*SPHERE, material=glass)]), translation=list(PLACES["sphere"]))
    g.node(mesh=g.mesh([primitive(*SMALL_CARD, material=blended)]), translation=list(PLACES["small card"]))
    g.camera(YFOV, None, (0.0, 0.0, CAMERA_Z), znear=0.01)
    g.write(path)


def every_feature_materials() -> list[snell.Material]:
    """The glTF scene's materials, as snell.Material."""
    wall_transform = snell.TextureTransform(offset=WALL_TRANSFORM["offset"], rotation=WALL_TRANSFORM["rotation"],
                                            scale=WALL_TRANSFORM["scale"])
    return [
        snell.Material(base_color=(0, 0, 0, 1), emissive=(1, 1, 1), emissive_texture=0,
                       emissive_transform=wall_transform),
        snell.Material(base_color=(0.9, 0.5, 0.3, 1), base_color_texture=1, normal_texture=2, normal_scale=0.8,
                       alpha_mode="mask", alpha_cutoff=0.4),
        snell.Material(base_color=(0.95, 1.0, 0.97, 1.0), transmission=1.0, ior=1.45, normal_texture=3),
        snell.Material(base_color=(0.2, 0.8, 0.3, 0.35), alpha_mode="blend"),
    ]


def every_feature_arrays(materials: list[snell.Material] | None = None) -> snell.Scene:
    """The same scene through Scene.from_arrays (with other materials, if given)."""
    textures = [
        snell.Texture(checker(), wrap_s="clamp", wrap_t="clamp", nearest=True),
        snell.Texture(holes(), nearest=True),
        snell.Texture(ripples(64, 1.0)),
        snell.Texture(ripples(64, 0.5), wrap_s="mirror", wrap_t="mirror"),
    ]
    meshes = [snell.Mesh(*WALL, material=0), snell.Mesh(*CARD, material=1), snell.Mesh(*SPHERE, material=2),
              snell.Mesh(*SMALL_CARD, material=3)]
    instances = [snell.Instance(0), snell.Instance(1, translation(*PLACES["card"])),
                 snell.Instance(2, translation(*PLACES["sphere"])),
                 snell.Instance(3, translation(*PLACES["small card"]))]
    camera = snell.Camera(transform=translation(0.0, 0.0, CAMERA_Z), yfov=YFOV)
    return snell.Scene.from_arrays(meshes, materials=materials or every_feature_materials(), textures=textures,
                                   instances=instances, cameras=[camera], name="every feature")


def test_texture_slots_alpha_and_samplers_from_arrays_render_like_their_gltf(device, tmp_path):
    every_feature_gltf(tmp_path / "features.gltf")
    pictures = []
    for scene in (snell.Scene.load(str(tmp_path / "features.gltf")), every_feature_arrays()):
        with snell.Renderer(device, scene) as renderer:
            pictures.append(srgb8(renderer.render(snell.View(WIDTH, HEIGHT, camera=0, method="trace"))).astype(int))
    assert np.abs(pictures[0] - pictures[1]).max() <= 1, "arrays and glTF draw the same materials differently"


@pytest.mark.parametrize("material, field, value", [
    (0, "emissive_texture", -1), (0, "emissive_transform", snell.TextureTransform()), (1, "normal_texture", -1),
    (1, "alpha_mode", "opaque"), (2, "normal_texture", -1), (3, "alpha_mode", "opaque")])
def test_each_new_material_field_changes_the_picture(device, material, field, value):
    """So that the comparison with glTF above cannot pass by both sides ignoring a field."""
    view = snell.View(WIDTH, HEIGHT, camera=0, method="trace")
    with snell.Renderer(device, every_feature_arrays()) as renderer:
        full = srgb8(renderer.render(view)).astype(int)
    materials = every_feature_materials()
    setattr(materials[material], field, value)
    with snell.Renderer(device, every_feature_arrays(materials)) as renderer:
        changed = srgb8(renderer.render(view)).astype(int)
    moved = (np.abs(changed - full).max(axis=2) > 8).mean()
    assert moved > 0.005, f"material {material}'s {field} = {value!r} left the picture as it was"


def test_a_texture_index_past_the_textures_is_named():
    with pytest.raises(snell.Error, match="normalTexture 5 of 0 textures"):
        snell.Scene.from_arrays([snell.Mesh(*CARD, material=0)], materials=[snell.Material(normal_texture=5)])


@pytest.mark.parametrize("make", [lambda: snell.Material(alpha_mode="translucent"),
                                  lambda: snell.Texture(holes(), wrap_s="wrap")])
def test_an_unknown_alpha_mode_or_wrap_is_named(make):
    with pytest.raises(snell.Error, match="translucent|wrap"):
        make()
