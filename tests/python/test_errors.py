"""Bad input raises snell.Error naming the array, index or file at fault."""

from __future__ import annotations

import numpy as np
import pytest

import snell
from conftest import SPHERE, lens_arrays

POSITIONS, NORMALS, INDICES, UVS = SPHERE


def scene_of(**mesh) -> snell.Scene:
    fields = {"positions": POSITIONS, "normals": NORMALS, "indices": INDICES}
    fields.update(mesh)
    return snell.Scene.from_arrays([snell.Mesh(**fields)])


def test_positions_of_the_wrong_dtype_are_named():
    with pytest.raises(snell.Error, match=r"mesh 0 positions must be float32, got float64"):
        scene_of(positions=POSITIONS.astype(np.float64))


def test_indices_of_the_wrong_dtype_are_named():
    with pytest.raises(snell.Error, match=r"mesh 0 indices must be uint32, got int64"):
        scene_of(indices=INDICES.astype(np.int64))


def test_an_array_of_the_wrong_shape_is_named():
    with pytest.raises(snell.Error, match=r"mesh 0 normals must have shape \(n, 3\), got \(\d+, 4\)"):
        scene_of(normals=np.zeros((len(NORMALS), 4), np.float32))


def test_a_list_where_an_array_belongs_is_named():
    with pytest.raises(snell.Error, match=r"positions must be a numpy array of float32, got list"):
        scene_of(positions=POSITIONS.tolist())


def test_an_index_past_the_vertices_is_named():
    bad = INDICES.copy()
    bad[7, 1] = len(POSITIONS)
    with pytest.raises(snell.Error, match=rf"triangle 7 names vertex {len(POSITIONS)} of {len(POSITIONS)}"):
        scene_of(indices=bad)


def test_normals_and_positions_of_different_lengths_are_refused():
    with pytest.raises(snell.Error, match=r"\d+ normals for \d+ positions"):
        scene_of(normals=NORMALS[:-1])


def test_a_material_index_past_the_materials_is_named():
    with pytest.raises(snell.Error, match=r"mesh 0: material 3 of 0"):
        snell.Scene.from_arrays([snell.Mesh(POSITIONS, NORMALS, INDICES, material=3)])


def test_set_vertices_of_the_wrong_length_is_refused(device):
    renderer = snell.Renderer(device, lens_arrays())
    with pytest.raises(snell.Error, match=r"set_vertices: mesh 1 positions: 3 rows for the mesh's \d+ vertices"):
        renderer.set_vertices(1, np.zeros((3, 3), np.float32))


def test_a_missing_file_is_named(tmp_path):
    missing = tmp_path / "nowhere.glb"
    with pytest.raises(snell.Error, match="nowhere.glb"):
        snell.Scene.load(str(missing))


def test_an_unknown_method_lists_the_methods(device):
    renderer = snell.Renderer(device, lens_arrays())
    with pytest.raises(snell.Error, match=r"no method 'raytrace' \(the methods: auto, trace, "):
        renderer.render(snell.View(32, 24, method="raytrace"))


def test_render_into_an_array_of_the_wrong_size_is_refused(device):
    renderer = snell.Renderer(device, lens_arrays())
    with pytest.raises(snell.Error, match=r"out must have shape \(24, 32, 4\)"):
        renderer.render_into(snell.View(32, 24), np.zeros((32, 24, 4), np.float32))


def test_a_closed_renderer_says_so(device):
    renderer = snell.Renderer(device, lens_arrays())
    renderer.close()
    with pytest.raises(snell.Error, match="the renderer is closed"):
        renderer.render(snell.View(32, 24))


def test_errors_are_runtime_errors():
    assert issubclass(snell.Error, RuntimeError)
