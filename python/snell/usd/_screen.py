"""How big things are on screen, for detail sized to the view: each subdivision cage's level, each round
gprim's segments (_gprims.py).

The view is the one snell draws a stage through first: the camera asked for (the
stage's first, else snell render's framed view of the bounds) at the image size
asked (1920 x 1080 unless said), at the time code read. A length's size in
pixels is taken where its box comes nearest the camera, so detail is enough for
the nearest part of a mesh. An animation keeps the levels chosen at its first
frame for the whole shot, so each frame refits the trees and none rebuilds them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Hashable, Optional

import numpy as np

from .. import DEFAULT_YFOV

#: The most levels a cage is refined by when its level is sized to the view, and the fewest (a cage is always
#: refined at least once: its limit surface, not its control points, is what the stage describes).
MAX_AUTO_LEVEL = 3
MIN_AUTO_LEVEL = 1
#: The refined triangles a scene may hold before levels are lowered (about 100 bytes each on the GPU with the
#: tree and the refine's buffers: some 800 MiB), largest meshes first, with one warning naming them.
DEFAULT_TRIANGLE_BUDGET = 8_000_000
#: The refined vertices whose refine tables (84 bytes a vertex at one level, more at more: measured) bind in
#: one buffer of 128 MiB, the least Vulkan guarantees (maxStorageBufferRange); lavapipe binds no more.
REFINED_VERTEX_BUDGET = 1_300_000


@dataclass
class Screen:
    """Pixels per metre of a view: at unit depth in front of a perspective camera, or anywhere in an
    orthographic one."""

    world_to_camera: np.ndarray  #: 4x4, column vectors
    pixels_per_metre: float
    orthographic: bool
    width: int
    height: int

    def pixels(self, length: float, lo: np.ndarray, hi: np.ndarray) -> float:
        """How many pixels `length` (metres) spans at the point of the box lo-hi (world) nearest the camera;
        inf where the camera is inside it or touches it, 0 where it lies wholly behind."""
        if self.orthographic:
            return length * self.pixels_per_metre
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        depth = -(corners @ self.world_to_camera[:3, :3].T + self.world_to_camera[:3, 3])[:, 2]
        if depth.max() <= 0.0:
            return 0.0
        if depth.min() <= 0.0:
            return math.inf
        return length * self.pixels_per_metre / float(depth.min())


def screen_of(camera, lo: np.ndarray, hi: np.ndarray, width: int, height: int) -> Screen:
    """The screen of a camera (a CameraState, conformed as snell-usd conforms it) or, with None, of the framed
    view of the world bounds lo-hi (snell render's: the whole of them, looking down -Z)."""
    if camera is not None:
        view, projection = camera.matrices(width, height)
        return Screen(view, 0.5 * height * abs(float(projection[1, 1])), camera.orthographic, width, height)
    centre, radius = np.zeros(3), 1.0
    if np.all(lo <= hi):
        centre, radius = 0.5 * (lo + hi), max(0.5 * float(np.linalg.norm(hi - lo)), 1e-6)
    view = np.eye(4)
    view[:3, 3] = -(centre + (0.0, 0.0, radius / math.sin(DEFAULT_YFOV / 2)))
    return Screen(view, 0.5 * height / math.tan(DEFAULT_YFOV / 2), False, width, height)


def level_for(edge_pixels: float, cap: int = MAX_AUTO_LEVEL) -> int:
    """The levels that bring a cage's mean edge (in pixels) to about a pixel: each halves it."""
    if not edge_pixels > 1.0:
        return MIN_AUTO_LEVEL
    if math.isinf(edge_pixels):
        return cap
    return int(min(cap, max(MIN_AUTO_LEVEL, math.ceil(math.log2(edge_pixels)))))


def mean_edge(points: np.ndarray, face_counts: np.ndarray, face_points: np.ndarray) -> float:
    """The mean length of a cage's face edges (each face's corners in turn), in the points' units."""
    if len(face_points) == 0 or len(points) == 0:
        return 0.0
    p = points[face_points]
    return float(np.mean(np.linalg.norm(p[_following(face_counts)] - p, axis=1)))


def _following(face_counts: np.ndarray) -> np.ndarray:
    """For each face corner (faces' corners in turn), the corner after it in its face: its edge's other end."""
    counts = np.asarray(face_counts, np.int64)
    ends = np.cumsum(counts)
    following = np.arange(int(counts.sum())) + 1
    following[ends - 1] = ends - counts
    return following


def fit_budget(meshes: dict[Hashable, tuple["CageCounts", int]], triangles: int,
               vertices: int) -> dict[Hashable, int]:
    """Levels lowered until the refined triangles and vertices fit: {mesh: (its cage's counts, level)} in,
    {mesh: level} out for the meshes lowered, the mesh of most refined triangles first; 0 (the cage drawn as
    polygons) is the last resort, and a scene still over then is left to the device's own check."""
    levels = {name: level for name, (_, level) in meshes.items()}

    def over() -> bool:
        sizes = [counts.refined(levels[name]) for name, (counts, _) in meshes.items()]
        return sum(t for _, t in sizes) > triangles or sum(v for v, _ in sizes) > vertices

    lowered: dict[str, int] = {}
    while over():
        name = max((n for n in levels if levels[n] > 0), key=lambda n: meshes[n][0].refined(levels[n])[1],
                   default=None)
        if name is None:
            break
        levels[name] -= 1
        lowered[name] = levels[name]
    return lowered


def world_box(points: np.ndarray, matrix: np.ndarray) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """The world bounds of points placed by a 4x4 (column vectors); None where none is finite."""
    world = np.asarray(points, np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    world = world[np.isfinite(world).all(axis=1)]
    return (world.min(axis=0), world.max(axis=0)) if len(world) else None


@dataclass(frozen=True)
class CageCounts:
    """A cage's vertices, edges, faces and face corners, and its scheme: what its refinements hold follows."""

    vertices: int
    edges: int
    faces: int
    corners: int
    scheme: str

    @staticmethod
    def of(face_counts: np.ndarray, face_points: np.ndarray, scheme: str) -> "CageCounts":
        counts = np.asarray(face_counts, np.int64)
        points = np.asarray(face_points, np.int64)
        pairs = np.sort(np.stack([points, points[_following(counts)]], axis=1), axis=1)
        return CageCounts(len(np.unique(points)), len(np.unique(pairs, axis=0)), len(counts), int(counts.sum()),
                          scheme)

    def refined(self, level: int) -> tuple[int, int]:
        """The vertices and triangles refined `level` times (exact for a manifold cage without holes):
        Catmull-Clark and bilinear make an n-gon n quads, then each quad 4; Loop makes each triangle 4."""
        v, e, f = self.vertices, self.edges, self.faces
        if level <= 0:
            return v, self.corners - 2 * f
        if self.scheme == "loop":
            for _ in range(level):
                v, e, f = v + e, 2 * e + 3 * f, 4 * f
            return v, f
        v, e, f = v + e + f, 2 * e + self.corners, self.corners
        for _ in range(level - 1):
            v, e, f = v + e + f, 2 * e + 4 * f, 4 * f
        return v, 2 * f


def refined_size(face_counts: np.ndarray, face_points: np.ndarray, scheme: str, level: int) -> tuple[int, int]:
    """The vertices and triangles of a cage refined `level` times (CageCounts.refined)."""
    return CageCounts.of(face_counts, face_points, scheme).refined(level)


def refined_bytes(vertices: int, triangles: int) -> int:
    """About what a refined mesh holds on the GPU: each vertex's position, normal and UV (32 bytes), each
    triangle's indices and its share of the tree (52)."""
    return 32 * vertices + 52 * triangles
