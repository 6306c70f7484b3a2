"""UsdGeomMesh prims as snell meshes: faces, normals, winding, instancing, visibility and purpose."""

from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdSkel, Vt

import snell.usd
from stages import bind, mesh, new_stage, preview_material, quad, sphere_arrays, texture, write_rgba_png


def read(stage, path, **options):
    stage.GetRootLayer().Save()
    contents = snell.usd.read(path, **options)
    return contents, contents.snell_meshes()


def geometric_normals(m) -> np.ndarray:
    """Each triangle's unit normal by its winding (counter-clockwise is the front)."""
    p = np.asarray(m.positions, float)[np.asarray(m.indices)]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def world_normals(contents, meshes, instance: int = 0) -> np.ndarray:
    """Each triangle's front in the world, as snell takes it: its counter-clockwise normal in the mesh's own space,
    carried by the inverse transpose (so a mirroring transform keeps a face's front where its normals point)."""
    matrix = np.asarray(contents.snell_instances()[instance].transform)[:3, :3]
    m = meshes[contents.snell_instances()[instance].mesh]
    p = np.asarray(m.positions, float)[np.asarray(m.indices)]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) @ np.linalg.inv(matrix)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_n_gons_are_fanned_into_triangles(tmp_path):
    stage = new_stage(tmp_path / "n.usda")
    angles = np.linspace(0, 2 * np.pi, 6)[:-1]
    pentagon = np.stack([np.cos(angles), np.sin(angles), np.zeros(5)], axis=1)
    mesh(stage, "/World/Pentagon", np.concatenate([pentagon, [(3, 0, 0), (4, 0, 0), (3, 1, 0)]]), [5, 3],
         [0, 1, 2, 3, 4, 5, 6, 7])
    _, meshes = read(stage, tmp_path / "n.usda")
    np.testing.assert_array_equal(meshes[0].indices, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [5, 6, 7]])
    np.testing.assert_allclose(geometric_normals(meshes[0]), [[0, 0, 1]] * 4, atol=1e-6)


def test_face_varying_normals_split_points_where_they_differ(tmp_path):
    stage = new_stage(tmp_path / "c.usda")
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    face_normals = [(0, 0, -1), (0, 0, 1), (0, -1, 0), (0, 1, 0), (-1, 0, 0), (1, 0, 0)]
    cube = mesh(stage, "/World/Cube", corners, [4] * 6, sum(faces, []))
    normals = UsdGeom.PrimvarsAPI(cube).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray, "faceVarying")
    normals.Set([n for n in face_normals for _ in range(4)])
    contents, meshes = read(stage, tmp_path / "c.usda")
    cube_mesh = meshes[0]
    assert len(cube_mesh.positions) == 24 and contents.sources[0].normals.interpolation == "faceVarying"
    # Every triangle's vertices carry its face's normal, which its winding agrees with.
    vertex_normals = np.asarray(cube_mesh.normals)[np.asarray(cube_mesh.indices)]
    np.testing.assert_allclose(vertex_normals, np.repeat(geometric_normals(cube_mesh)[:, None], 3, axis=1),
                               atol=1e-6)


def test_indexed_face_varying_normals_share_vertices_by_index(tmp_path):
    stage = new_stage(tmp_path / "q.usda")
    strip = mesh(stage, "/World/Strip", [(x, y, 0) for y in (0, 1) for x in range(3)], [4, 4], [0, 1, 4, 3, 1, 2, 5, 4])
    normals = UsdGeom.PrimvarsAPI(strip).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray, "faceVarying")
    normals.Set([(0, 0, 1)])
    normals.SetIndices(Vt.IntArray([0] * 8))
    _, meshes = read(stage, tmp_path / "q.usda")
    assert len(meshes[0].positions) == 6  # one normal value for all: no point is split


def test_uniform_normals_and_face_varying_st_split_points_per_face(tmp_path):
    stage = new_stage(tmp_path / "u.usda")
    fold = mesh(stage, "/World/Fold", [(x, y, 0) for y in (0, 1) for x in range(3)], [4, 4],
                [0, 1, 4, 3, 1, 2, 5, 4], normals=[(0, 0, 1), (0, 0.6, 0.8)], normals_interpolation="uniform",
                st=[(0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (0.5, 0), (0.5, 0.5), (0, 0.5)],
                st_interpolation="faceVarying")
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))
    material = preview_material(stage, "/World/T")
    texture(stage, material, "./t.png")  # the st primvar is read for a textured material
    bind(fold.GetPrim(), material)
    _, meshes = read(stage, tmp_path / "u.usda")
    assert len(meshes[0].positions) == 8  # the shared edge's two points, once per face
    by_triangle = np.asarray(meshes[0].normals)[np.asarray(meshes[0].indices)]
    np.testing.assert_allclose(by_triangle[:2], [[[0, 0, 1]] * 3] * 2)
    np.testing.assert_allclose(by_triangle[2:], [[[0, 0.6, 0.8]] * 3] * 2, rtol=1e-6)
    uv_by_triangle = np.asarray(meshes[0].uvs)[np.asarray(meshes[0].indices)]
    np.testing.assert_allclose(uv_by_triangle[0], [(0, 1), (1, 1), (1, 0)])  # face 0's corners 0, 1, 2, v flipped
    np.testing.assert_allclose(uv_by_triangle[2], [(0, 1), (0.5, 1), (0.5, 0.5)])  # face 1's own st


def test_primvars_normals_win_over_the_normals_attribute(tmp_path):
    stage = new_stage(tmp_path / "p.usda")
    q = quad(stage, "/World/Quad")  # normals attribute: +Z
    UsdGeom.PrimvarsAPI(q).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray, "constant").Set([(0, 1, 0)])
    _, meshes = read(stage, tmp_path / "p.usda")
    np.testing.assert_allclose(meshes[0].normals, [(0, 1, 0)] * 4)


def test_unauthored_normals_are_computed_smooth(tmp_path):
    stage = new_stage(tmp_path / "s.usda")
    points, counts, indices, analytic = sphere_arrays(rings=24, segments=32)
    mesh(stage, "/World/Ball", points, counts, indices)
    contents, meshes = read(stage, tmp_path / "s.usda")
    assert contents.sources[0].normals is None
    normals = np.asarray(meshes[0].normals)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    assert np.einsum("ij,ij->i", normals, analytic[contents.sources[0].parts[0].vertex_point]).min() > 0.99


def test_a_left_handed_mesh_is_wound_to_face_the_same_way(tmp_path):
    stage = new_stage(tmp_path / "l.usda")
    right = quad(stage, "/World/Right")
    left = mesh(stage, "/World/Left", right.GetPointsAttr().Get(), [4], [0, 3, 2, 1], normals=[(0, 0, 1)] * 4)
    left.CreateOrientationAttr(UsdGeom.Tokens.leftHanded)
    _, meshes = read(stage, tmp_path / "l.usda")
    np.testing.assert_allclose(geometric_normals(meshes[0]), [[0, 0, 1]] * 2, atol=1e-6)
    np.testing.assert_allclose(geometric_normals(meshes[1]), [[0, 0, 1]] * 2, atol=1e-6)


def test_a_mirroring_transform_keeps_each_faces_front_where_its_normals_point(tmp_path):
    stage = new_stage(tmp_path / "m.usda")
    quad(stage, "/World/Plain")
    mirror = UsdGeom.Xform.Define(stage, "/World/Mirror")
    mirror.AddScaleOp().Set(Gf.Vec3f(1, 1, -1))
    quad(stage, "/World/Mirror/Quad", z=1.0)
    contents, meshes = read(stage, tmp_path / "m.usda")
    # In the world, the plain quad faces +Z; the mirrored one faces -Z, as its mirrored normals do (Hydra's rule),
    # its winding left as authored.
    np.testing.assert_allclose(world_normals(contents, meshes, 0), [[0, 0, 1]] * 2, atol=1e-6)
    np.testing.assert_allclose(world_normals(contents, meshes, 1), [[0, 0, -1]] * 2, atol=1e-6)


def test_instance_proxies_share_one_snell_mesh(tmp_path):
    stage = new_stage(tmp_path / "i.usda")
    quad(stage, "/Prototype/Quad")
    stage.GetPrimAtPath("/Prototype").SetSpecifier(Sdf.SpecifierClass)
    for k, x in enumerate((-2.0, 2.0)):
        instance = UsdGeom.Xform.Define(stage, f"/World/Copy{k}")
        instance.AddTranslateOp().Set(Gf.Vec3d(x, 0, 0))
        instance.GetPrim().GetInherits().AddInherit("/Prototype")
        instance.GetPrim().SetInstanceable(True)
    contents, meshes = read(stage, tmp_path / "i.usda")
    instances = contents.snell_instances()
    assert len(meshes) == 1 and len(instances) == 2
    assert [np.asarray(i.transform)[0, 3] for i in instances] == [-2.0, 2.0]


def test_guide_and_invisible_prims_are_not_drawn(tmp_path):
    stage = new_stage(tmp_path / "g.usda")
    quad(stage, "/World/Shown")
    UsdGeom.Imageable(quad(stage, "/World/Guide")).CreatePurposeAttr(UsdGeom.Tokens.guide)
    hidden = UsdGeom.Xform.Define(stage, "/World/Hidden")
    hidden.CreateVisibilityAttr(UsdGeom.Tokens.invisible)
    quad(stage, "/World/Hidden/Quad")
    contents, meshes = read(stage, tmp_path / "g.usda")
    assert [m.name for m in meshes] == ["/World/Shown"]
    assert contents.skipped == {"purpose guide": ["/World/Guide"], "invisible": ["/World/Hidden"]}


def test_the_geometry_purpose_picks_render_or_proxy_prims(tmp_path):
    stage = new_stage(tmp_path / "r.usda")
    UsdGeom.Imageable(quad(stage, "/World/Render")).CreatePurposeAttr(UsdGeom.Tokens.render)
    UsdGeom.Imageable(quad(stage, "/World/Proxy")).CreatePurposeAttr(UsdGeom.Tokens.proxy)
    quad(stage, "/World/Always")
    stage.GetRootLayer().Save()
    names = {purpose: [m.name for m in snell.usd.read(tmp_path / "r.usda", geometry_purpose=purpose).snell_meshes()]
             for purpose in ("render", "proxy")}
    assert names == {"render": ["/World/Render", "/World/Always"], "proxy": ["/World/Proxy", "/World/Always"]}


def test_a_mesh_with_faces_but_no_points_is_an_error(tmp_path):
    stage = new_stage(tmp_path / "e.usda")
    quad(stage, "/World/Fine")
    empty = UsdGeom.Mesh.Define(stage, "/World/Empty")
    empty.CreateFaceVertexCountsAttr([3])
    empty.CreateFaceVertexIndicesAttr([0, 1, 2])
    contents, meshes = read(stage, tmp_path / "e.usda")
    assert [m.name for m in meshes] == ["/World/Fine"]
    assert [str(w) for w in contents.problems.errors] == ["error: /World/Empty: has 1 faces but no points"]
    with pytest.raises(snell.usd.StageError, match="/World/Empty: has 1 faces but no points"):
        snell.usd.read(tmp_path / "e.usda", strict=True)


def test_face_indices_past_the_points_are_an_error(tmp_path):
    stage = new_stage(tmp_path / "b.usda")
    mesh(stage, "/World/Bad", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [3], [0, 1, 7])
    contents, meshes = read(stage, tmp_path / "b.usda")
    assert meshes == [] and "refers to point 7; the mesh has 3 points" in str(contents.problems.errors[0])


def hair_alone(folder) -> object:
    stage = new_stage(folder / "n.usda")
    UsdGeom.BasisCurves.Define(stage, "/World/Hair")
    stage.GetRootLayer().Save()
    return folder / "n.usda"


def test_a_stage_with_nothing_to_draw_opens_with_a_warning_and_draws_its_background(tmp_path, device):
    with snell.usd.open(hair_alone(tmp_path), device=device) as opened:
        assert any("nothing to draw: no visible UsdGeomMesh or gprim" in str(w) for w in opened.warnings)
        pixels = opened.render(8, 6, background=(0.25, 0.5, 0.75))
    np.testing.assert_allclose(pixels[..., :3], np.broadcast_to([0.25, 0.5, 0.75], (6, 8, 3)), atol=1e-6)


def test_a_strict_open_refuses_a_stage_with_nothing_to_draw(tmp_path, device):
    with pytest.raises(snell.usd.StageError, match="nothing to draw: no visible UsdGeomMesh or gprim"):
        snell.usd.open(hair_alone(tmp_path), device=device, strict=True)


def test_rigid_skinning_moves_the_instance_as_vertex_skinning_moves_the_points(tmp_path):
    """A mesh bound to one joint with constant influences (UsdSkel's rigid case) is placed where the same
    mesh with per-vertex influences is skinned to."""
    stage = new_stage(tmp_path / "k.usda", time_range=(0, 10))
    UsdSkel.Root.Define(stage, "/World/Rig")
    skeleton = UsdSkel.Skeleton.Define(stage, "/World/Rig/Skel")
    skeleton.CreateJointsAttr(["Arm"])
    skeleton.CreateBindTransformsAttr([Gf.Matrix4d(1.0)])
    skeleton.CreateRestTransformsAttr([Gf.Matrix4d(1.0)])
    animation = UsdSkel.Animation.Define(stage, "/World/Rig/Skel/Swing")
    animation.CreateJointsAttr(["Arm"])
    animation.CreateTranslationsAttr([Gf.Vec3f(0, 0, 0)])
    animation.CreateScalesAttr([Gf.Vec3h(1, 1, 1)])
    rotations = animation.CreateRotationsAttr()
    rotations.Set([Gf.Quatf(1, 0, 0, 0)], 0)
    rotations.Set([Gf.Quatf(0.7071068, 0, 0, 0.7071068)], 10)
    UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets([animation.GetPath()])
    for name, constant in (("Rigid", True), ("Skinned", False)):
        q = quad(stage, f"/World/Rig/{name}", z=0.5)
        binding = UsdSkel.BindingAPI.Apply(q.GetPrim())
        binding.CreateSkeletonRel().SetTargets([skeleton.GetPath()])
        count = 1 if constant else 4
        binding.CreateJointIndicesPrimvar(constant, 1).Set([0] * count)
        binding.CreateJointWeightsPrimvar(constant, 1).Set([1.0] * count)
    stage.GetRootLayer().Save()
    contents = snell.usd.read(tmp_path / "k.usda")
    meshes = contents.snell_meshes()
    placements = {p.source.path: p for p in contents.placements}
    assert placements["/World/Rig/Rigid"].varying and not placements["/World/Rig/Rigid"].source.deforms
    assert placements["/World/Rig/Skinned"].source.deforms
    frame = contents.evaluate(5.0)
    rigid = dict((p.source.path, m) for p, m in frame.transforms)["/World/Rig/Rigid"]
    skinned = dict((s.path, pose) for s, pose in frame.poses)["/World/Rig/Skinned"].points
    rigid_points = np.asarray(meshes[0].positions, float) @ rigid[:3, :3].T + rigid[:3, 3]
    np.testing.assert_allclose(rigid_points, skinned, atol=1e-6)
    assert not np.allclose(skinned, meshes[0].positions, atol=1e-3)


def test_a_single_sided_mesh_seen_from_behind_is_not_drawn_as_usdview_culls_it(tmp_path, device):
    def picture(double_sided: bool):
        path = tmp_path / f"sided_{double_sided}.usda"
        stage = new_stage(path)
        m = quad(stage, "/World/Card", size=2.0)
        m.CreateDoubleSidedAttr(double_sided)
        bind(m.GetPrim(), preview_material(stage, "/World/Red", diffuseColor=(0.0, 0.0, 0.0),
                                           emissiveColor=(1.0, 0.0, 0.0)))
        camera = UsdGeom.Camera.Define(stage, "/World/Behind")  # on -Z, looking at the card's back
        camera.AddTranslateOp().Set(Gf.Vec3d(0, 0, -4))
        camera.AddRotateYOp().Set(180.0)
        stage.GetRootLayer().Save()
        with snell.usd.open(path, device=device) as opened:
            return opened.render(32, 32, camera="/World/Behind")[16, 16, :3]

    assert picture(True)[0] > 0.5, "a double-sided card is seen from behind"
    assert picture(False)[0] < 0.1, "a single-sided one (USD's doubleSided fallback, 0) is not"
