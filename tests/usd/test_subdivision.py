"""Subdivision surfaces from USD: subdivisionScheme and its tags read from the stage, the cage sent, snell refining."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
from pxr import Gf, UsdGeom, UsdShade, Vt

import snell.usd
from conftest import read_image, snell_usd_ok, unexpected
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
    contents = snell.usd.read(cube_stage(tmp_path), subdivision_level=2)
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


def test_a_cage_with_a_material_subset_is_one_mesh_refined_once_with_a_material_per_face(tmp_path, device):
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
        return path, contents.snell_meshes(), snell.usd._stage.scene_of(contents)[0]

    path, meshes, scene = read("subsets.usda", True)
    [mesh] = meshes
    assert len(mesh.positions) == len(points) and len(mesh.subdivision.hole_indices) == 0
    faces = np.asarray(mesh.face_materials)
    assert len(faces) == len(counts) and len(set(faces[top])) == 1 and faces[top][0] != faces[len(top)]
    assert set(faces[len(top):]) == {mesh.material}, "the faces outside the subset keep the mesh's material"
    _, _, whole = read("whole.usda", False)
    assert scene.drawn_triangle_count(0) == whole.drawn_triangle_count(0)
    assert scene.drawn_vertex_count(0) == whole.drawn_vertex_count(0)
    with snell.usd.open(path, device=device) as opened:
        opened.render(32, 32)
        frame = opened.renderer.last_frame()
        assert frame["meshes_refined"] == 0
        opened.renderer.mark_dirty(0)
        opened.render(32, 32)
        assert opened.renderer.last_frame()["meshes_refined"] == 1, "one refine job for both materials"


def test_animated_points_are_sent_as_the_cage_each_frame(tmp_path, device):
    path = tmp_path / "breathing.usda"
    stage = new_stage(path, time_range=(1, 2))
    m = subdivided(stage, "/World/Cube", CUBE_POINTS, [4] * 6, CUBE_FACES)
    for t, scale in ((1, 1.0), (2, 1.3)):
        m.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(np.asarray(CUBE_POINTS, np.float32) * scale), t)
    stage.GetRootLayer().Save()
    with snell.usd.open(path, device=device, subdivision_level=2) as opened:
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
    assert entry["subdivision"] == {"scheme": "catmullClark", "level": 3, "vertices": 386, "triangles": 768,
                                    "bytes": 32 * 386 + 52 * 768}
    assert entry["parts"][0]["vertices"] == 386 and entry["parts"][0]["triangles"] == 768
    bad = subprocess.run([sys.executable, "-m", "snell.usd", "info", str(path), "--subdiv-level", "9"],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "a subdivision level is 0 to 8, not '9'" in bad.stderr


def test_each_cages_level_follows_its_size_on_screen_and_info_counts_what_is_drawn(tmp_path):
    """Unit cubes 6 m and 4 km from a 50 mm camera at 1920 x 1080: the near one's 2 m edges span some 1400 pixels
    (3 levels, the most), the far one's about 2 (1 level, the fewest); info's refined counts are the scene's."""
    path = tmp_path / "near_far.usda"
    stage = new_stage(path)
    for name, z in (("Near", 0.0), ("Far", -4000.0)):
        subdivided(stage, f"/World/{name}", CUBE_POINTS, [4] * 6, CUBE_FACES).AddTranslateOp().Set(Gf.Vec3d(0, 0, z))
    UsdGeom.Camera.Define(stage, "/World/Camera").AddTranslateOp().Set(Gf.Vec3d(0, 0, 6))
    stage.GetRootLayer().Save()
    contents = snell.usd.read(path)
    levels = {s.path: s.cage.level for s in contents.sources}
    assert levels == {"/World/Near": 3, "/World/Far": 1}, levels
    scene, meshes = snell.usd._stage.scene_of(contents)
    done = subprocess.run([sys.executable, "-m", "snell.usd", "info", str(path), "--json"], capture_output=True,
                          text=True, timeout=120)
    listed = {m["prim"]: m["parts"][0] for m in json.loads(done.stdout)["meshes"]}
    for i, source in enumerate(contents.sources):
        part = listed[source.path]
        assert (part["vertices"], part["triangles"]) == (scene.drawn_vertex_count(i), scene.drawn_triangle_count(i))
    assert snell.usd.read(path, subdivision_level=2).sources[1].cage.level == 2, "a level given fixes every cage"


def test_the_triangle_budget_refines_the_largest_meshes_fewer_levels_with_one_warning_naming_them(tmp_path):
    path = tmp_path / "crowd.usda"
    stage = new_stage(path)
    for i in range(3):
        subdivided(stage, f"/World/Cube{i}", CUBE_POINTS, [4] * 6, CUBE_FACES).AddTranslateOp().Set(
            Gf.Vec3d(3.0 * i, 0, 0))
    UsdGeom.Camera.Define(stage, "/World/Camera").AddTranslateOp().Set(Gf.Vec3d(3, 0, 8))
    stage.GetRootLayer().Save()
    assert {s.cage.level for s in snell.usd.read(path).sources} == {3}
    contents = snell.usd.read(path, triangle_budget=3 * 192)  # each cube 12 x 4^3 = 768 at 3 levels, 192 at 2
    assert [s.cage.level for s in contents.sources] == [2, 2, 2]
    said = [str(w) for w in contents.problems.items if "refined fewer levels" in str(w)]
    assert len(said) == 1 and "/World/Cube0 (2), /World/Cube1 (2), /World/Cube2 (2)" in said[0], said


def test_a_million_cage_triangles_over_twenty_meshes_render_at_1080p_on_a_2_gib_device(tmp_path, monkeypatch):
    """20 wavy sheets of 24,649 quads each (985,960 cage triangles), seen close: the view asks 3 levels of each
    (63M triangles); the budgets bring them to 1 or 0 (the cage as polygons) and it renders, with one warning."""
    n = 158
    y, x = np.mgrid[0:n, 0:n] / (n - 1)
    points = np.stack([x - 0.5, 0.05 * np.sin(12 * x) * np.cos(9 * y), y - 0.5], -1).reshape(-1, 3)
    i = np.arange(n * n).reshape(n, n)
    quads = np.stack([i[:-1, :-1], i[1:, :-1], i[1:, 1:], i[:-1, 1:]], -1).reshape(-1)
    path = tmp_path / "sheets.usdc"
    stage = new_stage(path)
    for k in range(20):
        sheet = subdivided(stage, f"/World/Sheet{k}", points, [4] * (n - 1) ** 2, quads)
        sheet.AddTranslateOp().Set(Gf.Vec3d((k % 5) - 2.0, 0.2 * (k // 5), -0.3 * (k // 5)))
    camera = UsdGeom.Camera.Define(stage, "/World/Camera")
    camera.AddTranslateOp().Set(Gf.Vec3d(0, 2.5, 3.0))
    camera.AddRotateXOp().Set(-40.0)
    stage.GetRootLayer().Save()
    monkeypatch.setenv("SNELL_DEVICE_MEMORY_LIMIT", str(2 << 30))
    done = snell_usd_ok("render", path, "-o", tmp_path / "sheets.png", "--size", "1920x1080", timeout=600)
    said = [line for line in done.stderr.splitlines() if "refined fewer levels" in line]
    assert len(said) == 1 and "/World/Sheet19 (" in said[0], done.stderr
    picture = read_image(tmp_path / "sheets.png")
    assert picture[540, 960, :3].max() > 0.1, "the sheets fill the middle of the picture"
