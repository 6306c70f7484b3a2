"""Renderer.render_aovs: what each pixel's ray found, as `snell render --aov` writes it."""

from __future__ import annotations

import numpy as np
import pytest

import snell
from support import quad, uv_sphere

WIDTH, HEIGHT = 64, 48
MISS = 0xFFFFFFFF
ANGLE = np.radians(30.0)


def turned_card_and_glass() -> snell.Scene:
    """A card turned 30 degrees about +Y at the origin, and a glass sphere to its right."""
    c, s = np.cos(ANGLE), np.sin(ANGLE)
    turn = np.array([[c, 0, s, -0.6], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]], np.float64)
    card = snell.Mesh(*quad(1.0, 0.0)[:3], material=0)
    glass = snell.Mesh(*uv_sphere(0.35, 16, 24, centre=(0.6, 0.0, 0.0))[:3], material=1)
    return snell.Scene.from_arrays(
        [card, glass],
        materials=[snell.Material(base_color=(0.8, 0.8, 0.8, 1)), snell.Material(transmission=1.0, ior=1.5)],
        instances=[snell.Instance(0, turn), snell.Instance(1)])


@pytest.fixture(scope="module")
def aovs(device):
    with snell.Renderer(device, turned_card_and_glass()) as renderer:
        view = snell.View(WIDTH, HEIGHT, eye=(0, 0, 3), target=(0, 0, 0), yfov=0.6)
        yield renderer.render_aovs(view), renderer.render(snell.View(WIDTH, HEIGHT, eye=(0, 0, 3), target=(0, 0, 0),
                                                                     yfov=0.6, method="trace"))


def test_every_plane_has_the_views_shape_and_type(aovs):
    planes, _ = aovs
    shapes = {"rgba": ((HEIGHT, WIDTH, 4), np.float32), "depth": ((HEIGHT, WIDTH), np.float32),
              "normal": ((HEIGHT, WIDTH, 3), np.float32), "instance": ((HEIGHT, WIDTH), np.uint32),
              "primitive": ((HEIGHT, WIDTH), np.uint32), "interfaces": ((HEIGHT, WIDTH), np.uint32),
              "cost": ((HEIGHT, WIDTH), np.uint32)}
    assert set(planes) == set(shapes)
    for name, (shape, dtype) in shapes.items():
        assert planes[name].shape == shape and planes[name].dtype == dtype, name


def test_the_colour_is_the_traced_picture_and_alpha_its_coverage(aovs):
    planes, traced = aovs
    np.testing.assert_array_equal(planes["rgba"][..., :3], traced[..., :3])
    hit = planes["instance"] != MISS
    assert hit.any() and (~hit).any()
    np.testing.assert_array_equal(planes["rgba"][..., 3], hit.astype(np.float32))


def test_depth_and_normal_are_the_first_surfaces_in_camera_and_world_space(aovs):
    planes, _ = aovs
    card = planes["instance"] == 0
    # The card's plane through (-0.6, 0, 0) with normal (sin 30, 0, cos 30): its camera depth at each pixel.
    normal = np.array([np.sin(ANGLE), 0.0, np.cos(ANGLE)])
    np.testing.assert_allclose(planes["normal"][card], np.broadcast_to(normal, planes["normal"][card].shape), atol=1e-5)
    rows, columns = np.nonzero(card)
    t = np.tan(0.3)
    sx = (2 * (columns + 0.5) / WIDTH - 1) * t * WIDTH / HEIGHT
    # Ray (0, 0, 3) + s (sx, sy, -1) meets n . (p - (-0.6, 0, 0)) = 0 at camera depth s (n has no y: sy drops out).
    depth = (normal[0] * 0.6 + normal[2] * 3.0) / (-normal[0] * sx + normal[2])
    np.testing.assert_allclose(planes["depth"][card], depth, rtol=1e-4)
    miss = planes["instance"] == MISS
    assert np.isinf(planes["depth"][miss]).all() and not planes["normal"][miss].any()
    assert (planes["primitive"][miss] == MISS).all() and (planes["primitive"][card] < 2).all()


def test_glass_counts_its_interfaces_and_every_traced_pixel_its_cost(aovs):
    planes, _ = aovs
    glass = planes["instance"] == 1
    assert glass.any() and (planes["interfaces"][glass] >= 2).all(), "a ray through the sphere crosses it twice"
    assert (planes["interfaces"][planes["instance"] == 0] == 0).all()
    assert (planes["cost"][planes["instance"] != MISS] > 0).all()


def test_a_method_that_does_not_trace_is_refused(device):
    with snell.Renderer(device, turned_card_and_glass()) as renderer:
        with pytest.raises(snell.Error, match="trace"):
            renderer.render_aovs(snell.View(WIDTH, HEIGHT, method="iris-plane"))
