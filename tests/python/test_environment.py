"""snell.Environment: what glass reflects, given by the host as an equirectangular map of its own pixels."""

from __future__ import annotations

import numpy as np
import pytest

import snell

SIZE = 33  # odd: the centre pixel's ray meets the card head on


def glass_card() -> snell.Scene:
    """A thin glass card (IOR 1.5) facing +Z, lit by a dark light so no highlight lands on it."""
    positions = np.float32([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    card = snell.Mesh(positions, np.float32([[0, 0, 1]] * 4), np.uint32([[0, 1, 2], [0, 2, 3]]), material=0)
    return snell.Scene.from_arrays([card], materials=[snell.Material(transmission=1.0, ior=1.5, roughness=0.1)],
                                   lights=[snell.Light(type="directional", intensity=0.0)])


def centre(renderer: snell.Renderer, environment) -> np.ndarray:
    view = snell.View(SIZE, SIZE, eye=(0, 0, 3), method="trace", background=(0, 0, 0), environment=environment)
    return renderer.render(view)[SIZE // 2, SIZE // 2, :3]


def test_glass_reflects_the_environment_by_fresnels_reflectance_head_on(device):
    """Head on, a boundary of IOR 1.5 reflects ((n - 1) / (n + 1))^2 = 4 % of what lies behind the camera."""
    sky = np.zeros((16, 32, 3), np.float32)  # its middle column looks down -Z, its ends (the reflection) up +Z
    sky[:, :2] = sky[:, -2:] = (1.0, 2.0, 4.0)
    with snell.Renderer(device, glass_card()) as renderer:
        dark = centre(renderer, snell.Environment(np.zeros((16, 32, 3), np.float32)))
        lit = centre(renderer, snell.Environment(sky, name="sky"))
    np.testing.assert_allclose(lit - dark, 0.04 * np.float32([1.0, 2.0, 4.0]), rtol=0.01)


def test_a_view_without_an_environment_reflects_the_studio_gradient(device):
    with snell.Renderer(device, glass_card()) as renderer:
        black = centre(renderer, snell.Environment(np.zeros((1, 1, 3), np.float32)))
        studio = centre(renderer, None)
    assert np.all(studio > black + 0.004), (studio, black)


def test_a_negative_or_non_finite_texel_is_an_error_naming_the_environment():
    sky = np.ones((4, 8, 3), np.float32)
    sky[1, 2, 0] = np.nan
    with pytest.raises(snell.Error, match="^sky: the environment has a negative or non-finite texel"):
        snell.Environment(sky, name="sky")
    with pytest.raises(snell.Error, match=r"ground: an environment must be \(height, width, 3\) RGB"):
        snell.Environment(np.ones((4, 8), np.float32), name="ground")


def test_an_environment_wider_than_4096_texels_is_halved_until_it_fits():
    wide = snell.Environment(np.ones((2, 10000, 3), np.float32))
    assert (wide.width, wide.height) == (2500, 1)
