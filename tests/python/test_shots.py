"""snell.render_frames: a shot's frames on several devices, handed back on the caller's thread."""

from __future__ import annotations

import threading

import numpy as np
import OpenImageIO as oiio
import pytest

import snell
from conftest import VALIDATION, lens_arrays, run_snell

FPS = 4
FRAMES = range(4)  # 0 to 0.75 s: the lens squashes as its morph weight rises


def shot(scene: snell.Scene, view: snell.View, frames, devices: str) -> tuple[dict[int, np.ndarray], dict]:
    """Each frame's picture by number, and the summary."""
    pictures: dict[int, np.ndarray] = {}

    def keep(picture: dict) -> None:
        assert threading.current_thread() is threading.main_thread(), "pictures come back on the caller's thread"
        pictures[picture["number"]] = picture["rgba"]

    summary = snell.render_frames(scene, view, frames, keep, devices=devices, validation=VALIDATION)
    return pictures, summary


def test_two_workers_write_the_pixels_of_snell_render_devices(lens_gltf, snell_binary, tmp_path):
    view = snell.View(64, 48, camera=0, method="trace")
    frames = [snell.ShotFrame(f, f / FPS) for f in FRAMES]
    pictures, summary = shot(snell.Scene.load(str(lens_gltf)), view, frames, devices="0,0")
    assert summary["frames"] == len(FRAMES)
    assert [w["frames"] for w in summary["workers"]] != [len(FRAMES), 0], "both workers drew"
    assert sum(w["frames"] for w in summary["workers"]) == len(FRAMES)

    run_snell(snell_binary, "render", lens_gltf, "--size", "64x48", "--frames", "0-3", "--fps", str(FPS),
              "--devices", "0,0", "--method", "trace", "-o", tmp_path / "f_#.exr")
    for f in FRAMES:
        written = oiio.ImageBuf(str(tmp_path / f"f_{f}.exr")).get_pixels(oiio.FLOAT)
        # The command's EXR alpha is coverage; the colour is the same halves.
        np.testing.assert_array_equal(pictures[f][..., :3], written[..., :3], err_msg=f"frame {f}")


def test_the_frames_pictures_do_not_depend_on_the_device_count(lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    view = snell.View(48, 32, camera=0, viewport=True)
    one, _ = shot(scene, view, [f / FPS for f in FRAMES], devices="0")
    two, _ = shot(scene, view, [f / FPS for f in FRAMES], devices="0,0")
    assert sorted(one) == list(FRAMES), "plain times are numbered from 0"
    for f in FRAMES:
        np.testing.assert_array_equal(one[f], two[f], err_msg=f"frame {f}")
    assert not np.array_equal(one[0], one[3]), "the lens squashes over the shot"


def test_a_frames_vertices_and_camera_are_the_hosts_animation(device):
    """A DCC hands over each frame's vertices and camera: the shot draws what a Renderer would."""
    scene = lens_arrays()
    view = snell.View(48, 32, camera=0, method="trace")
    with snell.Renderer(device, scene) as renderer:
        rest, normals = renderer.positions(1).copy(), renderer.normals(1).copy()
    squashed = rest * np.array([1.3, 0.7, 1.3], np.float32)
    camera = np.array([[1, 0, 0, 0.2], [0, 1, 0, 0], [0, 0, 1, -3.0], [0, 0, 0, 1]], np.float32)
    projection = np.array([[1.5, 0, 0, 0], [0, 2.25, 0, 0], [0, 0, -1, -0.2], [0, 0, -1, 0]], np.float32)
    frame = snell.ShotFrame(7, view_matrix=camera, projection=projection, vertices={1: (squashed, normals)})
    pictures, _ = shot(scene, view, [frame], devices="0")

    with snell.Renderer(device, scene) as renderer:
        renderer.set_vertices(1, squashed, normals)
        view.set_matrices(camera, projection)
        want = renderer.render(view)
    np.testing.assert_array_equal(pictures[7], want)


def test_an_exception_in_the_frames_stops_the_shot_and_is_raised_as_itself(lens_gltf):
    def frames():
        yield 0.0
        raise KeyError("the host's own mistake")

    with pytest.raises(KeyError, match="the host's own mistake"):
        shot(snell.Scene.load(str(lens_gltf)), snell.View(32, 24, camera=0), frames(), devices="0")


def test_a_frame_that_is_not_a_time_is_an_error_naming_it(lens_gltf):
    with pytest.raises(snell.Error, match=r"frame 1 must be a snell.ShotFrame or a time in seconds"):
        shot(snell.Scene.load(str(lens_gltf)), snell.View(32, 24, camera=0), [0.0, "later"], devices="0")
