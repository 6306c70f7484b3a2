"""Per frame, only what moves is re-read from USD and sent to snell."""

from __future__ import annotations

import numpy as np
from pxr import Gf, UsdGeom, Vt

import snell.usd
from stages import camera, mesh, new_stage, quad, sphere_arrays

WIDTH, HEIGHT = 160, 120


def moving_stage(tmp_path):
    """A static wall, a ball whose points are sampled over time, and a quad whose transform is."""
    stage = new_stage(tmp_path / "moving.usda", time_range=(1, 3))
    quad(stage, "/World/Wall", size=6.0, z=-2.0)
    points, counts, indices, normals = sphere_arrays(0.5)
    ball = mesh(stage, "/World/Ball", points, counts, indices, normals=normals)
    for t in (1, 2, 3):
        ball.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(points * np.float32([1, 1 - 0.2 * (t - 1), 1])), t)
    slider = UsdGeom.Xform.Define(stage, "/World/Slider")
    move = slider.AddTranslateOp()
    for t in (1, 2, 3):
        move.Set(Gf.Vec3d(-1.5 + 0.5 * t, 1.0, 0.0), t)
    quad(stage, "/World/Slider/Card", size=0.5)
    camera(stage, "/World/Camera", position=(0, 0, 6))
    stage.GetRootLayer().Save()
    return tmp_path / "moving.usda"


def test_a_static_prim_is_not_sent_again(tmp_path, device):
    with snell.usd.open(moving_stage(tmp_path), device=device) as stage:
        stage.render(WIDTH, HEIGHT)
        feed = stage.set_time(2)
        stage.render(WIDTH, HEIGHT)
        frame = stage.renderer.last_frame()
    assert (feed.meshes, feed.transforms) == (1, 1)  # the ball's vertices, the card's transform; not the wall
    assert frame["meshes_uploaded"] == 1 and frame["trees_refit"] + frame["trees_built"] == 1
    assert frame["top_level_refit"] + frame["top_level_built"] == 1


def test_a_stage_that_does_not_move_sends_nothing(tmp_path, device):
    stage_file = new_stage(tmp_path / "still.usda", time_range=(1, 3))
    quad(stage_file, "/World/Wall")
    stage_file.GetRootLayer().Save()
    with snell.usd.open(tmp_path / "still.usda", device=device) as stage:
        stage.render(WIDTH, HEIGHT)
        feed = stage.set_time(3)
        stage.render(WIDTH, HEIGHT)
        frame = stage.renderer.last_frame()
    assert (feed.meshes, feed.transforms) == (0, 0)
    assert frame["meshes_uploaded"] == 0 and frame["trees_refit"] + frame["trees_built"] == 0


def test_sent_vertices_and_transforms_are_the_stages_at_that_time(tmp_path, device):
    path = moving_stage(tmp_path)
    with snell.usd.open(path, device=device) as stage:
        stage.set_time(3)
        ball = stage.contents.sources[1].parts[0].mesh
        moved = stage.renderer.positions(ball).copy()
        card = stage.contents.placements[2].matrix
    at_three = snell.usd.read(path, time=3)
    np.testing.assert_array_equal(moved, at_three.snell_meshes()[ball].positions)
    np.testing.assert_allclose(card, at_three.placements[2].matrix)
    assert card[0, 3] == 0.0


def test_a_time_code_outside_the_range_is_a_warning(tmp_path, device):
    with snell.usd.open(moving_stage(tmp_path), device=device) as stage:
        assert not stage.warnings
        stage.set_time(7)
        stage.set_time(8)  # said once, not every frame
        assert [str(w) for w in stage.warnings] == [
            "time code 7 is outside the stage's range 1-3: USD holds the nearest samples"]
