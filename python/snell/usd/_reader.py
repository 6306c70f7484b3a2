"""A USD stage read for snell at a time code: its meshes, materials, lights and cameras, and what moves.

Nothing here needs a GPU: `snell-usd info` stops here, and snell.usd.Stage
builds a scene and a renderer from it. The stage's world is mapped to
snell's (glTF's: +Y up, metres) by one matrix, to_snell: metersPerUnit as a
scale, and a Z-up stage turned so its +Z is snell's +Y ((x, y, z) ->
(x, z, -y)). Instance transforms carry it, so points stay in their own units
and a static prim is never touched again.
"""

from __future__ import annotations

import math
import os
import time as clock
from dataclasses import dataclass
from typing import Callable, Optional, Union

import numpy as np
from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdLux, UsdSkel

from .. import Instance, Light, Material, Mesh
from ._cameras import CameraState, camera_state
from ._colours import colour_atlas, mesh_colours
from ._dome import Dome, read_dome
from ._gprims import TYPES as GPRIM_TYPES
from ._gprims import GprimMesh
from ._lights import LightRecord, read_light, unsupported_light
from ._materials import MaterialRecord, MaterialTable
from ._meshes import (MeshSource, Part, Pose, Topology, material_subsets, read_normals, read_primvar,
                      read_subdivision, read_topology)
from ._mtlx import referenced_document
from ._problems import Problems, StageError
from ._screen import (DEFAULT_TRIANGLE_BUDGET, MAX_AUTO_LEVEL, REFINED_VERTEX_BUDGET, CageCounts, Screen,
                      fit_budget, level_for, mean_edge, screen_of, world_box)
from ._skinning import SkelFrame, Skin

GEOMETRY_PURPOSES = ("render", "proxy")
_Z_UP_TO_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


@dataclass
class ReadOptions:
    """How a stage is read."""

    purpose: str = "preview"  #: material purpose: preview, full or all (the all-purpose binding only)
    geometry_purpose: str = "render"  #: the purpose drawn beside default: render or proxy (guide never)
    meters_per_unit: Optional[float] = None  #: overrides the stage's metersPerUnit
    load_textures: bool = True
    strict: bool = False  #: a broken stage (mesh without points, missing texture) raises StageError
    missing_textures_fail: bool = False  #: a missing texture file is an error, not a warning with its fallback
    #: levels a subdivision surface's cage is refined by on the GPU (0: draw cages); None: each cage's own,
    #: sized to the view (_screen.py), within the triangle budget
    subdivision_level: Optional[int] = None
    image_size: tuple[int, int] = (1920, 1080)  #: the picture levels are sized for
    camera: Union[None, int, str] = None  #: the camera they are sized for (None: the first, or the framed view)
    triangle_budget: int = DEFAULT_TRIANGLE_BUDGET  #: refined triangles before sized levels are lowered


@dataclass
class Placement:
    """One placed copy of a mesh source: its snell instances (a part each) and where they are."""

    prim: Usd.Prim  #: the prim whose local-to-world places it (the skeleton, for a skinned mesh)
    source: MeshSource
    instances: list[int]
    varying: bool
    matrix: np.ndarray  #: current mesh-to-snell-world, 4x4, column vectors
    rigid_skin: Optional[Skin] = None
    #: a PointInstancer's instance: its matrix at a time code (None where the instancer no longer fits)
    placed: Optional[Callable[[Usd.TimeCode], Optional[np.ndarray]]] = None


@dataclass
class Frame:
    """The moving part of the stage at one time code, evaluated, not yet sent to snell."""

    time: float
    poses: list[tuple[MeshSource, Pose]]
    transforms: list[tuple[Placement, np.ndarray]]
    seconds: float = 0.0  #: the USD evaluation's wall time


def transform_might_vary(prim: Usd.Prim) -> bool:
    """Whether the prim's local-to-world may change over time (any xformable ancestor up to a reset)."""
    while prim and not prim.IsPseudoRoot():
        xformable = UsdGeom.Xformable(prim)
        if xformable:
            if xformable.TransformMightBeTimeVarying():
                return True
            if xformable.GetResetXformStack():
                return False
        prim = prim.GetParent()
    return False


class StageContents:
    """A stage as snell sees it at a time code (see the module's docstring)."""

    def __init__(self, path: Union[str, os.PathLike], time: Optional[float] = None,
                 options: Optional[ReadOptions] = None) -> None:
        started = clock.perf_counter()
        self.options = options or ReadOptions()
        if self.options.geometry_purpose not in GEOMETRY_PURPOSES:
            raise ValueError(f"geometry purpose must be render or proxy, got '{self.options.geometry_purpose}'")
        self.path = os.fspath(path)
        self.problems = Problems(self.path, self.options.strict, self.options.missing_textures_fail)
        with self.problems.usd_diagnostics():  # what USD says while reading is this stage's warnings
            self._read(time)
        self.load_seconds = clock.perf_counter() - started

    def _read(self, time: Optional[float]) -> None:
        self.stage = _open_stage(self.path)
        stage = self.stage
        if not hasattr(Tf, "DiagnosticTrap"):  # with it, USD's own report of these is kept (usd_diagnostics)
            for error in getattr(stage, "GetCompositionErrors", lambda: [])():
                self.problems.warn("", f"composition: {error}")
        self.has_range = stage.HasAuthoredTimeCodeRange()
        self.start, self.end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
        if self.has_range and self.start > self.end:
            self.problems.warn("", f"startTimeCode {self.start:g} is after endTimeCode {self.end:g}: snell takes "
                                   f"the range {self.end:g}-{self.start:g}, and opens at the start time code")
            self.range_lo, self.range_hi = self.end, self.start
        else:
            self.range_lo, self.range_hi = self.start, self.end
        self.time_codes_per_second = stage.GetTimeCodesPerSecond()
        self.time = float(self.start if time is None else time)
        if not self.in_range(self.time):
            self.problems.warn("", f"time code {self.time:g} is outside the stage's range {self.start:g}-{self.end:g}: "
                                   "USD holds the nearest samples")
        self.meters_per_unit_authored = UsdGeom.StageHasAuthoredMetersPerUnit(stage)
        self.meters_per_unit = float(self.options.meters_per_unit or UsdGeom.GetStageMetersPerUnit(stage))
        if not self.meters_per_unit_authored and self.options.meters_per_unit is None:
            self.problems.warn("", "metersPerUnit is not authored: USD's fallback, 0.01 (centimetres), applies")
        self.up_axis = str(UsdGeom.GetStageUpAxis(stage))
        if self.up_axis not in ("Y", "Z"):
            self.problems.warn("", f"upAxis '{self.up_axis}' of {stage.GetRootLayer().identifier} is neither Y nor "
                                   "Z (UsdGeom allows only those): read as Y")
        rotate = _Z_UP_TO_Y_UP if self.up_axis == "Z" else np.eye(4)
        self.to_snell = np.diag([self.meters_per_unit] * 3 + [1.0]) @ rotate

        self.materials = MaterialTable(Usd.TimeCode(self.time), self.options.purpose, self.problems,
                                       self.options.load_textures)
        self.sources: list[MeshSource] = []
        self.placements: list[Placement] = []
        self.lights: list[LightRecord] = []
        self.dome: Optional[Dome] = None  #: the DomeLight that is snell's environment
        self.cameras: list[Usd.Prim] = []
        self.skipped: dict[str, list[str]] = {}
        self._skel_cache = UsdSkel.Cache()
        self._xform_cache = UsdGeom.XformCache(Usd.TimeCode(self.time))
        self._first_screen: Optional[Screen] = None
        self._bbox_cache = UsdGeom.BBoxCache(Usd.TimeCode(self.time), [UsdGeom.Tokens.default_,
                                                                        self.options.geometry_purpose],
                                             useExtentsHint=True)
        self._topologies: dict[Sdf.Path, Optional[Topology]] = {}
        self._shared: dict[tuple, MeshSource] = {}
        self._initial: dict[int, Pose] = {}
        self._instance_count = 0
        self._traverse()
        self._size_subdivision()
        self.dynamic_sources = [s for s in self.sources if s.deforms]
        self.dynamic_placements = [p for p in self.placements if p.varying]

    # ------------------------------------------------------------------ detail

    def _size_subdivision(self) -> None:
        """Each cage's level from its mean edge on screen (_screen.py), then lowered to the triangle budget with
        one warning naming the meshes; a level given fixes them all."""
        cages = [s for s in self.sources if s.cage is not None]
        if not cages or self.options.subdivision_level is not None:
            return
        time = Usd.TimeCode(self.time)
        screen = self._screen_ahead()  # the view the gprims were sized for: one view for all detail
        points = {id(s): np.asarray(s.points_attribute.Get(time) or [], np.float64).reshape(-1, 3) for s in cages}
        near: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}  # each cage's box over its placements
        for placement in self.placements:
            source = placement.source
            box = world_box(points[id(source)], placement.matrix) if source.cage is not None else None
            if box is not None:
                seen = near.get(id(source))
                near[id(source)] = box + (placement.matrix,) if seen is None else (
                    np.minimum(seen[0], box[0]), np.maximum(seen[1], box[1]), seen[2])
        sizes: dict[int, tuple[CageCounts, int]] = {}
        for source in cages:
            if id(source) not in near:
                continue
            box_lo, box_hi, matrix = near[id(source)]
            edge = mean_edge(points[id(source)] @ matrix[:3, :3].T, source.topology.face_counts,
                             source.topology.face_points)
            counts = CageCounts.of(source.topology.face_counts, source.topology.face_points, source.cage.scheme)
            sizes[id(source)] = (counts, level_for(screen.pixels(edge, box_lo, box_hi)))
        lowered = fit_budget(sizes, self.options.triangle_budget, REFINED_VERTEX_BUDGET)
        for source in cages:
            level = lowered.get(id(source), sizes[id(source)][1] if id(source) in sizes else MAX_AUTO_LEVEL)
            if level == 0:
                source.drop_cage(read_normals(source.mesh, source.topology, time, self.problems))
                self._initial[id(source)] = source.pose(time, SkelFrame(time))
                continue
            source.cage.level = level  # the cage's one part holds this Subdivision itself
        if lowered:
            paths = {id(source): source.path for source in cages}
            named = ", ".join(sorted(f"{paths[key]} ({level})" for key, level in lowered.items()))
            self.problems.warn("", f"{len(lowered)} subdivision surfaces refined fewer levels than the view asks "
                                   f"(0: the cage drawn as polygons), to keep the scene within "
                                   f"{self.options.triangle_budget:,} refined triangles (--subdiv-budget) and "
                                   f"{REFINED_VERTEX_BUDGET:,} refined vertices (refine tables Vulkan binds on any "
                                   f"device): {named}")

    def _pixels_of(self, prim: Usd.Prim) -> Callable[[float], float]:
        """How many pixels a length in prim's own units spans where prim comes nearest the camera, in the view
        found ahead of the traversal (_screen_ahead)."""
        screen = self._screen_ahead()
        box = _snell_box(self.to_snell, self._bbox_cache.ComputeWorldBound(prim).ComputeAlignedRange())
        world = self.to_snell @ np.array(self._xform_cache.GetLocalToWorldTransform(prim)).T
        scale = float(np.mean(np.linalg.norm(world[:3, :3], axis=0)))
        if box is None:
            return lambda length: math.nan
        return lambda length: screen.pixels(length * scale, *box)

    def _screen_ahead(self) -> Screen:
        """The view a gprim's detail is sized for while the stage is still being read: the camera asked for
        (else the stage's first) or the framed view of USD's own bounds of the stage."""
        if self._first_screen is None:
            time = Usd.TimeCode(self.time)
            predicate = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
            cameras = [p for p in Usd.PrimRange(self.stage.GetPseudoRoot(), predicate) if p.IsA(UsdGeom.Camera)]
            which = self.options.camera
            prim = None
            if isinstance(which, str) and Sdf.Path.IsValidPathString(which):
                prim = self.stage.GetPrimAtPath(which)
            elif isinstance(which, int) and 0 <= which < len(cameras):
                prim = cameras[which]
            if not (prim and prim.IsA(UsdGeom.Camera)):
                prim = cameras[0] if cameras else None
            camera = (camera_state(prim, time, self.to_snell, self.meters_per_unit, self._xform_cache)
                      if prim is not None else None)
            box = _snell_box(self.to_snell, self._bbox_cache.ComputeWorldBound(self.stage.GetPseudoRoot())
                             .ComputeAlignedRange())
            lo, hi = box if box is not None else (np.full(3, np.inf), np.full(3, -np.inf))
            self._first_screen = screen_of(camera, lo, hi, *self.options.image_size)
        return self._first_screen

    # ------------------------------------------------------------------ traversal

    def _skip(self, what: str, prim: Usd.Prim) -> None:
        self.skipped.setdefault(what, []).append(str(prim.GetPath()))

    def _traverse(self) -> None:
        time = Usd.TimeCode(self.time)
        predicate = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
        walk = iter(Usd.PrimRange(self.stage.GetPseudoRoot(), predicate))
        excluded = {"guide", "render", "proxy"} - {self.options.geometry_purpose}
        for prim in walk:
            if prim.IsPseudoRoot():
                continue
            imageable = UsdGeom.Imageable(prim)
            if imageable:
                visibility = imageable.GetVisibilityAttr()
                if visibility.ValueMightBeTimeVarying():
                    self.problems.warn(prim.GetPath(), "its visibility is animated; snell reads it once, at time "
                                                       f"code {self.time:g}")
                if visibility.Get(time) == UsdGeom.Tokens.invisible:
                    self._skip("invisible", prim)
                    walk.PruneChildren()
                    continue
            self._unhonoured_draw_mode(prim)
            if prim.IsA(UsdSkel.Root):
                self._skel_cache.Populate(UsdSkel.Root(prim), predicate)
            if prim.IsA(UsdGeom.Camera):
                self.cameras.append(prim)
            elif prim.IsA(UsdGeom.PointInstancer):
                self._add_instancer(prim, time, excluded)
                walk.PruneChildren()  # its prototypes are drawn where it places them, not where they stand
            elif prim.IsA(UsdGeom.Mesh) or prim.GetTypeName() in GPRIM_TYPES:
                purpose = imageable.ComputePurpose()
                if purpose in excluded:
                    self._skip(f"purpose {purpose}", prim)
                    continue
                if prim.HasAPI(UsdLux.MeshLightAPI):
                    self.problems.warn(prim.GetPath(), "a mesh light: snell draws the mesh but not its light")
                self._add_mesh(prim, time)
            elif prim.HasAPI(UsdLux.LightAPI) or prim.IsA(UsdLux.BoundableLightBase) or \
                    prim.IsA(UsdLux.NonboundableLightBase):
                if prim.IsA(UsdLux.DomeLight) or prim.IsA(UsdLux.DomeLight_1):
                    self._add_dome(prim, time)
                elif prim.IsA(UsdLux.PortalLight) or prim.IsA(UsdLux.GeometryLight):
                    self.lights.append(unsupported_light(prim, self.problems))
                else:
                    self.lights.append(read_light(prim, time, self.to_snell, self._xform_cache, self.problems))
            elif prim.IsA(UsdGeom.Gprim):
                self._skip(prim.GetTypeName(), prim)
        for kind, paths in self.skipped.items():
            if kind in ("invisible",) or kind.startswith("purpose"):
                continue
            first = ", ".join(paths[:3]) + (", ..." if len(paths) > 3 else "")
            self.problems.warn("", f"{len(paths)} {kind} prim(s) skipped: snell reads UsdGeomMesh and "
                                   f"{', '.join(GPRIM_TYPES)} ({first})")

    def _add_dome(self, prim: Usd.Prim, time: Usd.TimeCode) -> None:
        """The first visible dome is snell's environment (_dome.py); snell has one, so others are skipped."""
        kind = prim.GetTypeName()
        if self.dome is not None:
            self.problems.warn(prim.GetPath(), f"a second {kind}: snell has one environment, {self.dome.path}'s: "
                                               "skipped")
            self.lights.append(LightRecord(str(prim.GetPath()), kind, None, "skipped"))
            return
        self.dome = read_dome(prim, time, self.to_snell, self.up_axis, self._xform_cache, self.problems,
                              self.options.load_textures)
        self.lights.append(LightRecord(self.dome.path, kind, None, self.dome.summary))

    def _unhonoured_draw_mode(self, prim: Usd.Prim) -> None:
        """model:drawMode asks for a stand-in (bounds, cards, origin); snell draws the model's geometry."""
        attribute = prim.GetAttribute("model:drawMode")
        if attribute and attribute.HasAuthoredValue():
            mode = str(attribute.Get())
            if mode not in ("default", "inherited"):
                self.problems.warn(prim.GetPath(), f"model:drawMode is '{mode}', which snell does not honour: the "
                                                   "model's own geometry is drawn")

    def _missing_materials(self, prim: Usd.Prim) -> None:
        """A material:binding (of any purpose) on the prim or an ancestor whose target is not a prim."""
        stage = prim.GetStage()
        while prim and not prim.IsPseudoRoot():
            for relationship in prim.GetRelationships():
                name = relationship.GetName()
                if not name.startswith("material:binding") or name.startswith("material:binding:collection"):
                    continue
                for target in relationship.GetTargets():
                    if not stage.GetPrimAtPath(target).IsValid() and referenced_document(stage, target) is None:
                        self.problems.warn(prim.GetPath(), f"{name} targets {target}, which does not exist: "
                                                           "USD binds nothing there")
            prim = prim.GetParent()

    def _skin_of(self, prim: Usd.Prim) -> Optional[Skin]:
        query = self._skel_cache.GetSkinningQuery(prim)
        if not query or not (query.HasJointInfluences() or query.HasBlendShapes()):
            return None
        skeleton = UsdSkel.BindingAPI(prim).GetInheritedSkeleton()
        skel_query = self._skel_cache.GetSkelQuery(skeleton) if skeleton else None
        if not skel_query:
            self.problems.warn(prim.GetPath(), "has joint influences but no skeleton is bound: drawn unskinned")
            return None
        return Skin(prim, query, skel_query, self.problems)

    def _add_instancer(self, prim: Usd.Prim, time: Usd.TimeCode, excluded: set[str]) -> None:
        """A PointInstancer: each visible, active instance of a prototype places that prototype's meshes (snell
        instances of shared meshes), by USD's own ComputeInstanceTransformsAtTime (positions, orientations,
        scales, the prototype root's transform); invisibleIds and inactiveIds are its mask."""
        instancer = UsdGeom.PointInstancer(prim)
        where = prim.GetPath()
        prototypes = [self.stage.GetPrimAtPath(p) for p in instancer.GetPrototypesRel().GetTargets()]
        indices = np.asarray(instancer.GetProtoIndicesAttr().Get(time) or [], np.int64)
        if len(indices) == 0 or not prototypes:
            self.problems.warn(where, "a PointInstancer without protoIndices or prototypes: nothing to draw")
            return
        mask = instancer.ComputeMaskAtTime(time)
        keep = np.asarray(mask, bool) if mask else np.ones(len(indices), bool)
        bad = (indices < 0) | (indices >= len(prototypes))
        if bad.any():
            self.problems.warn(where, f"{int(bad.sum())} protoIndices are outside its {len(prototypes)} prototypes: "
                                      "those instances are skipped")
        for n, proto in enumerate(prototypes):
            if not proto.IsValid():
                self.problems.warn(where, f"prototype {n} is not a prim of the stage: its instances are skipped")
        attributes = [instancer.GetPositionsAttr(), instancer.GetOrientationsAttr(), instancer.GetScalesAttr(),
                      instancer.GetProtoIndicesAttr()]
        varying = transform_might_vary(prim) or any(a.ValueMightBeTimeVarying() for a in attributes)
        if any(a.ValueMightBeTimeVarying() for a in (instancer.GetProtoIndicesAttr(), instancer.GetIdsAttr())) or \
                prim.GetAttribute("invisibleIds").ValueMightBeTimeVarying():
            self.problems.warn(where, "its protoIndices, ids or invisibleIds are animated; snell keeps the instances "
                                      f"of time code {self.time:g} and moves them")
        count = len(indices)
        cache: dict[float, list[np.ndarray]] = {}

        def instance_matrices(t: Usd.TimeCode) -> list[np.ndarray]:
            """Each instance's prototype-to-snell-world matrix at t (column vectors)."""
            key = t.GetValue()
            if key not in cache:
                cache.clear()
                xforms = instancer.ComputeInstanceTransformsAtTime(t, t, UsdGeom.PointInstancer.IncludeProtoXform,
                                                                   UsdGeom.PointInstancer.IgnoreMask)
                world = self.to_snell @ np.array(UsdGeom.XformCache(t).GetLocalToWorldTransform(prim)).T
                if xforms is None or len(xforms) != count:
                    cache[key] = []
                else:
                    cache[key] = [world @ np.array(x).T for x in xforms]
            return cache[key]

        if not instance_matrices(time):
            self.problems.warn(where, "its positions, orientations or scales do not fit its protoIndices: skipped")
            return
        predicate = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
        for n, proto in enumerate(prototypes):
            if not proto.IsValid() or not (keep & (indices == n)).any():
                continue
            for inner in Usd.PrimRange(proto, predicate):
                imageable = UsdGeom.Imageable(inner)
                if imageable and imageable.ComputeVisibility(time) == UsdGeom.Tokens.invisible:
                    continue
                if inner.IsA(UsdGeom.PointInstancer) and inner != prim:
                    self.problems.warn(inner.GetPath(), "a PointInstancer inside a prototype: skipped")
                    continue
                if not (inner.IsA(UsdGeom.Mesh) or inner.GetTypeName() in GPRIM_TYPES):
                    continue
                if imageable.ComputePurpose() in excluded:
                    continue
                relative, _ = UsdGeom.XformCache(time).ComputeRelativeTransform(inner, proto)
                below = np.array(relative).T  # the mesh in its prototype's space
                for i in np.nonzero(keep & (indices == n))[0]:
                    def placed(t: Usd.TimeCode, i: int = int(i), below: np.ndarray = below) -> np.ndarray:
                        matrices = instance_matrices(t)
                        return matrices[i] @ below if matrices else None
                    self._add_mesh(inner, time, placed, varying)

    def _add_mesh(self, prim: Usd.Prim, time: Usd.TimeCode, placed=None, varying_placement: bool = False) -> None:
        """A UsdGeomMesh, or a gprim tessellated as one (_gprims.py); placed: a PointInstancer's instance (its
        mesh-to-snell-world matrix at a time code), else the prim's own transform places it. A prim whose
        attributes are not of the types their schema gives is an error naming the attribute, never a traceback."""
        if prim.IsA(UsdGeom.Mesh) and not _typed_as_schema(prim, self.problems):
            return
        try:
            self._read_mesh(prim, time, placed, varying_placement)
        except (TypeError, ValueError, IndexError, Tf.ErrorException) as e:
            self.problems.fail(prim.GetPath(), f"cannot be read as a mesh ({str(e).strip().splitlines()[-1]})")

    def _read_mesh(self, prim: Usd.Prim, time: Usd.TimeCode, placed, varying_placement: bool) -> None:
        mesh = UsdGeom.Mesh(prim) if prim.IsA(UsdGeom.Mesh) else GprimMesh(prim, self._pixels_of(prim), time)
        skin = self._skin_of(prim) if prim.IsA(UsdGeom.Mesh) else None
        prototype = prim.GetPrimInPrototype() if prim.IsInstanceProxy() else prim
        key = prototype.GetPath()
        if skin is None and key in self._topologies:
            topology = self._topologies[key]
        else:
            topology = read_topology(mesh, time, self.problems)
            if skin is None:
                self._topologies[key] = topology
        if topology is None:
            return
        self._missing_materials(prim)
        double_sided = bool(mesh.GetDoubleSidedAttr().Get(time))
        parts = [(bind, triangles, self.materials.index_for(bind, prim, double_sided))
                 for bind, triangles in material_subsets(prim, topology, time, self.problems)]
        rigid = skin if skin is not None and skin.skinned and skin.rigid else None
        placed_by = skin.skeleton_prim if skin is not None and skin.skinned else prim
        frame = SkelFrame(time)
        matrix = placed(time) if placed is not None else self._matrix(placed_by, rigid, frame)
        share = (key, tuple(m for _, _, m in parts)) if skin is None else None
        source = self._shared.get(share) if share is not None else None
        if source is None:
            source = self._make_source(mesh, topology, skin, parts, time)
            if source is None:
                return
            if share is not None:
                self._shared[share] = source
        varying = transform_might_vary(placed_by) or bool(rigid is not None and rigid.animated)
        if placed is not None:
            varying = varying_placement
        instances = list(range(self._instance_count, self._instance_count + len(source.parts)))
        self._instance_count += len(source.parts)
        self.placements.append(Placement(placed_by, source, instances, varying, matrix, rigid, placed))

    def _make_source(self, mesh: UsdGeom.Mesh, topology: Topology, skin: Optional[Skin], parts: list,
                     time: Usd.TimeCode) -> Optional[MeshSource]:
        prim = mesh.GetPrim()
        cage = None
        if prim.IsA(UsdGeom.Mesh):
            level = self.options.subdivision_level
            cage = read_subdivision(mesh, topology, time, MAX_AUTO_LEVEL if level is None else level, self.problems)
        normals = None if cage is not None else read_normals(mesh, topology, time, self.problems)
        source = MeshSource(mesh, topology, normals, skin, self.problems, cage)
        pose = source.pose(time, SkelFrame(time))
        if pose is None:
            return None
        for bind, triangles, material in parts:
            material, corner_uvs = self._own_colours(prim, topology, triangles, material, time, cage is None)
            record = self.materials.records[material]
            st, st_values = None, None
            if record.st_primvar is not None and corner_uvs is None:
                st, st_values = self._st(prim, record.st_primvar, topology, time, record.path)
            name = str(prim.GetPath()) if bind == prim else f"{prim.GetPath()} ({bind.GetName()})"
            part = source.add_part(name, triangles, material, st, st_values, corner_uvs)
            if part.uvs is not None:
                self._undrawn_wraps(prim, part, record)
        self.sources.append(source)
        self._initial[id(source)] = pose
        return source

    def _own_colours(self, prim: Usd.Prim, topology: Topology, triangles: np.ndarray, material: int,
                     time: Usd.TimeCode, atlas: bool = True) -> tuple[int, Optional[np.ndarray]]:
        """A material whose colour or opacity reads the mesh's primvars, made the mesh's own (_colours.py): the
        material's index for these triangles, and the UVs of their split corners where the colour varies
        (without `atlas`, a subdivision cage's: their mean colour instead)."""
        record = self.materials.records[material]
        if record.colour_primvar is None and record.opacity_primvar is None:
            return material, None
        base_alpha = float(record.fields["base_color"][3])
        colours = mesh_colours(prim, record.colour_primvar, record.opacity_primvar, base_alpha, topology, triangles,
                               time, self.problems)
        if colours.corners is None:
            return self.materials.variant(material, tuple(colours.constant)), None
        named = [f"primvars:{p[0]}" for p in (record.colour_primvar, record.opacity_primvar) if p is not None]
        if not atlas:
            mean = colours.corners.reshape(-1, 4).mean(axis=0)
            self.problems.warn(prim.GetPath(), f"{' and '.join(named)} vary over a subdivision surface, whose "
                                               f"refined triangles carry no colour of their own: their mean "
                                               f"{_fmt_colour(mean)} is used")
            return self.materials.variant(material, tuple(mean)), None
        if record.slots:
            mean = colours.corners.reshape(-1, 4).mean(axis=0)
            self.problems.warn(prim.GetPath(), f"{' and '.join(named)} vary over the mesh, but {record.path}'s "
                                               f"textures read primvars:{record.st_primvar}; snell's meshes carry one "
                                               f"UV set: their mean {_fmt_colour(mean)} is used")
            return self.materials.variant(material, tuple(mean)), None
        texels, uvs = colour_atlas(colours.corners)
        texture = self.materials.add_texture(texels, f"{prim.GetPath()} {' and '.join(named)}")
        return self.materials.variant(material, (1.0, 1.0, 1.0, 1.0), texture), uvs

    def _undrawn_wraps(self, prim: Usd.Prim, part: Part, record: MaterialRecord) -> None:
        """A wrap snell has no sampler for ('black', 'useMetadata') matters only where the texture's UVs leave
        [0, 1]: said there, once per texture and mesh."""
        for slot in record.slots.values():
            if slot.snell_wraps == slot.wraps:
                continue
            matrix = slot.uv_matrix()  # the texture's own (s, t) axes, as snell samples them
            uv = part.uvs.astype(np.float64) @ matrix[:2, :2].T + matrix[:2, 2]
            outside = ((uv < -1e-6) | (uv > 1 + 1e-6)).any(axis=0)
            axes = [w for w, s, o in zip(slot.wraps, slot.snell_wraps, outside) if w != s and o]
            if axes:
                through = " (through its UsdTransform2d)" if slot.transform is not None else ""
                why = ("snell reads no wrap from the file (USD's fallback is black)" if axes[0] == "useMetadata"
                       else "snell has no black border")
                self.problems.warn(slot.prim, f"wrap '{axes[0]}' where {prim.GetPath()}'s st{through} leaves [0, 1]: "
                                              f"{why}: the texture repeats there")

    def _st(self, prim: Usd.Prim, name: str, topology: Topology, time: Usd.TimeCode, material: str):
        primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(name)
        if not primvar or not primvar.HasAuthoredValue():
            self.problems.warn(prim.GetPath(), f"has no primvars:{name} for the texture of {material}: the texture "
                                               "is read at st (0, 0)")
            return None, None
        indices = np.asarray(primvar.GetIndices(time), np.int64) if primvar.IsIndexed() else None
        st = read_primvar(prim, primvar.GetAttr(), primvar.GetInterpolation(), indices, topology, time,
                          self.problems, f"primvars:{name}")
        if st is None:
            return None, None
        if st.varying:
            self.problems.warn(prim.GetPath(), f"primvars:{name} is animated; snell reads it once, at time code "
                                               f"{self.time:g}")
        values = np.asarray(primvar.GetAttr().Get(time), np.float64).reshape(-1, 2)
        return st, values

    def _matrix(self, prim: Usd.Prim, rigid: Optional[Skin], frame: SkelFrame) -> np.ndarray:
        matrix = self.to_snell @ np.array(self._xform_cache.GetLocalToWorldTransform(prim)).T
        if rigid is not None:
            skinned = rigid.rigid_transform(frame)
            if skinned is not None:
                matrix = matrix @ skinned
        return matrix

    # ------------------------------------------------------------------ what snell takes

    def in_range(self, time_code: float) -> bool:
        """Whether a time code lies in the stage's authored range (any does, without one)."""
        return not self.has_range or self.range_lo <= time_code <= self.range_hi

    def snell_meshes(self) -> list[Mesh]:
        """Every part of every source as a snell.Mesh, numbering the parts (part.mesh) on the way."""
        meshes = []
        for source in self.sources:
            pose = self._initial[id(source)]
            for part in source.parts:
                positions = np.empty((len(part.vertex_point), 3), np.float32)
                normals = np.empty_like(positions)
                source.write(part, pose, positions, normals)
                part.mesh = len(meshes)
                face_materials = None
                if part.face_materials is not None:  # a hole's entry is never drawn; any material will do
                    face_materials = np.where(part.face_materials == -2, part.material, part.face_materials)
                meshes.append(Mesh(positions, None if part.cage is not None else normals, part.indices, part.uvs,
                                   material=part.material, name=part.name, subdivision=part.cage,
                                   face_materials=face_materials))
        return meshes

    def snell_instances(self) -> list[Instance]:
        """Every placement's instances, in order (snell_meshes first: it numbers the parts)."""
        return [Instance(part.mesh, placement.matrix)
                for placement in self.placements for part in placement.source.parts]

    def snell_materials(self) -> list[Material]:
        return [record.snell_material() for record in self.materials.records]

    def snell_lights(self) -> list[Light]:
        return [record.light for record in self.lights if record.light is not None]

    def snell_environment(self):
        """The dome's snell.Environment (what the glass reflects), or None for snell's studio gradient."""
        return self.dome.environment() if self.dome is not None else None

    def camera(self, which: Union[None, int, str], time_code: float) -> Optional[CameraState]:
        """A camera by prim path or index (None: the first, or None if the stage has none)."""
        with self.problems.usd_diagnostics():
            return self._camera(which, time_code)

    def _camera(self, which: Union[None, int, str], time_code: float) -> Optional[CameraState]:
        if which is None:
            if not self.cameras:
                return None
            prim = self.cameras[0]
        elif isinstance(which, int):
            if not 0 <= which < len(self.cameras):
                raise StageError(f"{self.path}: no camera {which}; the stage has {len(self.cameras)}")
            prim = self.cameras[which]
        else:
            prim = self.stage.GetPrimAtPath(which) if Sdf.Path.IsValidPathString(which) else Usd.Prim()
            if not prim or not prim.IsA(UsdGeom.Camera):
                known = ", ".join(str(c.GetPath()) for c in self.cameras) or "none"
                raise StageError(f"{self.path}: {which} is not a camera of the stage (its cameras: {known})")
        t = Usd.TimeCode(time_code)
        state = camera_state(prim, t, self.to_snell, self.meters_per_unit, UsdGeom.XformCache(t))
        if not (state.horizontal_aperture > 0 and state.vertical_aperture > 0 and
                (state.orthographic or state.focal_length > 0)):
            raise StageError(f"{self.path}: {state.path}: focal length {state.focal_length:g} and aperture "
                             f"{state.horizontal_aperture:g} x {state.vertical_aperture:g} make no picture")
        return state

    def evaluate(self, time_code: float) -> Frame:
        """Posed points and normals of the deforming sources and transforms of the moving placements."""
        with self.problems.usd_diagnostics():
            return self._evaluate(time_code)

    def _evaluate(self, time_code: float) -> Frame:
        started = clock.perf_counter()
        t = Usd.TimeCode(time_code)
        frame = SkelFrame(t)
        poses = []
        for source in self.dynamic_sources:
            pose = source.pose(t, frame)
            if pose is not None:
                poses.append((source, pose))
        self._xform_cache.SetTime(t)
        transforms = []
        for p in self.dynamic_placements:
            matrix = p.placed(t) if p.placed is not None else self._matrix(p.prim, p.rigid_skin, frame)
            if matrix is not None:  # an instancer whose points no longer fit its instances keeps them where they were
                transforms.append((p, matrix))
        return Frame(time_code, poses, transforms, clock.perf_counter() - started)


# What a mesh's attributes must hold for snell to read them: their schema's types (the value's shape).
_MESH_TYPES = {"points": ("point3f[]", "float3[]", "vector3f[]", "point3h[]", "float3h[]", "point3d[]"),
               "normals": ("normal3f[]", "float3[]", "vector3f[]", "normal3h[]", "normal3d[]"),
               "primvars:normals": ("normal3f[]", "float3[]", "vector3f[]", "normal3h[]", "normal3d[]"),
               "faceVertexCounts": ("int[]",), "faceVertexIndices": ("int[]",), "holeIndices": ("int[]",)}


def _typed_as_schema(prim: Usd.Prim, problems: Problems) -> bool:
    """Whether the mesh's authored points, normals and face lists are of their schema's types; where one is not
    (scalar normals, int points, double[] points), an error naming the attribute and both types."""
    for name, types in _MESH_TYPES.items():
        attribute = prim.GetAttribute(name)
        if not attribute or not attribute.HasAuthoredValue():
            continue
        # The type the layers author (the schema's type, GetTypeName's, hides a spec of another type).
        specs = attribute.GetPropertyStack(Usd.TimeCode.Default())
        kind = str(specs[0].typeName) if specs else str(attribute.GetTypeName())
        if kind not in types:
            problems.fail(prim.GetPath(), f"{name} is {kind}, not {types[0]} as UsdGeomMesh has it: the mesh is "
                                          "not drawn")
            return False
    return True


def _fmt_colour(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{float(c):.3g}" for c in values) + ")"


def _open_stage(path: str) -> Usd.Stage:
    if not os.path.exists(path):
        raise StageError(f"{path}: no such file")
    try:
        stage = Usd.Stage.Open(path, Usd.Stage.LoadAll)
    except Tf.ErrorException as e:
        # USD's own reason (a parse error, at its line), not only its closing "Failed to open layer".
        said = [str(getattr(a, "commentary", a)).strip() for a in e.args] or [str(e).strip()]
        reasons = [r for r in said if r and not r.startswith("Failed to open layer")] or said
        reason = next((r for r in reasons if r.startswith(path)), reasons[0] if reasons else "USD cannot open it")
        raise StageError(f"{path}: not a stage USD opens ({reason})") from None
    if stage is None:
        raise StageError(f"{path}: not a stage USD opens")
    return stage


def _snell_box(to_snell: np.ndarray, box: Gf.Range3d) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """A USD world range in snell's space (metres, +Y up), None where it is empty."""
    if box.IsEmpty():
        return None
    lo, hi = np.array(box.GetMin()), np.array(box.GetMax())
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    placed = corners @ to_snell[:3, :3].T + to_snell[:3, 3]
    return placed.min(axis=0), placed.max(axis=0)
