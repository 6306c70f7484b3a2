"""UsdSkel skinning and blend shapes, evaluated by USD's own code (UsdSkel.SkinningQuery, BlendShapeQuery).

Skinned points come out in the skeleton's space: the mesh's own transform is
not theirs, the skeleton prim's local-to-world places them. usd-core's Python
has ComputeSkinnedPoints but not ComputeSkinnedNormals, so authored normals
are skinned with the same call: skinning is affine per point (its joint
weights do not depend on the position), so skinning p + s·e_k and
subtracting skin(p) gives each point's linear part A exactly; normals then
take A's cofactor (det · A^-T, sign-corrected), as snell's own deform pass
does for glTF skins (shaders/comp/deform.comp).
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from pxr import Usd, UsdSkel, Vt

from ._problems import Problems


class SkelFrame:
    """The skeletons' skinning transforms and blend shape weights at one time code, each computed once."""

    def __init__(self, time: Usd.TimeCode) -> None:
        self.time = time
        self._xforms: dict[str, Vt.Matrix4dArray] = {}
        self._weights: dict[str, Vt.FloatArray] = {}

    def skinning_transforms(self, skeleton: UsdSkel.SkeletonQuery) -> Vt.Matrix4dArray:
        key = str(skeleton.GetPrim().GetPath())
        if key not in self._xforms:
            self._xforms[key] = skeleton.ComputeSkinningTransforms(self.time)
        return self._xforms[key]

    def blend_shape_weights(self, skeleton: UsdSkel.SkeletonQuery) -> Optional[Vt.FloatArray]:
        animation = skeleton.GetAnimQuery()
        if not animation:
            return None
        key = str(animation.GetPrim().GetPath())
        if key not in self._weights:
            self._weights[key] = animation.ComputeBlendShapeWeights(self.time)
        return self._weights[key]


class Skin:
    """One skinned mesh: its skinning and blend shape queries, and whether they move over time."""

    def __init__(self, prim: Usd.Prim, query: UsdSkel.SkinningQuery, skeleton: UsdSkel.SkeletonQuery,
                 problems: Problems) -> None:
        self.path = str(prim.GetPath())
        self.query = query
        self.skeleton = skeleton
        self.problems = problems
        self.rigid = query.IsRigidlyDeformed()
        self.skinned = query.HasJointInfluences()
        animation = skeleton.GetAnimQuery()
        joints_move = bool(animation) and animation.JointTransformsMightBeTimeVarying()
        weights_move = bool(animation) and animation.BlendShapeWeightsMightBeTimeVarying()
        self.blend: Optional[UsdSkel.BlendShapeQuery] = None
        if query.HasBlendShapes() and animation:
            self.blend = UsdSkel.BlendShapeQuery(UsdSkel.BindingAPI(prim))
            # Static per mesh: which points each shape moves, and by how much.
            self._point_indices = self.blend.ComputeBlendShapePointIndices()
            self._offsets = self.blend.ComputeSubShapePointOffsets()
            for i in range(self.blend.GetNumBlendShapes()):
                shape = self.blend.GetBlendShape(i)
                if shape.GetNormalOffsetsAttr().HasAuthoredValue():
                    problems.warn(shape.GetPath(), "normalOffsets are not applied (usd-core's Python has no "
                                                   "ComputeDeformedNormals): the mesh keeps its normals")
        self.animated = (self.skinned and joints_move) or (self.blend is not None and weights_move)
        self.deforms_points = (self.skinned and not self.rigid) or self.blend is not None

    @property
    def skeleton_prim(self) -> Usd.Prim:
        return self.skeleton.GetPrim()

    def _blend(self, points: Vt.Vec3fArray, frame: SkelFrame) -> None:
        weights = frame.blend_shape_weights(self.skeleton)
        if weights is None or self.blend is None:
            return
        mapper = self.query.GetBlendShapeMapper()
        if mapper and not mapper.IsNull() and not mapper.IsIdentity():
            weights = mapper.Remap(weights)
        sub_weights, shape_indices, sub_indices = self.blend.ComputeSubShapeWeights(weights)
        self.blend.ComputeDeformedPoints(sub_weights, shape_indices, sub_indices, self._point_indices,
                                         self._offsets, points)

    def deform(self, rest: Vt.Vec3fArray, frame: SkelFrame,
               linear_parts: bool = False) -> tuple[np.ndarray, Optional[np.ndarray]]:
        """The points posed at the frame (skeleton space unless rigid), and per point the normals' 3x3
        (cofactor) matrix when asked for (None for rigid meshes: their transform turns them)."""
        points = Vt.Vec3fArray(rest)
        self._blend(points, frame)
        if not self.skinned or self.rigid:
            return np.asarray(points), None
        xforms = frame.skinning_transforms(self.skeleton)
        shaped = np.asarray(points).copy() if linear_parts else None
        if not self.query.ComputeSkinnedPoints(xforms, points, frame.time):
            self.problems.warn(self.path, "UsdSkel could not skin the points (influences and points disagree): "
                                          "drawn unskinned")
            return np.asarray(points), None
        posed = np.asarray(points)
        if not linear_parts:
            return posed, None
        # Skinning is affine per point: differences of skinned points give its linear part exactly.
        # A step as large as the coordinates keeps float32 cancellation at ~1e-7 of the result.
        step = max(1.0, float(np.abs(shaped).max(initial=0.0)), float(np.abs(posed).max(initial=0.0)))
        columns = []
        for axis in range(3):
            moved = shaped.copy()
            moved[:, axis] += step
            probe = Vt.Vec3fArray.FromNumpy(moved)
            self.query.ComputeSkinnedPoints(xforms, probe, frame.time)
            columns.append((np.asarray(probe, np.float64) - posed) / step)
        a0, a1, a2 = columns
        c0, c1, c2 = np.cross(a1, a2), np.cross(a2, a0), np.cross(a0, a1)
        sign = np.where(np.einsum("ij,ij->i", a0, c0) < 0.0, -1.0, 1.0)[:, None, None]
        return posed, np.stack([c0, c1, c2], axis=2) * sign

    def rigid_transform(self, frame: SkelFrame) -> Optional[np.ndarray]:
        """A rigidly skinned mesh's transform to skeleton space (4x4, column vectors), or None if not rigid."""
        if not (self.skinned and self.rigid):
            return None
        xform = self.query.ComputeSkinnedTransform(frame.skinning_transforms(self.skeleton), frame.time)
        if xform is None:
            self.problems.warn(self.path, "UsdSkel could not compute the rigid skinning transform: drawn unskinned")
            return None
        return np.array(xform).T
