"""UsdGeomPointInstancer: its prototypes' meshes become snell instances, placed as USD computes them."""

from __future__ import annotations

import numpy as np
from pxr import Gf, UsdGeom, Vt

import snell.usd
from stages import new_stage, quad


def instancer_stage(path, animated: bool = False):
    stage = new_stage(path, time_range=(1, 2))
    instancer = UsdGeom.PointInstancer.Define(stage, "/World/Set")
    cube = UsdGeom.Cube.Define(stage, "/World/Set/Prototypes/Pawn")
    cube.CreateSizeAttr(1.0)
    quad(stage, "/World/Set/Prototypes/Board/Card", size=1.0)
    instancer.CreatePrototypesRel().SetTargets([cube.GetPath(), "/World/Set/Prototypes/Board"])
    instancer.CreateProtoIndicesAttr([0, 1, 0, 0])
    positions = instancer.CreatePositionsAttr()
    if animated:
        positions.Set(Vt.Vec3fArray([(0, 0, 0), (3, 0, 0), (6, 0, 0), (9, 0, 0)]), 1.0)
        positions.Set(Vt.Vec3fArray([(0, 5, 0), (3, 5, 0), (6, 5, 0), (9, 5, 0)]), 2.0)
    else:
        positions.Set(Vt.Vec3fArray([(0, 0, 0), (3, 0, 0), (6, 0, 0), (9, 0, 0)]))
    instancer.CreateScalesAttr(Vt.Vec3fArray([(2, 2, 2), (1, 1, 1), (1, 1, 1), (1, 1, 1)]))
    quarter = Gf.Quath(Gf.Rotation(Gf.Vec3d(0, 0, 1), 90).GetQuat())
    instancer.CreateOrientationsAttr(Vt.QuathArray([Gf.Quath(1), quarter, Gf.Quath(1), Gf.Quath(1)]))
    instancer.CreateInvisibleIdsAttr([2])
    instancer.DeactivateId(3)
    stage.GetRootLayer().Save()
    return stage


def world_bounds(contents, meshes, placement):
    m = meshes[placement.source.parts[0].mesh]
    p = np.asarray(m.positions, np.float64) @ placement.matrix[:3, :3].T + placement.matrix[:3, 3]
    return p.min(axis=0), p.max(axis=0)


def test_each_visible_active_instance_places_its_prototypes_meshes(tmp_path):
    instancer_stage(tmp_path / "set.usda")
    contents = snell.usd.read(tmp_path / "set.usda")
    meshes = contents.snell_meshes()
    placed = [(p.prim.GetPath().pathString, world_bounds(contents, meshes, p)) for p in contents.placements]
    # Instance 2 is invisible and 3 inactive: a pawn scaled 2 at the origin, the board turned 90 degrees at x 3.
    assert [path for path, _ in placed] == ["/World/Set/Prototypes/Pawn", "/World/Set/Prototypes/Board/Card"]
    np.testing.assert_allclose(placed[0][1], [(-1, -1, -1), (1, 1, 1)], atol=1e-6)
    # Orientations are half-precision quaternions: a quarter turn is good to 3e-4.
    np.testing.assert_allclose(placed[1][1], [(2.5, -0.5, 0), (3.5, 0.5, 0)], atol=1e-3)
    turned = contents.placements[1].matrix[:3, :3]
    np.testing.assert_allclose(turned @ (1, 0, 0), (0, 1, 0), atol=1e-3)
    assert len(contents.sources) == 2  # one snell mesh per prototype mesh, shared by its instances


def test_animated_positions_move_the_instances_per_time_code(tmp_path):
    instancer_stage(tmp_path / "set.usda", animated=True)
    contents = snell.usd.read(tmp_path / "set.usda", time=1.0)
    contents.snell_meshes()
    moved = contents.evaluate(2.0).transforms
    assert len(moved) == 2
    np.testing.assert_allclose([m[:3, 3] for _, m in moved], [(0, 5, 0), (3, 5, 0)], atol=1e-6)


def test_an_instancer_renders_its_instances(tmp_path, device):
    instancer_stage(tmp_path / "set.usda")
    with snell.usd.open(tmp_path / "set.usda", device=device) as stage:
        rgba = stage.render(64, 32, method="trace")
        assert not any("PointInstancer" in str(w) for w in stage.warnings)
    assert (rgba[..., :3].max(axis=2) > 0.05).sum() > 100  # the pawn and the board drawn, not skipped
