# SPDX-License-Identifier: GPL-3.0-or-later
"""A Subdivision Surface modifier left to snell's GPU: the cage and the modifier's settings.

When an object's last modifier is a Catmull-Clark Subdivision Surface that
is on for the depsgraph's mode (and the object's "Subdivide on the GPU" is
on), the add-on sends the mesh Blender evaluates *without* that modifier
(the cage: armature, shape keys and every earlier modifier applied) and the
modifier's settings as a snell.Subdivision; snell refines the cage on the
GPU each frame its vertices move, instead of Blender on the CPU.

The cage comes from the evaluated object with its last modifier switched
off for one to_mesh(): through the modifier's DisableTemporary flag (as
Blender's own USD and Alembic exporters do), set on the evaluated copy,
which tags nothing, so no depsgraph update follows and the original is
never touched. Where the flag cannot be set safely (ctypes' view of the
modifier does not match its RNA), Blender subdivides on the CPU as before.

Blender's subdivision is OpenSubdiv's, which snell uses too: crease c is
sharpness 10 c^2 (Blender's subdiv_converter), Boundary Smooth "All" is
edgeOnly and "Keep Corners" edgeAndCorner, UV Smooth maps onto the
faceVaryingLinearInterpolation rules, and Use Limit Surface places the
vertices on the limit surface. Blender shades the subdivided mesh by its
triangles' normals: so does snell (normals "mesh"). A mesh with
flat-shaded faces, sharp edges or custom normals keeps Blender's CPU
subdivision, whose normals those change.
"""

from __future__ import annotations

import ctypes
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Optional

import numpy as np

# DNA's ModifierData: two pointers (next, prev), then int type and int mode.
_SUBSURF_TYPE = 1  # eModifierType_Subsurf
_DISABLE_TEMPORARY = 0x80000000  # eModifierMode_DisableTemporary
_MODE_VIEWPORT, _MODE_RENDER = 1, 2  # eModifierMode_Realtime, eModifierMode_Render

BOUNDARY = {"ALL": "edgeOnly", "PRESERVE_CORNERS": "edgeAndCorner"}
UV_SMOOTH = {"NONE": "all", "PRESERVE_CORNERS": "cornersOnly", "PRESERVE_CORNERS_AND_JUNCTIONS": "cornersPlus1",
             "PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE": "cornersPlus2", "PRESERVE_BOUNDARIES": "boundaries",
             "SMOOTH_ALL": "none"}


@dataclass
class GpuModifier:
    """The last modifier of an evaluated object, left to snell, and the level it refines to."""

    modifier: object
    level: int


def gpu_modifier(obj, depsgraph) -> Optional[GpuModifier]:
    """The evaluated object's last modifier if snell should refine it on the GPU, else None."""
    settings = getattr(obj.original, "snell", None)
    if settings is None or not settings.gpu_subdivision or obj.type != "MESH" or not obj.modifiers:
        return None
    modifier = obj.modifiers[-1]
    if modifier.type != "SUBSURF" or modifier.subdivision_type != "CATMULL_CLARK":
        return None
    render = depsgraph.mode == "RENDER"
    if not (modifier.show_render if render else modifier.show_viewport):
        return None
    level = modifier.render_levels if render else modifier.levels
    scene = depsgraph.scene
    if scene.render.use_simplify:
        level = min(level, scene.render.simplify_subdivision_render if render else scene.render.simplify_subdivision)
    if level <= 0 or not _flag_settable(modifier):
        return None
    return GpuModifier(modifier, int(level))


def _mode_word(modifier) -> Optional[ctypes.c_uint]:
    pointer = modifier.as_pointer()
    if not pointer:
        return None
    at = pointer + 2 * ctypes.sizeof(ctypes.c_void_p)
    return ctypes.c_uint.from_address(at + ctypes.sizeof(ctypes.c_int))


def _flag_settable(modifier) -> bool:
    """Whether ctypes sees the modifier as RNA does: a subsurf, enabled as its show_* say."""
    pointer = modifier.as_pointer()
    if not pointer:
        return False
    kind = ctypes.c_int.from_address(pointer + 2 * ctypes.sizeof(ctypes.c_void_p)).value
    mode = _mode_word(modifier).value
    return (kind == _SUBSURF_TYPE and bool(mode & _MODE_VIEWPORT) == bool(modifier.show_viewport)
            and bool(mode & _MODE_RENDER) == bool(modifier.show_render))


@contextmanager
def _disabled(modifier):
    """The modifier off for the evaluation inside the block, on again after it, whatever happens."""
    word = _mode_word(modifier)
    before = word.value
    word.value = before | _DISABLE_TEMPORARY
    try:
        yield
    finally:
        word.value = before


def cage_mesh(obj, depsgraph, gpu: GpuModifier):
    """The evaluated object's mesh without its last modifier (to_mesh_clear after)."""
    with _disabled(gpu.modifier):
        return obj.to_mesh(preserve_all_data_layers=True, depsgraph=depsgraph)


def _floats(collection, attribute: str, count: int, width: int = 1) -> np.ndarray:
    values = np.empty(count * width, np.float32)
    collection.foreach_get(attribute, values)
    return values


def _creases(mesh, domain: str) -> Optional[np.ndarray]:
    """Edge ('EDGE') or vertex ('POINT') creases: 4.0 made them the attributes crease_edge and crease_vert;
    before, edges had a crease each and vertices a crease layer."""
    name = "crease_edge" if domain == "EDGE" else "crease_vert"
    attribute = mesh.attributes.get(name)
    count = len(mesh.edges) if domain == "EDGE" else len(mesh.vertices)
    if attribute is not None and attribute.domain == domain:
        return _floats(attribute.data, "value", count)
    if domain == "EDGE" and hasattr(mesh.edges[0] if len(mesh.edges) else None, "crease"):
        return _floats(mesh.edges, "crease", count)
    layers = getattr(mesh, "vertex_creases", None)
    if domain == "POINT" and layers is not None and len(layers):
        return _floats(layers[0].data, "value", count)
    return None


def shading_keeps_blender(mesh) -> Optional[str]:
    """Why the mesh's shading needs Blender's own subdivision (flat faces, sharp edges, custom normals), or None."""
    if not len(mesh.polygons):
        return "it has no faces"
    smooth = np.empty(len(mesh.polygons), bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    if not smooth.all():
        return "some of its faces are flat-shaded"
    sharp = mesh.attributes.get("sharp_edge")
    if sharp is not None and sharp.domain == "EDGE":
        flags = np.empty(len(mesh.edges), bool)
        sharp.data.foreach_get("value", flags)
        if flags.any():
            return "some of its edges are marked sharp"
    elif len(mesh.edges) and hasattr(mesh.edges[0], "use_edge_sharp"):
        flags = np.empty(len(mesh.edges), bool)
        mesh.edges.foreach_get("use_edge_sharp", flags)
        if flags.any():
            return "some of its edges are marked sharp"
    if getattr(mesh, "has_custom_normals", False):
        return "it has custom normals"
    return None


@dataclass
class Cage:
    """An evaluated cage's faces, its tags and its UVs, as snell takes them."""

    face_counts: np.ndarray   # per polygon
    face_points: np.ndarray   # per face corner, polygon after polygon: its vertex
    face_material: np.ndarray  # per polygon: its material slot
    uvs: Optional[np.ndarray]  # face-varying values (v running down, as snell's)
    uv_indices: Optional[np.ndarray]  # per face corner: its value
    subdivision: object       # a snell.Subdivision of the whole cage


def read_cage(mesh, gpu: GpuModifier, uv_layer) -> Cage:
    """The cage mesh's faces and the modifier's settings as a snell.Subdivision."""
    import snell

    modifier = gpu.modifier
    polygons = len(mesh.polygons)
    counts = np.empty(polygons, np.int32)
    starts = np.empty(polygons, np.int32)
    mesh.polygons.foreach_get("loop_total", counts)
    mesh.polygons.foreach_get("loop_start", starts)
    material = np.empty(polygons, np.int32)
    mesh.polygons.foreach_get("material_index", material)
    loop_vertex = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loop_vertex)
    corner_loops = np.concatenate([np.arange(s, s + n) for s, n in zip(starts, counts)]) if polygons else \
        np.zeros(0, np.int64)
    face_points = loop_vertex[corner_loops]
    subdivision = snell.Subdivision("catmullClark", gpu.level, face_vertex_counts=counts,
                                    interpolate_boundary=BOUNDARY.get(modifier.boundary_smooth, "edgeOnly"),
                                    face_varying_linear_interpolation=UV_SMOOTH.get(modifier.uv_smooth,
                                                                                    "cornersOnly"),
                                    limit_surface=bool(modifier.use_limit_surface), normals="mesh")
    if modifier.use_creases:
        edges = _creases(mesh, "EDGE")
        if edges is not None and (edges > 0).any():
            pairs = np.empty(len(mesh.edges) * 2, np.int32)
            mesh.edges.foreach_get("vertices", pairs)
            creased = np.nonzero(edges > 0)[0]
            subdivision.crease_indices = pairs.reshape(-1, 2)[creased].reshape(-1)
            subdivision.crease_lengths = np.full(len(creased), 2)
            subdivision.crease_sharpnesses = 10.0 * edges[creased] ** 2
        vertices = _creases(mesh, "POINT")
        if vertices is not None and (vertices > 0).any():
            creased = np.nonzero(vertices > 0)[0]
            subdivision.corner_indices = creased
            subdivision.corner_sharpnesses = 10.0 * vertices[creased] ** 2
    uvs = uv_indices = None
    if uv_layer is not None:
        loop_uvs = np.empty(len(mesh.loops) * 2, np.float32)
        uv_layer.data.foreach_get("uv", loop_uvs)
        corner_uvs = loop_uvs.reshape(-1, 2)[corner_loops]
        # One value per distinct (vertex, UV): corners that agree share it, so only a seam splits the surface.
        keys = np.column_stack([face_points.astype(np.float64), corner_uvs.astype(np.float64)])
        unique, uv_indices = np.unique(keys, axis=0, return_inverse=True)
        uvs = unique[:, 1:].astype(np.float32)
        uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's v runs down the image
        uv_indices = uv_indices.reshape(-1).astype(np.uint32)
        subdivision.uv_indices = uv_indices
    return Cage(counts, face_points.astype(np.uint32), material, uvs, uv_indices, subdivision)


