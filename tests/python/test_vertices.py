"""New vertices from numpy each frame: the host's own deformation."""

from __future__ import annotations

import numpy as np

import snell
from conftest import SPHERE, lens_arrays, squash_target
from support import srgb8

WIDTH, HEIGHT = 160, 120
LENS = 1  # the glass sphere's mesh in lens_arrays()


def squashed(weight: float):
    """The lens as the glTF morph deforms it (deform.comp: normals re-normalised)."""
    dp, dn = squash_target()
    positions = SPHERE[0] + weight * dp
    normals = SPHERE[1] + weight * dn
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return positions.astype(np.float32), normals.astype(np.float32)


def test_vertices_from_numpy_equal_the_same_gltf_morph(device, lens_gltf):
    morphed = snell.Renderer(device, snell.Scene.load(str(lens_gltf)))
    fed = snell.Renderer(device, lens_arrays())
    view = snell.View(WIDTH, HEIGHT, camera=0)
    pictures = []
    for t in (0.0, 0.35, 0.8):
        morphed.set_time(t)  # the animation's weight is t
        fed.set_vertices(LENS, *squashed(t))
        a, b = srgb8(morphed.render(view)).astype(int), srgb8(fed.render(view)).astype(int)
        differ = np.abs(a - b).max(axis=2) > 1
        assert differ.mean() < 0.002, f"at {t} s {differ.sum()} pixels differ by more than 1/255"
        pictures.append(a)
    assert (np.abs(pictures[0] - pictures[-1]).max(axis=2) > 8).mean() > 0.05, "the morph moved nothing"


def test_writing_the_mapped_view_in_place_moves_the_mesh(device):
    renderer = snell.Renderer(device, lens_arrays())
    view = snell.View(WIDTH, HEIGHT, camera=0)
    before = renderer.render(view)
    positions, normals = renderer.positions(LENS), renderer.normals(LENS)
    assert positions.shape == (len(SPHERE[0]), 3) and positions.dtype == np.float32 and positions.flags.writeable
    np.testing.assert_array_equal(positions, SPHERE[0])
    new_positions, new_normals = squashed(1.0)
    np.copyto(positions, new_positions)
    np.copyto(normals, new_normals)
    renderer.mark_dirty(LENS)
    after = renderer.render(view)
    frame = renderer.last_frame()
    assert frame["meshes_uploaded"] == 1 and frame["trees_refit"] + frame["trees_built"] == 1
    assert np.abs(after - before).max() > 0.05


def test_a_moved_instance_refits_only_the_top_level(device):
    renderer = snell.Renderer(device, lens_arrays())
    view = snell.View(WIDTH, HEIGHT, camera=0)
    before = renderer.render(view)
    renderer.set_transform(LENS, np.array([[1, 0, 0, 0.3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    after = renderer.render(view)
    frame = renderer.last_frame()
    assert frame["trees_refit"] == 0 and frame["trees_built"] == 0 and frame["meshes_uploaded"] == 0
    assert frame["top_level_refit"] or frame["top_level_built"]
    assert np.abs(after - before).max() > 0.05


def test_vertex_views_outlive_a_closed_renderer(device):
    renderer = snell.Renderer(device, lens_arrays())
    positions = renderer.positions(LENS)
    renderer.close()
    positions[0] = (1.0, 2.0, 3.0)  # the memory is still snell's, held by the view
    np.testing.assert_array_equal(positions[0], (1.0, 2.0, 3.0))
