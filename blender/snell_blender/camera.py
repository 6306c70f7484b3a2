"""Blender's axes and cameras in snell's terms, written once.

Blender's world is Z-up, snell's (glTF's) Y-up: the studio gradient that glass
reflects has its sky at +Y. Everything goes to snell through one rotation, the
glTF exporter's own, (x, y, z) -> (x, z, -y), and every camera (the viewport's,
the scene camera of F12 and of a shot) becomes a snell.View here.
"""

from __future__ import annotations

import numpy as np

Y_UP = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], np.float64)
_FROM_Y_UP = np.linalg.inv(Y_UP)


def _array(matrix) -> np.ndarray:
    """A mathutils matrix (or any nested rows) as a float64 array."""
    return np.array([list(row) for row in matrix], np.float64)


def to_snell(matrix) -> np.ndarray:
    """An object's Blender world matrix as a matrix of snell's Y-up world."""
    return Y_UP @ _array(matrix)


def view_to_snell(view_matrix) -> np.ndarray:
    """A Blender view matrix (world to camera) as snell's: its world to the same camera."""
    return _array(view_matrix) @ _FROM_Y_UP


def normals_to_blender(normals: np.ndarray) -> np.ndarray:
    """Normals of snell's Y-up world (rows of 3) in Blender's Z-up one."""
    return normals @ Y_UP[:3, :3].astype(normals.dtype)


def scene_camera(depsgraph, camera, width: int, height: int, pixel_aspect: tuple = (1.0, 1.0)) -> tuple:
    """The camera object's (view matrix in snell's world, projection) for a width x height frame at the
    depsgraph's time, with Blender's pixel aspect."""
    camera = camera.evaluated_get(depsgraph)
    projection = _array(camera.calc_matrix_camera(depsgraph, x=width, y=height, scale_x=pixel_aspect[0],
                                                  scale_y=pixel_aspect[1]))
    return view_to_snell(camera.matrix_world.inverted()), projection


def pixel_rays(depsgraph, camera, width: int, height: int) -> np.ndarray:
    """Each pixel's ray direction from the camera object (height x width x 3), unnormalised, in snell's world."""
    view, p = scene_camera(depsgraph, camera, width, height)
    rows, columns = np.mgrid[0:height, 0:width] + 0.5
    ndc_x, ndc_y = 2.0 * columns / width - 1.0, 1.0 - 2.0 * rows / height
    if p[3, 3] == 0.0:  # perspective: camera-space direction (x / -z, y / -z, -1) from the off-centre frustum
        rays = np.stack([(ndc_x + p[0, 2]) / p[0, 0], (ndc_y + p[1, 2]) / p[1, 1], -np.ones_like(ndc_x)], -1)
    else:
        rays = np.broadcast_to(np.array([0.0, 0.0, -1.0]), (height, width, 3))
    camera_to_world = np.linalg.inv(view)[:3, :3]
    return rays @ camera_to_world.T


def view_of(scene, width: int, height: int, view_matrix: np.ndarray, projection, viewport: bool, background):
    """A snell.View of the scene's settings from a view matrix of snell's world (view_to_snell) and
    Blender's projection."""
    import snell

    from .properties import settings

    options = settings(scene)
    return snell.View(width, height, view_matrix=view_matrix, projection=_array(projection), viewport=viewport,
                      method=options.method, max_interfaces=options.max_interfaces, fresnel=options.fresnel,
                      dispersion=options.dispersion, volume=options.volume, background=background)


def viewport_view(scene, region, region_3d, background):
    """The 3D viewport's snell.View: its region's size, view and window matrices."""
    return view_of(scene, region.width, region.height, view_to_snell(region_3d.view_matrix),
                   region_3d.window_matrix, True, background)
