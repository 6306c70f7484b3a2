"""UsdGeom's parametric gprims (Cube, Sphere, Cylinder, Cone, Capsule, Plane) as meshes, tessellated from their
attributes (size, radius, height, width, length, axis) at each time code.

A gprim is read as a mesh whose points and normals are computed, not authored:
GprimMesh gives the mesh reader (_meshes.py) what a UsdGeomMesh gives it,
with faces fixed per type and points and faceVarying normals from the
attributes at the time code asked, so an animated radius deforms the mesh
frame by frame as time-sampled points do. Faces wind counter-clockwise seen
from outside (the gprim's own orientation, rightHanded by default, still
applies). The height axis is the gprim's `axis`, its cross-section in the
other two taken in cyclic order (axis X: Y, Z; Y: Z, X; Z: X, Y), as USD's
own generators do. Round gprims take their segments around the axis from their
size on screen (segments_for, _screen.py): a lens must be finer than a ball.
"""

from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np
from pxr import Usd, UsdGeom, Vt

SEGMENTS = 32  # around the axis, where no screen sizes it; pole to pole on a sphere half that, a quarter per capsule end
MIN_SEGMENTS, MAX_SEGMENTS = 16, 512
#: The largest gap, in pixels, between a round gprim and its tessellation where it comes nearest the camera.
#: Glass magnifies it: through a lens of radius 174 pixels, chords a quarter of a pixel off drew 3.7% of the
#: checker behind it on the wrong square against a 256-segment sphere, 1/32 of a pixel under 0.5%.
CHORD_PIXELS = 1.0 / 32.0
TYPES = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane")

# (u, v, w) of a gprim built along w, in the stage's axes, for each `axis`: a cyclic order, right-handed.
_AXES = {"X": (1, 2, 0), "Y": (2, 0, 1), "Z": (0, 1, 2)}


class _Computed:
    """An attribute-like value the mesh reader reads (Get, ValueMightBeTimeVarying), computed from the gprim."""

    def __init__(self, compute: Callable[[Usd.TimeCode], object], varying: bool) -> None:
        self._compute = compute
        self._varying = varying

    def Get(self, time: Usd.TimeCode = Usd.TimeCode.Default()) -> object:  # noqa: N802 (USD's name)
        return self._compute(time)

    def ValueMightBeTimeVarying(self) -> bool:  # noqa: N802
        return self._varying

    def HasAuthoredValue(self) -> bool:  # noqa: N802
        return True


def _ring(count: int) -> tuple[np.ndarray, np.ndarray]:
    angles = 2.0 * np.pi * np.arange(count) / count
    return np.cos(angles), np.sin(angles)


class _Shape:
    """A tessellation: fixed faces, and points and faceVarying normals from the gprim's dimensions."""

    def __init__(self, counts: list[int], indices: list[int],
                 build: Callable[[dict[str, float]], tuple[np.ndarray, np.ndarray]]) -> None:
        self.counts = np.asarray(counts, np.int32)
        self.indices = np.asarray(indices, np.int32)
        self.build = build  # dimensions -> (points (P, 3), normals per face-vertex (F, 3)), in (u, v, w)


def segments_for(radius_pixels: float) -> int:
    """Segments around a circle of this radius (pixels) whose chords stray at most CHORD_PIXELS from it:
    r (1 - cos(pi / n)) <= CHORD_PIXELS; SEGMENTS where the radius is unknown (nan)."""
    if math.isnan(radius_pixels):
        return SEGMENTS
    if not radius_pixels > CHORD_PIXELS:
        return MIN_SEGMENTS
    n = math.pi / math.acos(1.0 - CHORD_PIXELS / radius_pixels) if math.isfinite(radius_pixels) else MAX_SEGMENTS
    return int(min(MAX_SEGMENTS, max(MIN_SEGMENTS, 4 * math.ceil(n / 4))))


def _grid_faces(rows: int, segments: int) -> tuple[list[int], list[int]]:
    """Quads between `rows` + 1 rings of `segments` points, counter-clockwise seen from outside when the rings
    run along +w and each ring counter-clockwise about +w."""
    ring = np.arange(segments)
    a = (np.arange(rows)[:, None] * segments + ring[None, :]).ravel()
    b = (np.arange(rows)[:, None] * segments + ((ring + 1) % segments)[None, :]).ravel()
    indices = np.stack([a, b, b + segments, a + segments], axis=1).ravel()
    return [4] * (rows * segments), indices.tolist()


def _profile_shape(profile: Callable[[dict[str, float]], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
                   rings: int, caps: tuple[bool, bool], segments: int) -> _Shape:
    """A surface of revolution about w: profile(d) gives per ring its radius, height and the profile's normal
    (radial part, axial part); caps close the first and last ring with flat n-gons (bottom facing -w)."""
    counts, indices = _grid_faces(rings - 1, segments)
    cap_faces = []
    if caps[0]:
        counts.append(segments)
        indices += list(range(segments - 1, -1, -1))
        cap_faces.append(-1.0)
    if caps[1]:
        counts.append(segments)
        top = (rings - 1) * segments
        indices += list(range(top, top + segments))
        cap_faces.append(1.0)
    cos, sin = _ring(segments)
    grid_corners = 4 * (rings - 1) * segments
    face_indices = np.asarray(indices)

    def build(d: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
        radius, height, n_radial, n_axial = profile(d)
        points = np.stack([np.outer(radius, cos).ravel(), np.outer(radius, sin).ravel(),
                           np.repeat(height, segments)], axis=1)
        ring_normals = np.stack([np.outer(n_radial, cos).ravel(), np.outer(n_radial, sin).ravel(),
                                 np.repeat(n_axial, segments)], axis=1)
        normals = ring_normals[face_indices[:grid_corners]]
        caps_normals = [np.tile((0.0, 0.0, w), (segments, 1)) for w in cap_faces]
        return points, np.concatenate([normals, *caps_normals]) if caps_normals else normals

    return _Shape(counts, indices, build)


def _sphere_profile(rings: int) -> Callable:
    """A sphere's rings from the -w pole to the +w pole; the poles are rings of radius 0, so their quads are
    triangles (and a zero-area one, which nothing hits)."""
    theta = np.linspace(np.pi, 0.0, rings + 1)

    def profile(d: dict[str, float]):
        r = d["radius"]
        return r * np.sin(theta), r * np.cos(theta), np.sin(theta), np.cos(theta)

    return profile


def _cube() -> _Shape:
    corners = np.array([(x, y, z) for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], float)
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    normals = np.repeat(np.array([(0, 0, -1), (0, 0, 1), (0, -1, 0), (0, 1, 0), (-1, 0, 0), (1, 0, 0)], float),
                        4, axis=0)
    return _Shape([4] * 6, sum(faces, []), lambda d: (corners * (d["size"] / 2.0), normals))


def _plane() -> _Shape:
    corners = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], float)

    def build(d: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
        return corners * (d["u"] / 2.0, d["v"] / 2.0, 1.0), np.tile((0.0, 0.0, 1.0), (4, 1))

    return _Shape([4], [0, 1, 2, 3], build)


def _cone_profile(d: dict[str, float]):
    r, h = d["radius"], d["height"]
    slope = math.hypot(r, h) or 1.0
    # Base ring and a ring of radius 0 at the apex: the side's normal leans up by the cone's slope.
    return (np.array([r, 0.0]), np.array([-h / 2.0, h / 2.0]), np.full(2, h / slope), np.full(2, r / slope))


def _shape(kind: str, segments: int = SEGMENTS) -> _Shape:
    if kind == "Cube":
        return _cube()
    if kind == "Plane":
        return _plane()
    if kind == "Sphere":
        return _profile_shape(_sphere_profile(segments // 2), segments // 2 + 1, (False, False), segments)
    if kind == "Cylinder":
        return _profile_shape(lambda d: (np.full(2, d["radius"]), np.array([-d["height"], d["height"]]) / 2.0,
                                         np.ones(2), np.zeros(2)), 2, (True, True), segments)
    if kind == "Cone":
        return _profile_shape(_cone_profile, 2, (True, False), segments)
    # A capsule: a hemisphere at each end of a cylinder of `height`; the equator ring twice, once for each end,
    # the cylinder's side between them.
    n = segments // 4
    theta = np.concatenate([np.linspace(np.pi, np.pi / 2, n + 1), np.linspace(np.pi / 2, 0.0, n + 1)])
    end = np.concatenate([np.full(n + 1, -0.5), np.full(n + 1, 0.5)])

    def capsule(d: dict[str, float]):
        r = d["radius"]
        return r * np.sin(theta), end * d["height"] + r * np.cos(theta), np.sin(theta), np.cos(theta)

    return _profile_shape(capsule, 2 * n + 2, (False, False), segments)


_SHAPES: dict[tuple[str, int], _Shape] = {}


class GprimMesh:
    """A gprim read as a UsdGeomMesh: the mesh reader's calls, on faces and points tessellated from it."""

    def __init__(self, prim: Usd.Prim, radius_pixels: Callable[[float], float] = lambda radius: math.nan,
                 time: Usd.TimeCode = Usd.TimeCode.EarliestTime()) -> None:
        """radius_pixels: how many pixels a length (the gprim's own units) spans where the gprim comes nearest
        the camera (_screen.py); round gprims take their segments from it, for their radius at `time`."""
        self.prim = prim
        self.kind = prim.GetTypeName()
        self._attributes = [prim.GetAttribute(n) for n in ("size", "radius", "height", "width", "length", "axis")]
        round_kinds = ("Sphere", "Cylinder", "Cone", "Capsule")
        radius = self._dimensions(time)[0].get("radius", 0.0)
        self.segments = segments_for(radius_pixels(radius)) if self.kind in round_kinds else SEGMENTS
        key = (self.kind, self.segments)
        if key not in _SHAPES:
            _SHAPES[key] = _shape(self.kind, self.segments)
        self.shape = _SHAPES[key]
        varying = any(a and a.ValueMightBeTimeVarying() for a in self._attributes)
        self._points = _Computed(lambda t: Vt.Vec3fArray.FromNumpy(self._at(t)[0]), varying)
        self._normals = _Computed(lambda t: Vt.Vec3fArray.FromNumpy(self._at(t)[1]), varying)
        self._counts = _Computed(lambda t: Vt.IntArray(self.shape.counts.tolist()), False)
        self._indices = _Computed(lambda t: Vt.IntArray(self.shape.indices.tolist()), False)
        self._holes = _Computed(lambda t: Vt.IntArray(), False)
        self._cache: Optional[tuple[float, tuple[np.ndarray, np.ndarray]]] = None

    def _dimensions(self, time: Usd.TimeCode) -> tuple[dict[str, float], str]:
        values = {a.GetName(): a.Get(time) for a in self._attributes if a}
        axis = str(values.get("axis") or "Z")
        d = {name: float(values[name]) for name in ("size", "radius", "height", "width", "length")
             if values.get(name) is not None}
        if self.kind == "Plane":  # width along x (axis Z or Y) or z (axis X); length along y (Z or X) or z (Y)
            d["u"], d["v"] = (d["width"], d["length"]) if axis == "Z" else (d["length"], d["width"])
        return d, axis if axis in _AXES else "Z"

    def _at(self, time: Usd.TimeCode) -> tuple[np.ndarray, np.ndarray]:
        key = time.GetValue() if not time.IsDefault() else math.nan
        if self._cache is None or not (self._cache[0] == key or (math.isnan(key) and math.isnan(self._cache[0]))):
            d, axis = self._dimensions(time)
            points, normals = self.shape.build(d)
            order = np.argsort(_AXES[axis])  # (u, v, w) columns into the stage's x, y, z
            self._cache = (key, (np.ascontiguousarray(points[:, order], np.float32),
                                 np.ascontiguousarray(normals[:, order], np.float32)))
        return self._cache[1]

    # The calls the mesh reader makes of a UsdGeomMesh.
    def GetPrim(self) -> Usd.Prim:  # noqa: N802 (USD's names)
        return self.prim

    def GetPath(self):  # noqa: N802
        return self.prim.GetPath()

    def GetPointsAttr(self) -> _Computed:  # noqa: N802
        return self._points

    def GetNormalsAttr(self) -> _Computed:  # noqa: N802
        return self._normals

    def GetNormalsInterpolation(self) -> str:  # noqa: N802
        return UsdGeom.Tokens.faceVarying

    def GetFaceVertexCountsAttr(self) -> _Computed:  # noqa: N802
        return self._counts

    def GetFaceVertexIndicesAttr(self) -> _Computed:  # noqa: N802
        return self._indices

    def GetHoleIndicesAttr(self) -> _Computed:  # noqa: N802
        return self._holes

    def GetOrientationAttr(self) -> Usd.Attribute:  # noqa: N802
        return UsdGeom.Gprim(self.prim).GetOrientationAttr()

    def GetDoubleSidedAttr(self) -> Usd.Attribute:  # noqa: N802
        return UsdGeom.Gprim(self.prim).GetDoubleSidedAttr()
