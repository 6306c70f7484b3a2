"""UsdGeom's parametric gprims, tessellated from their attributes as meshes."""

from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom

import snell.usd
from stages import new_stage


def read_one(tmp_path, define, time=None):
    stage = new_stage(tmp_path / "g.usda", time_range=(1, 2))
    define(stage)
    stage.GetRootLayer().Save()
    contents = snell.usd.read(tmp_path / "g.usda", time=time)
    return contents, contents.snell_meshes()


def corners(m) -> np.ndarray:
    return np.asarray(m.positions, np.float64)[np.asarray(m.indices)]


def outward(m, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Each non-degenerate triangle's winding normal, dotted with the direction from the centre to it."""
    p = corners(m)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    keep = np.linalg.norm(n, axis=1) > 1e-9
    return np.einsum("ij,ij->i", n[keep], p[keep].mean(axis=1) - centre)


@pytest.mark.parametrize("kind, attributes, lo, hi", [
    ("Cube", {"size": 3.0}, (-1.5, -1.5, -1.5), (1.5, 1.5, 1.5)),
    ("Sphere", {"radius": 0.5}, (-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)),
    ("Cylinder", {"radius": 0.5, "height": 4.0, "axis": "X"}, (-2, -0.5, -0.5), (2, 0.5, 0.5)),
    ("Cone", {"radius": 1.0, "height": 2.0, "axis": "Y"}, (-1, -1, -1), (1, 1, 1)),
    ("Capsule", {"radius": 0.25, "height": 1.0, "axis": "Z"}, (-0.25, -0.25, -0.75), (0.25, 0.25, 0.75)),
    ("Plane", {"width": 2.0, "length": 4.0, "axis": "Y"}, (-1, 0, -2), (1, 0, 2)),
])
def test_each_gprim_is_tessellated_to_the_extent_its_attributes_give(tmp_path, kind, attributes, lo, hi):
    def define(stage):
        prim = stage.DefinePrim("/World/Shape", kind)
        for name, value in attributes.items():
            prim.GetAttribute(name).Set(value)

    contents, meshes = read_one(tmp_path, define)
    assert len(meshes) == 1 and not [w for w in contents.problems.items if "skipped" in w.message]
    p = np.asarray(meshes[0].positions, np.float64)
    np.testing.assert_allclose(p.min(axis=0), lo, atol=1e-6)
    np.testing.assert_allclose(p.max(axis=0), hi, atol=1e-6)
    if kind != "Plane":
        assert (outward(meshes[0]) > 0).all()  # counter-clockwise seen from outside


def test_a_spheres_points_and_normals_lie_on_its_radius(tmp_path):
    contents, meshes = read_one(tmp_path,
                                lambda stage: UsdGeom.Sphere.Define(stage, "/World/Ball").CreateRadiusAttr(2.0))
    p, n = np.asarray(meshes[0].positions, np.float64), np.asarray(meshes[0].normals, np.float64)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 2.0, rtol=1e-6)
    np.testing.assert_allclose(n, p / 2.0, atol=1e-6)


def test_an_animated_radius_deforms_the_gprim_per_time_code(tmp_path):
    def define(stage):
        radius = UsdGeom.Sphere.Define(stage, "/World/Ball").CreateRadiusAttr()
        radius.Set(1.0, 1.0)
        radius.Set(3.0, 2.0)

    contents, meshes = read_one(tmp_path, define, time=1.0)
    source = contents.sources[0]
    assert source.deforms
    pose = contents.evaluate(2.0).poses[0][1]
    np.testing.assert_allclose(np.linalg.norm(np.asarray(pose.points, np.float64), axis=1), 3.0, rtol=1e-6)


def test_a_gprim_renders_lit_where_it_faces_the_light(tmp_path, device):
    def define(stage):
        cube = UsdGeom.Cube.Define(stage, "/World/Box")
        cube.CreateSizeAttr(1.0)
        cube.AddRotateXYZOp().Set(Gf.Vec3f(20, 30, 0))

    read_one(tmp_path, define)
    with snell.usd.open(tmp_path / "g.usda", device=device) as stage:
        rgba = stage.render(32, 32, method="trace")
    assert rgba[16, 16, :3].mean() > 4 * rgba[0, 0, :3].mean()


def lens_stage(path, as_mesh: bool):
    """A glass ball of radius 1 (IOR 1.5) before a checker of 1/4 m squares 3 m behind it, filling a 50 mm
    camera's view from 4.5 m: a Sphere gprim, or the same sphere as a 256-segment mesh with its normals."""
    from stages import bind, mesh, preview_material, sphere_arrays

    stage = new_stage(path)
    tiles, counts, indices, colours = [], [], [], []
    for i in range(-12, 12):
        for j in range(-12, 12):
            x, y = 0.25 * i, 0.25 * j
            first = len(tiles)
            tiles += [(x, y, -3), (x + 0.25, y, -3), (x + 0.25, y + 0.25, -3), (x, y + 0.25, -3)]
            counts.append(4)
            indices += [first, first + 1, first + 2, first + 3]
            colours.append((i + j) % 2)
    for parity, colour in ((0, (0.05, 0.05, 0.05)), (1, (0.9, 0.9, 0.9))):
        faces = [k for k, c in enumerate(colours) if c == parity]
        own = np.asarray(indices).reshape(-1, 4)[faces]
        wall = mesh(stage, f"/World/Wall{parity}", tiles, [4] * len(faces), own.ravel(),
                    normals=[(0, 0, 1)] * len(tiles))
        bind(wall.GetPrim(), preview_material(stage, f"/World/Wall{parity}Look", diffuseColor=colour,
                                              emissiveColor=colour))
    if as_mesh:
        points, counts, indices, normals = sphere_arrays(1.0, rings=128, segments=256)
        ball = mesh(stage, "/World/Ball", points, counts, indices, normals=normals)
    else:
        ball = UsdGeom.Sphere.Define(stage, "/World/Ball")
        ball.CreateRadiusAttr(1.0)
    bind(ball.GetPrim(), preview_material(stage, "/World/Glass", opacity=0.0, ior=1.5))
    UsdGeom.Camera.Define(stage, "/World/Camera").AddTranslateOp().Set(Gf.Vec3d(0, 0, 4.5))
    stage.GetRootLayer().Save()
    return path


def checker_parity(path, device, size: int = 256) -> np.ndarray:
    with snell.usd.open(path, device=device, image_size=(size, size)) as stage:
        rgba = stage.render(size, size)
    return rgba[..., 1] > 0.2


def test_a_glass_sphere_gprim_lens_draws_the_checker_as_a_256_segment_mesh_sphere_does(tmp_path, device,
                                                                                          monkeypatch):
    """Tessellated for its size on screen (chords within 1/32 of a pixel), the lens draws each pixel's checker parity
    as the fine mesh does on all but 0.5% of the pixels; at the fixed 32 segments it did not."""
    fine = checker_parity(lens_stage(tmp_path / "mesh.usda", True), device)
    sized = checker_parity(lens_stage(tmp_path / "gprim.usda", False), device)
    assert np.mean(sized != fine) <= 0.005, f"{np.mean(sized != fine):.2%} of the pixels differ"
    monkeypatch.setattr(snell.usd._gprims, "segments_for", lambda radius_pixels: 32)
    coarse = checker_parity(lens_stage(tmp_path / "coarse.usda", False), device)
    assert np.mean(coarse != fine) > 0.005, "the test tells a coarse lens from a fine one"
