"""Subdivision surfaces from USD: subdivisionScheme and its tags read from the stage, the cage sent, snell refining."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
from pxr import UsdGeom, UsdShade, Vt

import snell.usd
from conftest import unexpected
from stages import bind, new_stage, preview_material, sphere_arrays

CUBE_POINTS = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
CUBE_FACES = [0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5]


def subdivided(stage, path: str, points, counts, indices, scheme=None) -> UsdGeom.Mesh:
    """A mesh whose subdivisionScheme is left unauthored (USD's fallback: catmullClark) unless given."""
    m = UsdGeom.Mesh.Define(stage, path)
    m.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(points, np.float32)))
    m.CreateFaceVertexCountsAttr(list(map(int, counts)))
    m.CreateFaceVertexIndicesAttr(list(map(int, indices)))
    if scheme is not None:
        m.CreateSubdivisionSchemeAttr(scheme)
    return m


def cube_stage(tmp_path, name: str = "cube.usda", **tags):
    path = tmp_path / name
    stage = new_stage(path)
    m = subdivided(stage, "/World/Cube", CUBE_POINTS, [4] * 6, CUBE_FACES)
    for attribute, value in tags.items():
        getattr(m, f"Create{attribute}Attr")(value)
    stage.GetRootLayer().Save()
    return path


def test_a_mesh_without_a_scheme_is_a_catmull_clark_surface_sent_as_its_cage(tmp_path):
    contents = snell.usd.read(cube_stage(tmp_path))
    assert unexpected(contents.problems.items) == []
    [m] = contents.snell_meshes()
    assert m.subdivision is not None and m.subdivision.scheme == "catmullClark" and m.subdivision.level == 2
    assert len(m.positions) == 8 and list(m.subdivision.face_vertex_counts) == [4] * 6
    scene, _ = snell.usd._stage.scene_of(contents)
    assert scene.vertex_count(0) == 8 and scene.drawn_vertex_count(0) == 98


def test_subdivision_level_zero_draws_the_cage_and_scheme_none_is_a_polygon_mesh(tmp_path):
    path = cube_stage(tmp_path)
    [cage] = snell.usd.read(path, subdivision_level=0).snell_meshes()
    assert cage.subdivision is None and len(np.asarray(cage.indices)) == 12
    [polygons] = snell.usd.read(cube_stage(tmp_path, "none.usda", SubdivisionScheme="none")).snell_meshes()
    assert polygons.subdivision is None


def test_creases_corners_holes_and_rules_are_read_from_the_stage(tmp_path):
    path = cube_stage(tmp_path, CreaseIndices=[0, 1, 3], CreaseLengths=[3], CreaseSharpnesses=[10.0],
                      CornerIndices=[7], CornerSharpnesses=[4.0], HoleIndices=[2], InterpolateBoundary="edgeOnly",
                      FaceVaryingLinearInterpolation="all", TriangleSubdivisionRule="smooth",
                      Orientation="leftHanded")
    [m] = snell.usd.read(path).snell_meshes()
    s = m.subdivision
    assert (s.crease_indices, s.crease_lengths, s.crease_sharpnesses) == ([0, 1, 3], [3], [10.0])
    assert (s.corner_indices, s.corner_sharpnesses) == ([7], [4.0])
    assert s.hole_indices == [2] and s.interpolate_boundary == "edgeOnly"
    assert s.face_varying_linear_interpolation == "all" and s.smooth_triangles and s.left_handed


def test_a_sharp_crease_changes_the_picture(tmp_path, device):
    def picture(path):
        with snell.usd.open(path, device=device) as stage:
            return stage.render(96, 96)

    smooth = picture(cube_stage(tmp_path))
    creased = picture(cube_stage(tmp_path, "creased.usda", CreaseIndices=[4, 5, 7, 6, 4], CreaseLengths=[5],
                                 CreaseSharpnesses=[10.0]))
    assert (np.abs(smooth - creased).max(axis=2) > 0.05).mean() > 0.01


def test_each_material_subset_refines_the_whole_cage_and_draws_its_own_faces(tmp_path):
    points, counts, indices, _ = sphere_arrays(rings=6, segments=8)
    top = list(range(16))  # the cap: the pole's triangles and the first ring of quads

    def read(name: str, with_subset: bool):
        path = tmp_path / name
        stage = new_stage(path)
        m = subdivided(stage, "/World/Cornea", points, counts, indices)
        if with_subset:
            subset = UsdGeom.Subset.CreateGeomSubset(m, "tip", UsdGeom.Tokens.face, Vt.IntArray(top),
                                                     UsdShade.Tokens.materialBind)
            bind(subset.GetPrim(), preview_material(stage, "/World/Glass", opacity=0.0, ior=1.376))
        stage.GetRootLayer().Save()
        contents = snell.usd.read(path)
        return contents.snell_meshes(), snell.usd._stage.scene_of(contents)[0]

    meshes, scene = read("subsets.usda", True)
    assert len(meshes) == 2 and all(len(x.positions) == len(points) for x in meshes)
    assert sorted(map(len, (x.subdivision.hole_indices for x in meshes))) == [len(top), len(counts) - len(top)]
    _, whole = read("whole.usda", False)
    assert scene.drawn_triangle_count(0) + scene.drawn_triangle_count(1) == whole.drawn_triangle_count(0)
    assert 0 < scene.drawn_triangle_count(1) < whole.drawn_triangle_count(0)


def test_animated_points_are_sent_as_the_cage_each_frame(tmp_path, device):
    path = tmp_path / "breathing.usda"
    stage = new_stage(path, time_range=(1, 2))
    m = subdivided(stage, "/World/Cube", CUBE_POINTS, [4] * 6, CUBE_FACES)
    for t, scale in ((1, 1.0), (2, 1.3)):
        m.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(np.asarray(CUBE_POINTS, np.float32) * scale), t)
    stage.GetRootLayer().Save()
    with snell.usd.open(path, device=device) as opened:
        opened.render(64, 64)
        opened.set_time(2)
        after = opened.render(64, 64)
        frame = opened.renderer.last_frame()
        assert frame["meshes_refined"] == 1 and frame["vertices_refined"] == 98
        assert after.shape == (64, 64, 4)


def test_a_loop_cage_of_quads_is_drawn_unrefined_with_a_warning_naming_the_prim(tmp_path):
    contents = snell.usd.read(cube_stage(tmp_path, SubdivisionScheme="loop"))
    scene, _ = snell.usd._stage.scene_of(contents)
    warnings = scene.warnings
    assert len(warnings) == 1 and "/World/Cube" in warnings[0] and "Loop" in warnings[0], warnings
    assert scene.drawn_vertex_count(0) == 8


def test_info_says_which_meshes_are_refined_and_by_how_many_levels(tmp_path):
    path = cube_stage(tmp_path)
    done = subprocess.run([sys.executable, "-m", "snell.usd", "info", str(path), "--json", "--subdiv-level", "3"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    [entry] = json.loads(done.stdout)["meshes"]
    assert entry["subdivision"] == {"scheme": "catmullClark", "level": 3}
    bad = subprocess.run([sys.executable, "-m", "snell.usd", "info", str(path), "--subdiv-level", "9"],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "a subdivision level is 0 to 8, not '9'" in bad.stderr
