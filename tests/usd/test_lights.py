"""UsdLux lights as snell's punctual lights, by the conversions of docs/usd.md."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import Gf, UsdLux

import snell.usd
from stages import new_stage, quad, sphere_light


def lights_of(tmp_path, build):
    stage = new_stage(tmp_path / "l.usda")
    quad(stage, "/World/Card")
    build(stage)
    stage.GetRootLayer().Save()
    contents = snell.usd.read(tmp_path / "l.usda")
    return contents, contents.snell_lights(), "\n".join(str(w) for w in contents.problems.items)


def test_a_sphere_light_is_a_point_light_of_its_intensity(tmp_path):
    def build(stage):
        sphere_light(stage, "/World/Bulb", (1, 2, 3), intensity=100.0, radius=0.2, exposure=2.0,
                     color=Gf.Vec3f(1.0, 0.5, 0.25))

    _, (light,), _ = lights_of(tmp_path, build)
    assert light.type == "point"
    assert light.intensity == pytest.approx(100.0 * 4 * math.pi * 0.2 ** 2, rel=1e-6)  # L pi r^2, L = 100 * 2^2
    np.testing.assert_allclose(light.position, (1, 2, 3))
    np.testing.assert_allclose(light.color, (1.0, 0.5, 0.25))


def test_a_normalized_sphere_light_keeps_its_power_whatever_its_size(tmp_path):
    def build(stage):
        sphere_light(stage, "/World/Small", (0, 0, 2), intensity=80.0, radius=0.1, normalize=True)
        sphere_light(stage, "/World/Large", (0, 0, 2), intensity=80.0, radius=2.0, normalize=True)

    _, (small, large), _ = lights_of(tmp_path, build)
    assert small.intensity == pytest.approx(20.0) and large.intensity == pytest.approx(20.0)  # L / 4


def test_a_distant_light_gives_the_illuminance_of_its_angular_size(tmp_path):
    def build(stage):
        sun = UsdLux.DistantLight.Define(stage, "/World/Sun")
        sun.CreateIntensityAttr(1000.0)
        sun.CreateAngleAttr(4.0)
        sun.AddRotateXOp().Set(-90.0)  # -Z turned to -Y: shining down
        lamp = UsdLux.DistantLight.Define(stage, "/World/Normalized")
        lamp.CreateIntensityAttr(3.0)
        lamp.CreateNormalizeAttr(True)

    _, (sun, lamp), _ = lights_of(tmp_path, build)
    assert sun.type == "directional"
    assert sun.intensity == pytest.approx(1000.0 * math.pi * math.sin(math.radians(2.0)) ** 2, rel=1e-6)
    np.testing.assert_allclose(sun.direction, (0, -1, 0), atol=1e-6)
    assert lamp.intensity == pytest.approx(3.0)


def test_a_shaped_sphere_light_is_a_spot(tmp_path):
    def build(stage):
        light = sphere_light(stage, "/World/Spot", (0, 0, 4), intensity=50.0, radius=0.1)
        shaping = UsdLux.ShapingAPI.Apply(light.GetPrim())
        shaping.CreateShapingConeAngleAttr(40.0)
        shaping.CreateShapingConeSoftnessAttr(0.25)

    _, (spot,), _ = lights_of(tmp_path, build)
    assert spot.type == "spot"
    assert spot.outer_cone_angle == pytest.approx(math.radians(40.0))
    assert spot.inner_cone_angle == pytest.approx(math.radians(30.0))
    np.testing.assert_allclose(spot.direction, (0, 0, -1))


def test_a_rect_light_is_a_point_light_of_the_same_power_with_a_message(tmp_path):
    def build(stage):
        rect = UsdLux.RectLight.Define(stage, "/World/Panel")
        rect.CreateIntensityAttr(40.0)
        rect.CreateWidthAttr(2.0)
        rect.CreateHeightAttr(0.5)

    _, (light,), text = lights_of(tmp_path, build)
    assert light.type == "point" and light.intensity == pytest.approx(40.0 * 2.0 * 0.5 / 4)
    assert "/World/Panel: a RectLight shines as a point light of the same power (10 cd)" in text


def test_a_portal_light_is_a_warning_and_gives_snell_no_light(tmp_path):
    _, lights, text = lights_of(tmp_path, lambda stage: UsdLux.PortalLight.Define(stage, "/World/Window"))
    assert lights == [] and "/World/Window: a PortalLight: a portal only guides a dome light: skipped" in text


def test_a_stage_without_lights_is_lit_by_snells_headlight(tmp_path, device):
    contents, lights, _ = lights_of(tmp_path, lambda stage: None)
    assert lights == [] and contents.lights == []
    with snell.usd.Stage(contents, device=device) as stage:
        middle = stage.render(40, 30)[15, 20, :3]
    # shared/trace.h: the fallback grey 0.18 under the headlight (E = pi along the view): ambient 0.03 * 0.18,
    # Lambert E * 0.18 / pi and the highlight 0.04 E; ambient alone would be 0.0054.
    np.testing.assert_allclose(middle, 0.03 * 0.18 + 0.18 + 0.04 * math.pi, rtol=1e-2)
