"""UsdGeomMesh prims as snell meshes: triangles, split vertices, normals, texture coordinates.

A mesh prim becomes one snell mesh per material: its materialBind
GeomSubsets, and the faces no subset claims. n-gons are fanned (as Hydra
does); a leftHanded orientation reverses the winding. A snell vertex is one
distinct (point, normal element, st element) of the faces' corners, found
from the primvars' indices at open time, so faceVarying normals or st split
points exactly where they differ, and the same split serves every frame.
Unauthored normals are computed smooth (area-weighted face normals summed at
each point) from the posed points.

A subdivision surface (subdivisionScheme catmullClark, USD's fallback, loop
or bilinear) is sent as its cage instead: every point, its faces as USD
gives them, and its tags (creases, corners, holes, interpolateBoundary,
faceVaryingLinearInterpolation, triangleSubdivisionRule) in a
snell.Subdivision, which snell refines on the GPU each time the points are
sent. Each material's part carries the whole cage, the other parts' faces
as holes, so every part refines the one surface. Its normals are snell's
own (USD ignores authored normals on a subdivision surface).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from pxr import Usd, UsdGeom, UsdShade, Vt

from .. import Subdivision
from ._problems import Problems
from ._skinning import SkelFrame, Skin

_PER_POINT = (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying)


@dataclass
class Topology:
    """A mesh's faces as fan triangles of corners (face-vertex ids), winding made right-handed."""

    point_count: int
    face_counts: np.ndarray
    face_points: np.ndarray  #: faceVertexIndices: the point of each face-vertex
    triangles: np.ndarray  #: (T, 3) face-vertex ids
    triangle_face: np.ndarray  #: (T,) the face each triangle came from

    @property
    def face_count(self) -> int:
        return len(self.face_counts)

    def face_of_corner(self) -> np.ndarray:
        return np.repeat(np.arange(self.face_count), self.face_counts)


@dataclass
class Primvar:
    """Where each face-vertex reads a primvar (normals or st): element ids into its values."""

    attribute: Usd.Attribute
    interpolation: str
    corner_ids: np.ndarray  #: per face-vertex, an index into the values
    point_ids: Optional[np.ndarray]  #: per point, when the primvar is a function of the point alone
    varying: bool


@dataclass
class Part:
    """One snell mesh of a mesh prim: the triangles of one material, over their own vertices."""

    name: str
    triangles: np.ndarray  #: ids into the topology's triangles
    material: int
    vertex_point: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    vertex_normal: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    indices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.uint32))
    uvs: Optional[np.ndarray] = None
    identity: bool = False  #: vertex i is point i: positions copy without a gather
    mesh: int = -1  #: snell's mesh index
    cage: Optional[Subdivision] = None  #: a subdivision surface's scheme and tags: indices are then its faces
    face_materials: Optional[np.ndarray] = None  #: a cage's: each face's material (snell.Mesh's face_materials)


@dataclass
class Pose:
    """A mesh prim's points and normals at one time code, before they are split into its parts' vertices."""

    points: np.ndarray  #: (P, 3) float32
    normals: np.ndarray  #: the values part.vertex_normal indexes
    normal_basis: Optional[np.ndarray] = None  #: (P, 3, 3): each point's skinning cofactor for authored normals
    unit: bool = False  #: the normals are unit length as they are


def read_topology(mesh: UsdGeom.Mesh, time: Usd.TimeCode, problems: Problems) -> Optional[Topology]:
    """The mesh's faces as triangles; None (with a warning or an error) when there is nothing to draw."""
    path = mesh.GetPath()
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get(time) or [], np.int64)
    face_points = np.asarray(mesh.GetFaceVertexIndicesAttr().Get(time) or [], np.int64)
    points = mesh.GetPointsAttr().Get(time)
    point_count = 0 if points is None else len(points)
    if len(counts) == 0:
        problems.warn(path, "has no faces: skipped")
        return None
    if point_count == 0:
        problems.fail(path, f"has {len(counts)} faces but no points")
        return None
    if counts.sum() != len(face_points) or (counts < 0).any():
        problems.fail(path, f"faceVertexCounts add up to {int(counts.sum())} but faceVertexIndices has "
                            f"{len(face_points)} entries")
        return None
    if len(face_points) and (face_points.min() < 0 or face_points.max() >= point_count):
        bad = int(face_points[(face_points < 0) | (face_points >= point_count)][0])
        problems.fail(path, f"faceVertexIndices refers to point {bad}; the mesh has {point_count} points")
        return None
    if mesh.GetFaceVertexCountsAttr().ValueMightBeTimeVarying() or \
            mesh.GetFaceVertexIndicesAttr().ValueMightBeTimeVarying():
        problems.warn(path, "its faces change over time; snell keeps those of the time code it opened at")
    keep = counts >= 3
    if not keep.all():
        problems.warn(path, f"{int((~keep).sum())} faces with fewer than 3 vertices are skipped")
    holes = np.asarray(mesh.GetHoleIndicesAttr().Get(time) or [], np.int64)
    if len(holes):
        keep[holes[(holes >= 0) & (holes < len(counts))]] = False
    ntri = np.where(keep, counts - 2, 0)
    start = np.cumsum(counts) - counts
    face = np.repeat(np.arange(len(counts)), ntri)
    k = np.arange(ntri.sum()) - np.repeat(np.cumsum(ntri) - ntri, ntri) + 1
    triangles = np.stack([start[face], start[face] + k, start[face] + k + 1], axis=1)
    if mesh.GetOrientationAttr().Get(time) == UsdGeom.Tokens.leftHanded:
        triangles = triangles[:, [0, 2, 1]]
    if len(triangles) == 0:
        problems.warn(path, "has no faces of 3 or more vertices: skipped")
        return None
    return Topology(point_count, counts, face_points, triangles, face)


_SCHEMES = ("catmullClark", "loop", "bilinear")


def read_subdivision(mesh: UsdGeom.Mesh, topology: Topology, time: Usd.TimeCode, level: int,
                     problems: Problems) -> Optional[Subdivision]:
    """The mesh's subdivisionScheme and tags as a snell.Subdivision of the whole cage; None for a polygon mesh
    (scheme none), a level of 0 (cages drawn as they are), or a cage that cannot be refined (said once)."""
    scheme = str(mesh.GetSubdivisionSchemeAttr().Get(time) or "catmullClark")
    if scheme == "none" or level <= 0:
        return None
    path = mesh.GetPath()
    if scheme not in _SCHEMES:
        problems.warn(path, f"subdivisionScheme '{scheme}' is not one USD defines: drawn as its cage")
        return None
    if (topology.face_counts < 3).any():
        problems.warn(path, "a subdivision cage with faces of fewer than 3 vertices: drawn unrefined")
        return None

    def values(attribute: Usd.Attribute, kind) -> np.ndarray:
        return np.asarray(attribute.Get(time) or [], kind)

    cage = Subdivision(scheme=scheme, level=level, face_vertex_counts=topology.face_counts)
    boundary = str(mesh.GetInterpolateBoundaryAttr().Get(time) or "edgeAndCorner")
    face_varying = str(mesh.GetFaceVaryingLinearInterpolationAttr().Get(time) or "cornersPlus1")
    for what, token, setter in (("interpolateBoundary", boundary, "interpolate_boundary"),
                                ("faceVaryingLinearInterpolation", face_varying, "face_varying_linear_interpolation")):
        try:
            setattr(cage, setter, token)
        except ValueError:
            problems.warn(path, f"{what} '{token}' is not one USD defines: its fallback applies")
    cage.smooth_triangles = str(mesh.GetTriangleSubdivisionRuleAttr().Get(time) or "") == "smooth"
    cage.left_handed = mesh.GetOrientationAttr().Get(time) == UsdGeom.Tokens.leftHanded
    cage.hole_indices = values(mesh.GetHoleIndicesAttr(), np.int64)
    cage.crease_indices = values(mesh.GetCreaseIndicesAttr(), np.int64)
    cage.crease_lengths = values(mesh.GetCreaseLengthsAttr(), np.int64)
    cage.crease_sharpnesses = values(mesh.GetCreaseSharpnessesAttr(), np.float32)
    cage.corner_indices = values(mesh.GetCornerIndicesAttr(), np.int64)
    cage.corner_sharpnesses = values(mesh.GetCornerSharpnessesAttr(), np.float32)
    for attribute in (mesh.GetCreaseIndicesAttr(), mesh.GetCornerIndicesAttr(), mesh.GetCreaseSharpnessesAttr()):
        if attribute.ValueMightBeTimeVarying():
            problems.warn(path, f"its {attribute.GetName()} are animated; snell keeps those of time code "
                                f"{time.GetValue():g}")
    return cage


def read_primvar(prim: Usd.Prim, attribute: Usd.Attribute, interpolation: str, indices: Optional[np.ndarray],
                 topology: Topology, time: Usd.TimeCode, problems: Problems, what: str) -> Optional[Primvar]:
    """Element ids of a normals or st primvar per face-vertex; None (with a warning) if they do not fit."""
    values = attribute.Get(time)
    count = 0 if values is None else len(values)
    expected = {UsdGeom.Tokens.vertex: topology.point_count, UsdGeom.Tokens.varying: topology.point_count,
                UsdGeom.Tokens.faceVarying: len(topology.face_points), UsdGeom.Tokens.uniform: topology.face_count,
                UsdGeom.Tokens.constant: 1}.get(interpolation)
    if expected is None:
        problems.warn(prim.GetPath(), f"{what} has interpolation '{interpolation}', which a mesh cannot use: ignored")
        return None
    sized = len(indices) if indices is not None else count
    if sized != expected or count == 0 or (indices is not None and len(indices) and
                                           (indices.min() < 0 or indices.max() >= count)):
        holds = f"{sized} indices into {count} values" if indices is not None else f"{count} values"
        problems.warn(prim.GetPath(), f"{what} ({interpolation}) has {holds}; the mesh needs {expected}: ignored")
        return None
    if interpolation in _PER_POINT:
        corner_ids, point_ids = topology.face_points, np.arange(topology.point_count)
    elif interpolation == UsdGeom.Tokens.faceVarying:
        corner_ids, point_ids = np.arange(len(topology.face_points)), None
    elif interpolation == UsdGeom.Tokens.uniform:
        corner_ids, point_ids = topology.face_of_corner(), None
    else:
        corner_ids, point_ids = np.zeros(len(topology.face_points), np.int64), np.zeros(topology.point_count, np.int64)
    if indices is not None:
        corner_ids = indices[corner_ids]
        point_ids = None if point_ids is None else indices[point_ids]
    varying = attribute.ValueMightBeTimeVarying()
    return Primvar(attribute, interpolation, corner_ids, point_ids, varying)


def read_normals(mesh: UsdGeom.Mesh, topology: Topology, time: Usd.TimeCode, problems: Problems) -> Optional[Primvar]:
    """primvars:normals, else normals; None: computed from the points."""
    primvar = UsdGeom.PrimvarsAPI(mesh.GetPrim()).GetPrimvar("normals")
    if primvar and primvar.HasAuthoredValue():
        indices = np.asarray(primvar.GetIndices(time), np.int64) if primvar.IsIndexed() else None
        return read_primvar(mesh.GetPrim(), primvar.GetAttr(), primvar.GetInterpolation(), indices, topology, time,
                            problems, "primvars:normals")
    attribute = mesh.GetNormalsAttr()
    if attribute.HasAuthoredValue():
        return read_primvar(mesh.GetPrim(), attribute, mesh.GetNormalsInterpolation(), None, topology, time,
                            problems, "normals")
    return None


def smooth_normals(points: np.ndarray, topology: Topology) -> np.ndarray:
    """Per point, the sum of its faces' area-weighted normals, made unit length (float32)."""
    tri_points = topology.face_points[topology.triangles]
    p = points.astype(np.float64, copy=False)
    face_normals = np.cross(p[tri_points[:, 1]] - p[tri_points[:, 0]], p[tri_points[:, 2]] - p[tri_points[:, 0]])
    at = tri_points.reshape(-1)
    summed = np.empty((topology.point_count, 3))
    for axis in range(3):
        summed[:, axis] = np.bincount(at, weights=np.repeat(face_normals[:, axis], 3), minlength=topology.point_count)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    summed = np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)
    summed[length[:, 0] == 0] = (0.0, 0.0, 1.0)  # a point no face reaches: any unit vector
    return summed.astype(np.float32)


class MeshSource:
    """One mesh prim read for snell (or one prototype's mesh, shared by instances): its parts and its pose."""

    def __init__(self, mesh: UsdGeom.Mesh, topology: Topology, normals: Optional[Primvar],
                 skin: Optional[Skin], problems: Problems, cage: Optional[Subdivision] = None) -> None:
        self.mesh = mesh
        self.path = str(mesh.GetPath())
        self.topology = topology
        self.cage = cage  #: the whole cage's subdivision, when the mesh is sent as one
        self.normals = None if cage is not None else normals
        self.skin = skin
        self.problems = problems
        self.parts: list[Part] = []
        self.points_attribute = mesh.GetPointsAttr()
        self.deforms = (self.points_attribute.ValueMightBeTimeVarying() or bool(normals and normals.varying)
                        or bool(skin and skin.animated and skin.deforms_points))
        self._rest: Optional[Vt.Vec3fArray] = None  # points that do not vary, read once
        self._cage_parts: list[tuple] = []  # add_part's arguments for each cage part, to make them again as polygons
        self._cage_st: Optional[Usd.Attribute] = None  # the texture coordinates the cage's first material reads
        self._authored_holes = np.zeros(0, np.int64)  # the cage's own hole_indices, before unclaimed faces join them
        self._miscounted = False

    @property
    def skinned_normals(self) -> bool:
        return bool(self.normals is not None and self.skin is not None and self.skin.skinned and not self.skin.rigid)

    def add_part(self, name: str, triangles: np.ndarray, material: int, st: Optional[Primvar],
                 st_values: Optional[np.ndarray], corner_uvs: Optional[np.ndarray] = None) -> Part:
        """A part of these triangles, with its vertices split where its normals or st differ; with corner_uvs
        ((T * 3, 2): a colour atlas's, _colours.py) every triangle has its own three vertices, with those UVs.
        A cage has one part, the whole cage, whose faces each carry their material: snell refines it once."""
        t = self.topology
        if self.cage is not None:
            self._cage_parts.append((name, triangles, material, st, st_values))
            return self._add_cage_part(name, triangles, material, st, st_values)
        corners = t.triangles[triangles]
        normal_per_point = self.normals is None or self.normals.point_ids is not None
        st_per_point = st is None or st.point_ids is not None
        part = Part(name, triangles, material)
        if corner_uvs is not None:
            part.vertex_point = t.face_points[corners].reshape(-1)
            part.vertex_normal = (part.vertex_point if self.normals is None else
                                  self.normals.corner_ids[corners].reshape(-1))
            part.indices = np.arange(3 * len(triangles), dtype=np.uint32).reshape(-1, 3)
            part.uvs = np.ascontiguousarray(corner_uvs, np.float32)
            self.parts.append(part)
            return part
        if normal_per_point and st_per_point:
            corner_points = t.face_points[corners]
            used = np.unique(corner_points)
            part.identity = len(used) == t.point_count
            part.vertex_point = used
            local = corner_points if part.identity else np.searchsorted(used, corner_points)
            part.vertex_normal = used if self.normals is None else self.normals.point_ids[used]
            vertex_st = None if st is None else st.point_ids[used]
        else:
            columns = [t.face_points[corners].reshape(-1)]
            columns.append((t.face_points if self.normals is None else self.normals.corner_ids)[corners].reshape(-1))
            if st is not None:
                columns.append(st.corner_ids[corners].reshape(-1))
            unique, inverse = np.unique(np.stack(columns, axis=1), axis=0, return_inverse=True)
            local = inverse.reshape(-1, 3)
            part.vertex_point, part.vertex_normal = unique[:, 0], unique[:, 1]
            vertex_st = unique[:, 2] if st is not None else None
        part.indices = np.ascontiguousarray(local, np.uint32)
        if vertex_st is not None:
            uv = st_values[vertex_st].astype(np.float64)
            uv[:, 1] = 1.0 - uv[:, 1]  # USD's st (0, 0) is the image's lower left; snell's v runs down
            part.uvs = uv.astype(np.float32)
        self.parts.append(part)
        return part

    def drop_cage(self, normals: Optional[Primvar]) -> None:
        """Draws the cage as the polygons it is (a subdivision level of 0), with these normals: its parts made
        again, in the same order."""
        parts, self._cage_parts = self._cage_parts, []
        self.cage, self.normals, self.parts = None, normals, []
        for arguments in parts:
            self.add_part(*arguments)

    def _add_cage_part(self, name: str, triangles: np.ndarray, material: int, st: Optional[Primvar],
                       st_values: Optional[np.ndarray]) -> Part:
        t = self.topology
        faces = np.unique(t.triangle_face[triangles])
        if self.parts:  # another material's faces of the cage: the one part takes them
            part = self.parts[0]
            part.triangles = np.concatenate([part.triangles, triangles])
            part.face_materials[faces] = material
            part.cage.hole_indices = self._cage_holes(part.face_materials)
            if (st is None) != (part.uvs is None) or (st is not None and st.attribute != self._cage_st):
                self.problems.warn(name, "its material reads other texture coordinates than the cage's first "
                                         "material; the cage carries one set, the first material's")
            return part
        cage = self.cage  # the one part's: its holes grow with the faces no material claims
        self._authored_holes = np.asarray(cage.hole_indices, np.int64)
        part = Part(self.path, triangles, material, cage=cage, identity=True)
        part.face_materials = np.full(t.face_count, -2, np.int32)  # -2: no material's face, a hole
        part.face_materials[faces] = material
        cage.hole_indices = self._cage_holes(part.face_materials)
        part.vertex_point = np.arange(t.point_count)
        part.vertex_normal = part.vertex_point
        part.indices = np.ascontiguousarray(t.face_points, np.uint32)
        self._cage_st = None if st is None else st.attribute
        if st is not None:
            per_point = st.point_ids is not None
            uv = st_values[st.point_ids].astype(np.float64) if per_point else st_values.astype(np.float64)
            uv[:, 1] = 1.0 - uv[:, 1]  # USD's st (0, 0) is the image's lower left; snell's v runs down
            part.uvs = uv.astype(np.float32)
            if not per_point:
                cage.uv_indices = st.corner_ids
        self.parts.append(part)
        return part

    def _cage_holes(self, face_materials: np.ndarray) -> np.ndarray:
        """The cage's holes: its authored ones and the faces no material claims."""
        holes = np.union1d(np.nonzero(face_materials == -2)[0], self._authored_holes)
        return holes[(holes >= 0) & (holes < self.topology.face_count)]

    def _points(self, time: Usd.TimeCode) -> Vt.Vec3fArray:
        if self._rest is not None:
            return self._rest
        points = self.points_attribute.Get(time)
        if not self.points_attribute.ValueMightBeTimeVarying():
            self._rest = points
        return points

    def pose(self, time: Usd.TimeCode, frame: SkelFrame) -> Optional[Pose]:
        """Points and normals at the time code; None (with a warning) when the points no longer fit the faces."""
        rest = self._points(time)
        if rest is None or len(rest) != self.topology.point_count:
            count = 0 if rest is None else len(rest)
            if not self._miscounted:  # said once: a changing point count would say it every frame
                self._miscounted = True
                self.problems.warn(self.path, f"has {count} points at time code {time.GetValue():g}, not the "
                                              f"{self.topology.point_count} its faces use: not updated there")
            return None
        basis = None
        if self.skin is not None and self.skin.deforms_points:
            points, basis = self.skin.deform(rest, frame, linear_parts=self.skinned_normals)
        else:
            points = np.asarray(rest)
        if self.cage is not None:  # snell makes a cage's normals
            return Pose(points, np.zeros((1, 3), np.float32), unit=True)
        if self.normals is None:
            return Pose(points, smooth_normals(points, self.topology), unit=True)
        values = self.normals.attribute.Get(time)
        normals = np.asarray(values, np.float32) if values is not None else np.zeros((1, 3), np.float32)
        return Pose(points, normals, basis)

    def write(self, part: Part, pose: Pose, positions: np.ndarray, normals: np.ndarray) -> None:
        """The part's vertices of a pose, into snell's arrays (mapped memory, or fresh ones)."""
        if part.identity:
            np.copyto(positions, pose.points)
        else:
            np.take(pose.points, part.vertex_point, axis=0, out=positions)
        if part.cage is not None:
            normals.fill(0.0)
            return
        if pose.normal_basis is None and pose.unit:
            np.take(pose.normals, part.vertex_normal, axis=0, out=normals)
            return
        n = pose.normals[part.vertex_normal].astype(np.float64)
        if pose.normal_basis is not None:
            n = np.einsum("vij,vj->vi", pose.normal_basis[part.vertex_point], n)
        length = np.linalg.norm(n, axis=1, keepdims=True)
        np.copyto(normals, np.divide(n, length, out=np.zeros_like(n), where=length > 0), casting="unsafe")


def material_subsets(prim: Usd.Prim, topology: Topology, time: Usd.TimeCode,
                     problems: Problems) -> list[tuple[Usd.Prim, np.ndarray]]:
    """The mesh's materialBind GeomSubsets as (subset prim, triangle ids); a face claimed twice stays with the first."""
    subsets = UsdShade.MaterialBindingAPI(prim).GetMaterialBindSubsets()
    out = []
    claimed = np.zeros(topology.face_count, bool)
    for subset in subsets:
        if subset.GetElementTypeAttr().Get() != UsdGeom.Tokens.face:
            problems.warn(subset.GetPath(), "a materialBind subset of non-face elements: ignored")
            continue
        faces = np.asarray(subset.GetIndicesAttr().Get(time) or [], np.int64)
        faces = faces[(faces >= 0) & (faces < topology.face_count)]
        mine = np.zeros(topology.face_count, bool)
        mine[faces] = True
        if (mine & claimed).any():
            problems.warn(subset.GetPath(), f"{int((mine & claimed).sum())} of its faces belong to an earlier "
                                            "materialBind subset, which keeps them")
            mine &= ~claimed
        claimed |= mine
        out.append((subset.GetPrim(), np.nonzero(mine[topology.triangle_face])[0]))
    rest = np.nonzero(~claimed[topology.triangle_face])[0]
    out.insert(0, (prim, rest))
    return [(p, tris) for p, tris in out if len(tris)]
