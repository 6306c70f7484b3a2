"""Renderer.render: the same pixels as `snell render`, from every kind of camera."""

from __future__ import annotations

import numpy as np
import pytest

import snell
from conftest import CAMERA_Z, YFOV, lens_arrays, run_snell
from support import read_png, srgb8

WIDTH, HEIGHT = 160, 120


def test_render_equals_snell_render_of_the_same_gltf(device, snell_binary, lens_gltf, tmp_path):
    run_snell(snell_binary, "render", lens_gltf, "-o", tmp_path / "cli.png", "--size", f"{WIDTH}x{HEIGHT}",
              "--time", "0.5")
    scene = snell.Scene.load(str(lens_gltf))
    with snell.Renderer(device, scene) as renderer:
        renderer.set_time(0.5)
        rgba = renderer.render(snell.View(WIDTH, HEIGHT, camera=0))
    assert rgba.shape == (HEIGHT, WIDTH, 4) and rgba.dtype == np.float32
    cli = read_png(tmp_path / "cli.png")[..., :3].astype(int)
    ours = srgb8(rgba).astype(int)
    assert np.abs(cli - ours).max() <= 1, "the module's pixels differ from snell render's by more than 1/255"


def test_render_into_fills_the_callers_array(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    view = snell.View(WIDTH, HEIGHT, camera=0)
    out = np.full((HEIGHT, WIDTH, 4), -1.0, np.float32)
    renderer.render_into(view, out)
    np.testing.assert_array_equal(out, renderer.render(view))


def test_compact_trees_draw_the_same_picture(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    view = snell.View(WIDTH, HEIGHT, camera=0)
    exact = snell.Renderer(device, scene).render(view)
    compact = snell.Renderer(device, scene, compact_trees=True).render(view)
    np.testing.assert_array_equal(compact, exact)


def test_view_matrices_give_the_scene_cameras_picture(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    by_camera = renderer.render(snell.View(WIDTH, HEIGHT, camera=0))
    f = 1.0 / np.tan(YFOV / 2)
    aspect = WIDTH / HEIGHT
    projection = np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0], [0, 0, -1, -0.02], [0, 0, -1, 0]])
    view_matrix = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -CAMERA_Z], [0, 0, 0, 1]])
    by_matrices = renderer.render(snell.View(WIDTH, HEIGHT, view_matrix=view_matrix, projection=projection))
    assert np.abs(srgb8(by_camera).astype(int) - srgb8(by_matrices).astype(int)).max() <= 1


def test_lens_shift_moves_the_picture_by_whole_pixels(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    f = 1.0 / np.tan(YFOV / 2)
    aspect = WIDTH / HEIGHT
    view_matrix = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -CAMERA_Z], [0, 0, 0, 1]])

    def render(shift_x: float) -> np.ndarray:
        # An off-centre frustum: the window slides by shift_x of its half width.
        projection = np.array([[f / aspect, 0, shift_x, 0], [0, f, 0, 0], [0, 0, -1, -0.02], [0, 0, -1, 0]])
        return renderer.render(snell.View(WIDTH, HEIGHT, view_matrix=view_matrix, projection=projection))

    centred, shifted = render(0.0), render(20 * 2 / WIDTH)  # 20 pixels
    np.testing.assert_allclose(shifted[:, :-20], centred[:, 20:], atol=2e-3)


def test_orthographic_matrices_render_parallel_rays(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    half_height = 0.8
    projection = np.array([[HEIGHT / WIDTH / half_height, 0, 0, 0], [0, 1 / half_height, 0, 0],
                           [0, 0, -0.1, -1], [0, 0, 0, 1]])
    view_matrix = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -CAMERA_Z], [0, 0, 0, 1]])
    rgba = renderer.render(snell.View(WIDTH, HEIGHT, view_matrix=view_matrix, projection=projection))
    # The sphere (radius 0.5) fills 0.5 / 0.8 of the half height, whatever the distance.
    column = rgba[:, WIDTH // 2, :3]
    row_top = int(HEIGHT / 2 * (1 - 0.5 / half_height))
    assert not np.allclose(column[row_top + 3], column[row_top - 3], atol=1e-3)


def test_a_projection_whose_aspect_is_not_the_views_is_refused(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    projection = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, -1, -0.02], [0, 0, -1, 0]])
    with pytest.raises(snell.Error, match="aspect"):
        renderer.render(snell.View(WIDTH, HEIGHT, view_matrix=np.eye(4), projection=projection))


def test_viewport_composite_traces_only_the_glass(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    traced = renderer.render(snell.View(WIDTH, HEIGHT, camera=0))
    composite = renderer.render(snell.View(WIDTH, HEIGHT, camera=0, viewport=True))
    frame = renderer.last_frame()
    assert frame["method"] == "masked"
    assert 0 < frame["pixels_traced"] < WIDTH * HEIGHT / 2
    # Where the lens is, the composite shows the trace's pixels.
    centre = (slice(HEIGHT // 2 - 5, HEIGHT // 2 + 5), slice(WIDTH // 2 - 5, WIDTH // 2 + 5))
    np.testing.assert_allclose(composite[centre], traced[centre], atol=4e-3)


def test_last_frame_reports_counters_and_pass_times(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    renderer.render(snell.View(64, 48, camera=0))
    first = renderer.last_frame()
    assert first["trees_built"] == 2 and first["top_level_built"]
    assert {"blas build", "tlas", "trace"} <= set(first["pass_ms"]) and first["gpu_ms"] > 0
    renderer.render(snell.View(64, 48, camera=0))
    assert renderer.last_frame()["skipped"], "a second frame of nothing changed reuses the image"


def test_optics_switches_change_the_glass(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    with_fresnel = renderer.render(snell.View(WIDTH, HEIGHT, camera=0))
    without = renderer.render(snell.View(WIDTH, HEIGHT, camera=0, fresnel=False))
    assert np.abs(with_fresnel - without).max() > 0.01


def test_every_method_draws(device, lens_gltf):
    scene = snell.Scene.load(str(lens_gltf))
    renderer = snell.Renderer(device, scene)
    names = [name for name, _ in snell.methods()]
    assert {"trace", "trace-1", "masked", "iris-plane", "normal-offset", "refraction-map", "none"} <= set(names)
    for method in (name for name in names if name != "driver-rt"):
        rgba = renderer.render(snell.View(64, 48, camera=0, method=method))
        assert np.isfinite(rgba).all() and renderer.last_frame()["method"] in (method, "masked"), method


def test_scene_from_arrays_renders_like_its_gltf(device, lens_gltf):
    loaded = snell.Renderer(device, snell.Scene.load(str(lens_gltf)))
    arrays = snell.Renderer(device, lens_arrays())
    view = snell.View(WIDTH, HEIGHT, camera=0)
    a, b = srgb8(loaded.render(view)).astype(int), srgb8(arrays.render(view)).astype(int)
    assert np.abs(a - b).max() <= 1


def test_framing_looks_down_z_at_the_box_from_far_enough_to_see_its_bounding_sphere():
    framed = snell.framing((-1.0, 0.0, -3.0), (3.0, 4.0, 1.0))
    distance = float(np.sqrt(12.0)) / np.sin(snell.DEFAULT_YFOV / 2)  # the box's half diagonal over sin(yfov / 2)
    assert np.allclose(framed["eye"], (1.0, 2.0, -1.0 + distance), rtol=1e-6)
    assert np.allclose(framed["target"], (1.0, 2.0, -1.0)) and framed["up"] == (0.0, 1.0, 0.0)
    empty = snell.framing((np.inf,) * 3, (-np.inf,) * 3)  # nothing drawn: the unit sphere about the origin
    assert np.allclose(empty["eye"], (0.0, 0.0, 1.0 / np.sin(snell.DEFAULT_YFOV / 2)), rtol=1e-6)
