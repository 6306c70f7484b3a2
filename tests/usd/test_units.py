"""metersPerUnit and upAxis: a Z-up stage in centimetres is the same scene as a Y-up one in metres."""

from __future__ import annotations

import numpy as np
from pxr import Gf, UsdLux

import snell.usd
from conftest import srgb8, unexpected
from stages import bind, mesh, new_stage, preview_material, sphere_arrays, sphere_light, texture, write_rgba_png

WIDTH, HEIGHT = 160, 120


def y_up_to_z_up(p) -> np.ndarray:
    """Metres, +Y up -> the same place in a Z-up stage: (x, y, z) -> (x, -z, y)."""
    p = np.asarray(p, np.float64)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def lens_stage(path, up: str, scale: float):
    """A glass ball over a floor in front of a checkered wall, lit by a sphere and a distant light; no camera.

    up 'Y' writes it as it is (scale 1: metres); up 'Z' writes every point, normal and position turned to
    Z-up and every length times `scale` (100: centimetres)."""
    turn = y_up_to_z_up if up == "Z" else (lambda p: np.asarray(p, np.float64))
    stage = new_stage(path, up=up, meters_per_unit=1.0 / scale)
    checker = np.kron((np.indices((4, 4)).sum(0) % 2), np.ones((8, 8))).astype(np.uint8)[..., None]
    write_rgba_png(path.parent / "checker.png", (checker * [200, 150, 40] + [40, 60, 150]).astype(np.uint8))
    wall = preview_material(stage, "/World/Looks/Wall", roughness=1.0)
    texture(stage, wall, "./checker.png", sourceColorSpace="sRGB", wrapS="repeat", wrapT="repeat")
    glass = preview_material(stage, "/World/Looks/Glass", opacity=0.0, ior=1.45, diffuseColor=(0.95, 1.0, 0.97))
    floor = preview_material(stage, "/World/Looks/Floor", diffuseColor=(0.6, 0.5, 0.4))
    quad_points = np.array([(-2, -1.2, -1), (2, -1.2, -1), (2, 1.8, -1), (-2, 1.8, -1)], float)
    w = mesh(stage, "/World/Wall", turn(quad_points) * scale, [4], [0, 1, 2, 3], normals=turn([(0, 0, 1)] * 4),
             st=[(0, 0), (2, 0), (2, 1.5), (0, 1.5)])
    bind(w.GetPrim(), wall)
    floor_points = np.array([(-2, -0.6, 1.5), (2, -0.6, 1.5), (2, -0.6, -1), (-2, -0.6, -1)], float)
    f = mesh(stage, "/World/Floor", turn(floor_points) * scale, [4], [0, 1, 2, 3], normals=turn([(0, 1, 0)] * 4))
    bind(f.GetPrim(), floor)
    points, counts, indices, normals = sphere_arrays(0.5, 16, 24, centre=(0.3, 0.0, 0.2))
    ball = mesh(stage, "/World/Ball", turn(points) * scale, counts, indices, normals=turn(normals))
    bind(ball.GetPrim(), glass)
    sphere_light(stage, "/World/Key", turn((2.0, 3.0, 4.0)) * scale, intensity=300.0, radius=0.3 * scale)
    sun = UsdLux.DistantLight.Define(stage, "/World/Sun")
    sun.CreateIntensityAttr(1.5)
    sun.CreateNormalizeAttr(True)
    # The sun's -Z points down and back (towards -Y, -Z in metres, Y-up): its matrix's z axis is the opposite.
    back = np.array([0.0, 0.6, 0.8])
    right = np.array([1.0, 0.0, 0.0])
    up_axis = np.cross(back, right)
    rows = np.stack([turn(right), turn(up_axis), turn(back)])
    sun.AddTransformOp().Set(Gf.Matrix4d(*[float(v) for row in rows for v in (*row, 0.0)], 0, 0, 0, 1))
    stage.GetRootLayer().Save()
    return path


def test_a_z_up_centimetre_stage_renders_as_the_y_up_metre_one(tmp_path, device):
    (tmp_path / "m").mkdir()
    (tmp_path / "cm").mkdir()
    metres = lens_stage(tmp_path / "m" / "lens.usda", "Y", 1.0)
    centimetres = lens_stage(tmp_path / "cm" / "lens.usda", "Z", 100.0)
    pictures, bounds = [], []
    for path in (metres, centimetres):
        with snell.usd.open(path, device=device) as stage:
            assert not unexpected(stage.warnings), unexpected(stage.warnings)
            pictures.append(srgb8(stage.render(WIDTH, HEIGHT)))  # no camera: the framed view, looking down -Z
            bounds.append(stage.bounds())
    np.testing.assert_allclose(bounds[1], bounds[0], rtol=1e-5, atol=1e-5)  # in metres, +Y up, both
    differ = np.abs(pictures[0] - pictures[1]).max(axis=2) > 1
    assert differ.mean() <= 0.01, f"{differ.sum()} pixels differ by more than 1/255"
    assert (pictures[0].max(axis=2) > 40).mean() > 0.3, "the framed view shows too little of the scene"


def test_the_lights_follow_the_stage_units(tmp_path):
    """A sphere light of radius r (stage units) has L pi (r m)^2 candela, m the metres per unit."""
    metres = snell.usd.read(lens_stage(tmp_path / "lens_m.usda", "Y", 1.0)).snell_lights()
    centimetres = snell.usd.read(lens_stage(tmp_path / "lens_cm.usda", "Z", 100.0)).snell_lights()
    np.testing.assert_allclose([metres[0].intensity, centimetres[0].intensity], 300.0 * np.pi * 0.3 ** 2, rtol=1e-6)
    np.testing.assert_allclose(centimetres[0].position, (2.0, 3.0, 4.0), atol=1e-5)
    np.testing.assert_allclose(centimetres[1].direction, metres[1].direction, atol=1e-6)
    np.testing.assert_allclose(metres[1].direction, (0.0, -0.6, -0.8), atol=1e-6)
