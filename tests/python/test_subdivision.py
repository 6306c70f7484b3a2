"""Subdivision surfaces from numpy: a cage and its tags in, the refined surface drawn, the cage fed each frame."""

from __future__ import annotations

import numpy as np
import pytest

import snell

# A unit cube's cage: corner bits x = 1, y = 2, z = 4, faces counter-clockwise seen from outside.
CUBE_POINTS = np.array([[(i & 1) - 0.5, ((i >> 1) & 1) - 0.5, ((i >> 2) & 1) - 0.5] for i in range(8)], np.float32)
CUBE_FACES = np.array([0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, 4, 5, 7, 6], np.uint32)
WIDTH, HEIGHT = 96, 96


def cube_scene(subdivision: snell.Subdivision, points: np.ndarray = CUBE_POINTS) -> snell.Scene:
    glass = snell.Material(transmission=1.0, ior=1.5, name="glass")
    mesh = snell.Mesh(points, None, CUBE_FACES, subdivision=subdivision, material=0, name="cube")
    return snell.Scene.from_arrays([mesh], materials=[glass], name="a subdivided cube")


def catmull_clark(level: int = 2, **tags) -> snell.Subdivision:
    s = snell.Subdivision("catmullClark", level, face_vertex_counts=np.full(6, 4))
    for name, value in tags.items():
        setattr(s, name, value)
    return s


def view() -> snell.View:
    return snell.View(WIDTH, HEIGHT, eye=(1.6, 1.3, 2.2), target=(0, 0, 0))


def test_a_cage_is_drawn_as_its_refined_surface(device):
    scene = cube_scene(catmull_clark(2))
    assert scene.vertex_count(0) == 8  # what the host writes: the cage
    assert scene.drawn_vertex_count(0) == 98 and scene.drawn_triangle_count(0) == 192
    assert scene.warnings == []
    with pytest.raises(snell.Error, match=r"indices must have shape \(n, 3\)"):  # a plain mesh's are triangles
        snell.Scene.from_arrays([snell.Mesh(CUBE_POINTS, np.zeros_like(CUBE_POINTS), CUBE_FACES,
                                            subdivision=snell.Subdivision("none"))])


def test_the_refined_cube_is_rounder_than_its_cage(device):
    refined = snell.Renderer(device, cube_scene(catmull_clark(3))).render(view())
    cage = snell.Renderer(device, cube_scene(catmull_clark(1, scheme="bilinear"))).render(view())  # flat: the cage

    def covered(picture: np.ndarray) -> int:  # pixels where the glass is, off the background
        return int((np.abs(picture[..., :3] - picture[0, 0, :3]).max(axis=2) > 1e-3).sum())

    # The smooth surface's silhouette lies inside the cage's: fewer pixels meet the glass.
    assert 0 < covered(refined) < 0.9 * covered(cage)


def test_set_vertices_moves_the_cage_and_the_next_frame_refines_it(device):
    renderer = snell.Renderer(device, cube_scene(catmull_clark(2)))
    before = renderer.render(view())
    renderer.set_vertices(0, CUBE_POINTS * np.array([1.4, 0.7, 1.0], np.float32))
    after = renderer.render(view())
    frame = renderer.last_frame()
    assert frame["meshes_refined"] == 1 and frame["vertices_refined"] == 98
    assert np.abs(after - before).max() > 0.1
    renderer.render(view())
    assert renderer.last_frame()["meshes_refined"] == 0, "a frame whose cage did not move refines nothing"


def test_the_tags_are_read_by_name_and_a_wrong_one_is_an_error():
    s = snell.Subdivision("loop", 1, interpolate_boundary="edgeOnly", face_varying_linear_interpolation="all",
                          normals="mesh")
    assert (s.scheme, s.level, s.interpolate_boundary, s.face_varying_linear_interpolation, s.normals) == \
        ("loop", 1, "edgeOnly", "all", "mesh")
    s.crease_indices, s.crease_lengths, s.crease_sharpnesses = [0, 1, 3], [3], [10.0]
    assert s.crease_indices == [0, 1, 3] and s.crease_sharpnesses == [10.0]
    with pytest.raises(snell.Error, match="scheme 'smooth' is not one of none, catmullClark, loop, bilinear"):
        snell.Subdivision("smooth")
    with pytest.raises(snell.Error, match="interpolate_boundary"):
        s.interpolate_boundary = "sharp"


def test_a_bad_cage_is_an_error_naming_the_mesh(device):
    faces = CUBE_FACES.copy()
    faces[3] = 9
    with pytest.raises(snell.Error, match=r"mesh 0 \('cube'\) indices: corner 3 names vertex 9 of 8"):
        snell.Scene.from_arrays([snell.Mesh(CUBE_POINTS, None, faces, subdivision=catmull_clark(2), name="cube")])
    with pytest.raises(snell.Error, match="faceVertexCounts add up to 25"):
        s = catmull_clark(2)
        s.face_vertex_counts = [5, 4, 4, 4, 4, 4]
        snell.Scene.from_arrays([snell.Mesh(CUBE_POINTS, None, CUBE_FACES, subdivision=s, name="cube")])


def test_tags_snell_cannot_refine_are_a_warning_and_the_cage_is_drawn(device):
    scene = cube_scene(catmull_clark(2, crease_indices=[0, 40], crease_lengths=[2], crease_sharpnesses=[2.0]))
    assert scene.drawn_vertex_count(0) == 8
    assert len(scene.warnings) == 1 and "crease vertex 40" in scene.warnings[0] and "cage is drawn" in \
        scene.warnings[0]
    snell.Renderer(device, scene).render(view())  # and it draws
