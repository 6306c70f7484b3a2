"""UsdGeomCamera as snell's view and projection matrices."""

from __future__ import annotations

import numpy as np
import pytest

import snell
import snell.usd
from conftest import srgb8
from stages import camera, mesh, new_stage, quad, sphere_arrays

WIDTH, HEIGHT = 160, 120


def camera_stage(tmp_path, **camera_options):
    stage = new_stage(tmp_path / "c.usda")
    quad(stage, "/World/Card", size=1.0)
    points, counts, indices, normals = sphere_arrays(0.3, centre=(0.6, 0.4, 0.2))
    mesh(stage, "/World/Ball", points, counts, indices, normals=normals)
    camera(stage, "/World/Camera", **camera_options)
    stage.GetRootLayer().Save()
    return tmp_path / "c.usda"


def test_focal_length_and_aperture_give_the_projection(tmp_path):
    contents = snell.usd.read(camera_stage(tmp_path, focal_length=50.0, aperture=(36.0, 24.0)))
    view, projection = contents.camera(None, 0.0).matrices(300, 200)
    np.testing.assert_allclose(projection[0, 0], 2 * 50 / 36)
    np.testing.assert_allclose(projection[1, 1], 2 * 50 / 24)
    np.testing.assert_allclose(projection[3], [0, 0, -1, 0])
    np.testing.assert_allclose(view, np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -5], [0, 0, 0, 1]]), atol=1e-12)


@pytest.mark.parametrize("policy, aperture", [("expandAperture", (36.0, 36.0)), ("cropAperture", (24.0, 24.0)),
                                              ("adjustApertureWidth", (24.0, 24.0)),
                                              ("adjustApertureHeight", (36.0, 36.0))])
def test_the_aperture_is_conformed_to_the_images_aspect(tmp_path, policy, aperture):
    state = snell.usd.read(camera_stage(tmp_path, aperture=(36.0, 24.0))).camera(None, 0.0)
    assert state.aperture_for(100, 100, policy) == aperture
    _, projection = state.matrices(100, 100, policy)
    assert projection[0, 0] == pytest.approx(projection[1, 1])  # snell's pixels are square


def test_aperture_offsets_shift_the_picture_by_whole_pixels(tmp_path, device):
    """A horizontal offset of 20 pixels' worth of aperture slides the picture 20 pixels left."""
    pixel = 36.0 / WIDTH
    pictures = []
    for offset in (0.0, 20 * pixel):
        with snell.usd.open(camera_stage(tmp_path, aperture=(36.0, 27.0), offset=(offset, 0.0)),
                            device=device) as stage:
            pictures.append(stage.render(WIDTH, HEIGHT))
    centred, shifted = pictures
    np.testing.assert_allclose(shifted[:, :-20], centred[:, 20:], atol=2e-3)
    assert np.abs(shifted - centred).max() > 0.05


def test_a_usd_camera_renders_as_the_same_scene_camera(tmp_path, device):
    """focalLength 35 over a vertical aperture of 2 * 35 tan(0.3) is a glTF camera of yfov 0.6."""
    vertical = 2 * 35.0 * np.tan(0.3)
    with snell.usd.open(camera_stage(tmp_path, aperture=(vertical * WIDTH / HEIGHT, vertical)),
                        device=device) as stage:
        ours = srgb8(stage.render(WIDTH, HEIGHT))
        look = srgb8(stage.renderer.render(snell.View(WIDTH, HEIGHT, eye=(0, 0, 5), target=(0, 0, 0), yfov=0.6)))
    assert (np.abs(ours - look).max(axis=2) > 1).mean() <= 0.01


def test_a_camera_is_picked_by_path_and_an_unknown_one_is_refused(tmp_path):
    contents = snell.usd.read(camera_stage(tmp_path))
    assert contents.camera("/World/Camera", 0.0).path == "/World/Camera"
    with pytest.raises(snell.usd.StageError, match="/World/Card is not a camera of the stage"):
        contents.camera("/World/Card", 0.0)


def test_without_a_camera_the_view_frames_the_bounds(tmp_path, device):
    stage_file = new_stage(tmp_path / "n.usda")
    quad(stage_file, "/World/Card", size=1.0, z=3.0)
    stage_file.GetRootLayer().Save()
    with snell.usd.open(tmp_path / "n.usda", device=device) as stage:
        assert stage.cameras == []
        picture = srgb8(stage.render(WIDTH, HEIGHT))
    lit = picture.max(axis=2) > 30
    rows, columns = np.nonzero(lit)
    # The card is centred and fills the framed view's middle.
    assert abs(rows.mean() - HEIGHT / 2) < 2 and abs(columns.mean() - WIDTH / 2) < 2 and lit.mean() > 0.1
