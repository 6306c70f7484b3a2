"""A UsdLux DomeLight is snell's environment: what glass reflects (docs/usd.md, Lights).

A thin glass card faces the camera head on, so the ray the card reflects at
the picture's centre leaves along snell's +Z. That pixel is the card's own
light plus R times the environment along +Z, linear in the environment: a
black dome gives the first term, a white one calibrates R per channel, and
(pixel - black) / (white - black) is the dome's radiance seen along +Z.
"""

from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdLux

import snell
import snell.usd
from conftest import snell_usd_ok
from stages import bind, dome_light, mesh, new_stage, preview_material, write_hdr

SIZE = 33  # odd: the centre pixel's ray runs along the axis
#: The dome's texture by region of its lat-long (OpenEXR's: the middle column looks down +Z, a quarter of the
#: width to its left down +X), each a colour no other region has.
REGIONS = {"+Z": (1.0, 0.05, 0.05), "+X": (0.05, 1.0, 0.05), "-X": (0.05, 0.05, 1.0), "-Z": (1.0, 1.0, 0.05),
           "+Y": (1.0, 0.05, 1.0), "-Y": (0.05, 1.0, 1.0)}


def region_texture(path, width: int = 64, height: int = 32):
    """An HDR lat-long map of REGIONS: the poles' quarters of the height, then the four sides' longitudes."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    side = np.select([(u >= 0.125) & (u < 0.375), (u >= 0.375) & (u < 0.625), (u >= 0.625) & (u < 0.875)],
                     ["+X", "+Z", "-X"], "-Z")
    image = np.array([[REGIONS["+Y" if y < 0.25 else "-Y" if y > 0.75 else side[x]] for x in range(width)]
                      for y in v])
    return write_hdr(path, image)


def glass_card_stage(path, up: str = "Y", dome=None):
    """A 2 m glass card facing the framed view (snell's +Z, whatever the stage's up axis), and a dome."""
    stage = new_stage(path, up=up)
    points = np.float32([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)])
    normal = (0, 0, 1)
    if up == "Z":  # snell's (x, y, z) is the stage's (x, -z, y)
        points, normal = points[:, [0, 2, 1]] * (1, -1, 1), (0, -1, 0)
    card = mesh(stage, "/World/Card", points, [4], [0, 1, 2, 3], normals=[normal] * 4)
    bind(card.GetPrim(), preview_material(stage, "/World/Glass", opacity=0.0, ior=1.5, roughness=0.1))
    # A dark light: without one snell's headlight would put its highlight where the card reflects the dome.
    UsdLux.DistantLight.Define(stage, "/World/Dark").CreateIntensityAttr(0.0)
    if dome is not None:
        dome(stage)
    stage.GetRootLayer().Save()
    return path


def centre(path, device) -> np.ndarray:
    """The centre pixel's linear RGB through the framed view, on a black background."""
    with snell.usd.open(path, device=device) as stage:
        rgba = stage.render(SIZE, SIZE, method="trace", background=(0, 0, 0))
    return rgba[SIZE // 2, SIZE // 2, :3].astype(np.float64)


@pytest.fixture(scope="module")
def calibration(tmp_path_factory, device):
    """The centre pixel under a black dome and under a white one of radiance 1."""
    folder = tmp_path_factory.mktemp("calibration")
    dark = glass_card_stage(folder / "black.usda", dome=lambda s: dome_light(s, "/World/Dome", intensity=0.0))
    black = centre(dark, device)
    white = centre(glass_card_stage(folder / "white.usda", dome=lambda s: dome_light(s, "/World/Dome")), device)
    assert np.all(white - black > 0.02), (black, white)  # the glass reflects enough of the dome to measure
    return black, white


def seen_along_z(path, device, calibration) -> np.ndarray:
    black, white = calibration
    return (centre(path, device) - black) / (white - black)


def test_a_uniform_dome_is_its_colour_times_intensity_times_two_to_the_exposure(tmp_path, device, calibration):
    path = glass_card_stage(tmp_path / "d.usda", dome=lambda s: dome_light(
        s, "/World/Dome", color=Gf.Vec3f(0.5, 1.0, 0.25), intensity=2.0, exposure=1.0))
    np.testing.assert_allclose(seen_along_z(path, device, calibration), (2.0, 4.0, 1.0), rtol=0.02)
    contents = snell.usd.read(path)
    (record,) = [r for r in contents.lights if r.kind == "DomeLight"]
    assert record.light is None and "snell's environment, uniform (2, 4, 1)" in record.summary
    assert [light.intensity for light in contents.snell_lights()] == [0.0]  # the dark light's; none of the dome's


TURNS = {
    "a DomeLight on a Y-up stage (OpenEXR's orientation)": ("Y", False, None, "+Z"),
    "a DomeLight turned 90 degrees about Y": ("Y", False, 90.0, "-X"),
    "a DomeLight_1 on a Z-up stage (poleAxis scene: its pole up +Z)": ("Z", True, None, "+Z"),
    "a DomeLight on a Z-up stage (its pole up +Y, as its schema says)": ("Z", False, None, "-Y"),
}


@pytest.mark.parametrize("case", sorted(TURNS))
def test_the_dome_texture_is_seen_along_the_direction_usd_gives_it(tmp_path, device, calibration, case):
    up, version_1, turn, region = TURNS[case]
    texture = region_texture(tmp_path / "regions.hdr")

    def dome(stage):
        light = dome_light(stage, "/World/Dome", texture=str(texture), version_1=version_1)
        if turn is not None:
            light.AddRotateYOp().Set(turn)

    seen = seen_along_z(glass_card_stage(tmp_path / "d.usda", up=up, dome=dome), device, calibration)
    np.testing.assert_allclose(seen, REGIONS[region], atol=0.03, err_msg=f"snell's +Z should see {region}")


def test_a_dome_1_pole_axis_z_on_a_y_up_stage_turns_its_top_pole_to_z(tmp_path, device, calibration):
    texture = region_texture(tmp_path / "regions.hdr")

    def dome(stage):
        dome_light(stage, "/World/Dome", texture=str(texture), version_1=True).GetPrim().CreateAttribute(
            "poleAxis", Sdf.ValueTypeNames.Token).Set("Z")

    seen = seen_along_z(glass_card_stage(tmp_path / "d.usda", dome=dome), device, calibration)
    np.testing.assert_allclose(seen, REGIONS["+Y"], atol=0.03)


def test_an_unreadable_dome_texture_is_a_warning_naming_it_and_the_dome_colour_is_drawn(
        tmp_path, device, calibration):
    (tmp_path / "sky.exr").write_bytes(b"not an image at all")
    path = glass_card_stage(tmp_path / "d.usda", dome=lambda s: dome_light(
        s, "/World/Dome", texture="./sky.exr", color=Gf.Vec3f(0.25, 0.5, 1.0)))
    np.testing.assert_allclose(seen_along_z(path, device, calibration), (0.25, 0.5, 1.0), rtol=0.02)
    warnings = "\n".join(str(w) for w in snell.usd.read(path).problems.items)
    assert "/World/Dome: texture" in warnings and "sky.exr" in warnings, warnings
    assert "the dome's colour (0.25, 0.5, 1) is drawn instead" in warnings, warnings


def test_a_missing_dome_texture_is_a_warning_and_with_strict_an_error(tmp_path):
    path = glass_card_stage(tmp_path / "d.usda", dome=lambda s: dome_light(s, "/World/Dome", texture="./gone.hdr"))
    warnings = "\n".join(str(w) for w in snell.usd.read(path).problems.items)
    assert "/World/Dome: texture file ./gone.hdr not found" in warnings, warnings
    with pytest.raises(snell.usd.StageError, match="gone.hdr not found"):
        snell.usd.read(path, strict=True)


def test_a_mirrored_ball_dome_and_a_second_dome_are_warnings(tmp_path):
    texture = region_texture(tmp_path / "regions.hdr")

    def domes(stage):
        dome_light(stage, "/World/Ball", texture=str(texture), textureFormat="mirroredBall")
        dome_light(stage, "/World/Second")

    contents = snell.usd.read(glass_card_stage(tmp_path / "d.usda", dome=domes))
    warnings = "\n".join(str(w) for w in contents.problems.items)
    assert "/World/Ball: texture" in warnings and "is a mirroredBall map; snell reads lat-long maps" in warnings
    assert "/World/Second: a second DomeLight: snell has one environment, /World/Ball's" in warnings, warnings
    assert contents.dome.path == "/World/Ball" and contents.dome.radiance.shape == (1, 1, 3)


def test_snell_usd_info_lists_the_dome_as_the_environment(tmp_path):
    texture = region_texture(tmp_path / "regions.hdr")
    path = glass_card_stage(tmp_path / "d.usda",
                            dome=lambda s: dome_light(s, "/World/Dome", texture=str(texture), intensity=3.0))
    done = snell_usd_ok("info", path)
    assert f"/World/Dome (DomeLight): snell's environment, texture {texture} x (3, 3, 3)" in done.stdout, done.stdout


def test_a_stage_without_a_dome_keeps_snells_studio_gradient(tmp_path, device):
    with snell.usd.open(glass_card_stage(tmp_path / "d.usda"), device=device) as stage:
        assert stage.environment is None and stage.view(8, 8).environment is None
