# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender's evaluated scene as a snell scene and renderer, kept in step.

The topology (which objects, their triangles, materials, lights) goes to
snell once; after that a frame sends only the evaluated (deformed: armature,
shape keys, modifiers) positions and normals of the objects Blender
re-evaluated, written straight into snell's mapped vertex memory, and the
transforms that moved. Anything else that changes (a material, a light,
the number of vertices) rebuilds the snell scene.

Vertices are Blender's face corners (loops), as the glTF exporter splits
them: a corner carries its vertex's position, its split normal (smooth,
flat or custom, what the viewport shows) and its UV. Each material slot of
an object is one snell mesh.

An object whose last modifier is a Subdivision Surface snell refines
(subdivision.py) sends its cage instead: Blender's vertices, its faces and
the modifier's settings; each frame its cage's positions, which snell
refines on the GPU.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from . import camera, compat, convert, runtime, subdivision


@dataclass
class MeshPart:
    """The triangles of one object that use one material: one snell mesh."""

    mesh: int                 # snell mesh index
    loops: np.ndarray         # the object's loops this part uses (its vertices, in order)
    vertex_of_loop: np.ndarray  # their Blender vertex indices
    positions: Optional[np.ndarray] = None  # snell's mapped (n, 3) views, once a renderer exists
    normals: Optional[np.ndarray] = None


@dataclass
class ObjectGeometry:
    """One evaluated object's geometry as snell meshes."""

    name: str
    vertex_count: int
    loop_count: int
    parts: list = field(default_factory=list)
    co: Optional[np.ndarray] = None           # (vertices, 3) scratch for foreach_get
    loop_normals: Optional[np.ndarray] = None  # (loops, 3) scratch
    sent: Optional[tuple] = None               # the (co, loop normals) last sent
    cage: bool = False  # its meshes are a subdivision cage's (vertices are Blender's, normals snell's)


class TopologyChanged(Exception):
    """The scene changed in a way new vertices cannot say: build it again."""


def _instance_key(instance) -> tuple:
    """A stable key for a depsgraph object instance."""
    if instance.is_instance:
        return (instance.parent.original.name, instance.object.original.name, tuple(instance.persistent_id))
    return (instance.object.original.name,)


def _read_mesh(obj):
    """The evaluated object's mesh with loop triangles and corner normals ready (to_mesh_clear after)."""
    mesh = obj.to_mesh()
    if mesh is None:
        return None
    mesh.calc_loop_triangles()
    compat.prepare_corner_normals(mesh)
    return mesh


def _render_uv_layer(mesh):
    """The UV map Cycles and the glTF exporter read where a texture names none: the one marked for render."""
    for layer in mesh.uv_layers:
        if layer.active_render:
            return layer
    return mesh.uv_layers.active


class SceneSync:
    """A snell scene and renderer built from a depsgraph, updated from its later states.

    Without a device it is the scene alone: a shot's workers make their own
    renderers, and each frame carries its whole state (frame_state).
    """

    def __init__(self, device, depsgraph) -> None:
        import snell

        started = time.perf_counter()
        self.device = device
        self.geometry: dict[str, ObjectGeometry] = {}
        self.instances: dict[tuple, tuple] = {}  # key -> (object name, [snell instance per part], matrix)
        self.notes: set[str] = set()
        self.problems: list[str] = []  # what the materials hold that snell cannot draw, named
        meshes, materials, lights = [], [], []
        textures = convert.Textures()
        material_index: dict[str, int] = {}
        placed = []  # (mesh, transform)

        for instance in depsgraph.object_instances:
            obj = instance.object
            matrix = camera.to_snell(instance.matrix_world)
            if obj.type == "LIGHT":
                light, note = convert.light_of(obj, camera.to_snell(instance.matrix_world))
                lights.append(light)
                if note:
                    self.notes.add(note)
                continue
            if obj.type not in ("MESH", "CURVE", "SURFACE", "META", "FONT"):
                continue
            name = obj.original.name
            geometry = self.geometry.get(name)
            if geometry is None:
                geometry = self._topology(obj, depsgraph, meshes, materials, material_index, textures)
                if geometry is None:
                    continue
                self.geometry[name] = geometry
            key = _instance_key(instance)
            first = len(placed)
            for part in geometry.parts:
                placed.append((part.mesh, matrix))
            self.instances[key] = (name, list(range(first, len(placed))), matrix)

        scene = depsgraph.scene
        self.light_state = self._lights_of(depsgraph)
        self.background = convert.background_of(scene.world)
        self.empty = not meshes
        if self.empty:  # snell needs a mesh: a degenerate one draws nothing
            zero = np.zeros((3, 3), np.float32)
            meshes.append(snell.Mesh(zero, np.tile(np.float32([0, 0, 1]), (3, 1)), np.uint32([[0, 1, 2]])))
            placed.append((0, np.eye(4)))
        for problem in self.problems:
            print(f"snell: {problem}")
        self.notes.update(self.problems)
        runtime.note_scene_problems(self.problems)
        instances = [snell.Instance(mesh, matrix) for mesh, matrix in placed]
        # What went to snell, for tools that replay the feed elsewhere (bench/record_blender_feed.py).
        self.arrays = {"meshes": meshes, "materials": materials, "textures": textures.textures, "lights": lights,
                       "instances": instances}
        self.scene = snell.Scene.from_arrays(meshes, materials=materials, textures=textures.textures, lights=lights,
                                             instances=instances, name=scene.name)
        self.renderer = snell.Renderer(device, self.scene) if device is not None else None
        for geometry in self.geometry.values() if device is not None else ():
            for part in geometry.parts:
                part.positions = self.renderer.positions(part.mesh)
                part.normals = self.renderer.normals(part.mesh)
        self.build_seconds = time.perf_counter() - started

    def _cage_of(self, obj, depsgraph):
        """The object's cage and its GpuModifier where snell refines it, else (None, None)."""
        gpu = subdivision.gpu_modifier(obj, depsgraph)
        if gpu is None:
            return None, None
        mesh = subdivision.cage_mesh(obj, depsgraph, gpu)
        why = subdivision.shading_keeps_blender(mesh) if mesh is not None else "it has no mesh"
        if why is not None:
            obj.to_mesh_clear()
            self.notes.add(f"{obj.original.name} is subdivided by Blender: {why}")
            return None, None
        return mesh, gpu

    def _topology(self, obj, depsgraph, meshes, materials, material_index, textures) -> Optional[ObjectGeometry]:
        """Adds an object's meshes (one per material slot it uses) with their current vertices."""
        mesh, gpu = self._cage_of(obj, depsgraph)
        if mesh is not None:
            try:
                return self._cage_topology(obj, mesh, gpu, meshes, materials, material_index, textures)
            finally:
                obj.to_mesh_clear()
        return self._triangle_topology(obj, meshes, materials, material_index, textures)

    def _material_index(self, obj, slot: int, material_index, materials, textures, uv_layer) -> tuple:
        """The snell material of an object's material slot (made once per Blender material), and its key."""
        blender_material = obj.material_slots[slot].material if slot < len(obj.material_slots) else None
        key = blender_material.name if blender_material is not None else ""
        if key not in material_index:
            materials.append(convert.material_of(blender_material, textures,
                                                 uv_layer.name if uv_layer is not None else "", self.problems))
            material_index[key] = len(materials) - 1
        return material_index[key], key

    def _cage_topology(self, obj, mesh, gpu, meshes, materials, material_index, textures) -> ObjectGeometry:
        """An object's subdivision cage: one snell mesh whose faces carry their slots' materials, refined once
        for all of them, as Blender's own GPU subdivision refines once and draws a range per material."""
        import snell

        uv_layer = _render_uv_layer(mesh)
        cage = subdivision.read_cage(mesh, gpu, uv_layer)
        geometry = ObjectGeometry(obj.original.name, len(mesh.vertices), len(mesh.loops), cage=True)
        co, _ = self._read_vertices(mesh, geometry)
        geometry.sent = (co.copy(), None)
        slots = np.unique(cage.face_material)
        snell_material = np.empty(len(slots), np.int32)
        for k, slot in enumerate(slots):
            snell_material[k], _ = self._material_index(obj, int(slot), material_index, materials, textures,
                                                        uv_layer)
        face_materials = snell_material[np.searchsorted(slots, cage.face_material)]
        part = MeshPart(len(meshes), np.zeros(0, np.int32), np.arange(geometry.vertex_count, dtype=np.int32))
        meshes.append(snell.Mesh(np.ascontiguousarray(co), None, cage.face_points, cage.uvs,
                                 material=int(face_materials[0]) if len(face_materials) else -1,
                                 name=obj.original.name, subdivision=cage.subdivision,
                                 face_materials=face_materials))
        geometry.parts.append(part)
        return geometry

    def _triangle_topology(self, obj, meshes, materials, material_index, textures) -> Optional[ObjectGeometry]:
        """An object's evaluated triangles, a snell mesh per material slot, over its loops."""
        import snell

        mesh = _read_mesh(obj)
        if mesh is None or len(mesh.loop_triangles) == 0:
            if mesh is not None:
                obj.to_mesh_clear()
            return None
        try:
            triangles = len(mesh.loop_triangles)
            tri_loops = np.empty(triangles * 3, np.int32)
            mesh.loop_triangles.foreach_get("loops", tri_loops)
            tri_loops = tri_loops.reshape(-1, 3)
            tri_material = np.empty(triangles, np.int32)
            mesh.loop_triangles.foreach_get("material_index", tri_material)
            loop_vertex = np.empty(len(mesh.loops), np.int32)
            mesh.loops.foreach_get("vertex_index", loop_vertex)
            uvs = None
            uv_layer = _render_uv_layer(mesh)
            if uv_layer is not None:
                uvs = np.empty(len(mesh.loops) * 2, np.float32)
                uv_layer.data.foreach_get("uv", uvs)
                uvs = uvs.reshape(-1, 2)
                uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's v runs down the image
            geometry = ObjectGeometry(obj.original.name, len(mesh.vertices), len(mesh.loops))
            co, loop_normals = self._read_vertices(mesh, geometry)
            geometry.sent = (co.copy(), loop_normals.copy())
            for slot in np.unique(tri_material):
                loops, remapped = np.unique(tri_loops[tri_material == slot], return_inverse=True)
                index, key = self._material_index(obj, int(slot), material_index, materials, textures, uv_layer)
                part = MeshPart(len(meshes), loops.astype(np.int32), loop_vertex[loops])
                meshes.append(snell.Mesh(
                    np.ascontiguousarray(co[part.vertex_of_loop]), np.ascontiguousarray(loop_normals[loops]),
                    remapped.reshape(-1, 3).astype(np.uint32),
                    None if uvs is None else np.ascontiguousarray(uvs[loops]),
                    material=index, name=f"{obj.original.name}/{key}"))
                geometry.parts.append(part)
            return geometry
        finally:
            obj.to_mesh_clear()

    @staticmethod
    def _read_vertices(mesh, geometry: ObjectGeometry) -> tuple:
        """The mesh's vertex positions and loop normals (a cage's: None) into the object's scratch arrays."""
        if geometry.co is None:
            geometry.co = np.empty((geometry.vertex_count, 3), np.float32)
            geometry.loop_normals = None if geometry.cage else np.empty((geometry.loop_count, 3), np.float32)
        mesh.vertices.foreach_get("co", geometry.co.reshape(-1))
        if geometry.cage:
            return geometry.co, None
        compat.read_corner_normals(mesh, geometry.loop_normals.reshape(-1))
        return geometry.co, geometry.loop_normals

    def _evaluated_vertices(self, obj, depsgraph) -> tuple:
        """An evaluated object's (positions, loop normals), in the object's scratch arrays."""
        geometry = self.geometry[obj.original.name]
        if geometry.cage:
            mesh, gpu = self._cage_of(obj, depsgraph)
            if mesh is None:
                raise TopologyChanged(f"{obj.original.name} is no longer subdivided by snell")
        else:
            mesh = _read_mesh(obj)
        try:
            if mesh is None or len(mesh.vertices) != geometry.vertex_count or len(mesh.loops) != geometry.loop_count:
                raise TopologyChanged(f"{obj.original.name}'s topology changed")
            return self._read_vertices(mesh, geometry)
        finally:
            obj.to_mesh_clear()

    def frame_state(self, depsgraph) -> tuple:
        """The depsgraph's frame whole: every mesh's vertices {mesh: (positions, normals)} and every
        instance's transform {instance: matrix}, changed or not (a shot's frame must not depend on the
        frames a worker drew before it). Raises TopologyChanged as send_changed does."""
        if self._lights_of(depsgraph) != self.light_state:
            raise TopologyChanged("a light changed")
        vertices = {}
        for obj in self._mesh_objects(depsgraph):
            co, loop_normals = self._evaluated_vertices(obj, depsgraph)
            for part in self.geometry[obj.original.name].parts:
                normals = np.zeros_like(co) if loop_normals is None else loop_normals[part.loops]
                vertices[part.mesh] = (co[part.vertex_of_loop], normals)
        transforms = {}
        for key, matrix in self._transforms_of(depsgraph).items():
            for index in self.instances[key][1]:
                transforms[index] = matrix
        return vertices, transforms

    def send_vertices(self, obj, depsgraph, only_if_changed: bool = False) -> bool:
        """Writes an evaluated object's vertices into snell's memory and marks its meshes dirty.

        With only_if_changed, vertices equal to those sent last are not sent
        (a render's frame change has no update list to say what moved).
        Returns whether they were sent.
        """
        geometry = self.geometry[obj.original.name]
        co, loop_normals = self._evaluated_vertices(obj, depsgraph)
        if only_if_changed and geometry.sent is not None:
            if np.array_equal(geometry.sent[0], co) and (loop_normals is None or
                                                         np.array_equal(geometry.sent[1], loop_normals)):
                return False
        geometry.sent = (co.copy(), None if loop_normals is None else loop_normals.copy())
        for part in geometry.parts:
            if geometry.cage:  # the cage's vertices are Blender's, in order; snell makes the normals
                np.copyto(part.positions, co)
            else:
                np.take(co, part.vertex_of_loop, axis=0, out=part.positions)
                np.take(loop_normals, part.loops, axis=0, out=part.normals)
            self.renderer.mark_dirty(part.mesh)
        return True

    def send_changed(self, depsgraph, stop=lambda: False, progress=lambda done, total: None) -> Optional[dict]:
        """Brings the renderer to another frame of a render: every object's evaluated vertices are read
        and only those that changed are sent, then the transforms that moved.

        `stop()` is asked between objects; when it says so, None is returned and
        the renderer holds a frame part way. `progress(done, total)` follows the objects.
        Raises TopologyChanged when only a rebuild can say what changed.
        """
        started = time.perf_counter()
        if self._lights_of(depsgraph) != self.light_state:
            raise TopologyChanged("a light changed")
        objects = self._mesh_objects(depsgraph)
        sent = []
        for done, obj in enumerate(objects):
            if stop():
                return None
            if self.send_vertices(obj, depsgraph, only_if_changed=True):
                sent.append(obj.original.name)
            progress(done + 1, len(objects))
        moved = self._update_transforms(depsgraph)
        return {"meshes_sent": sent, "meshes_read": len(objects), "instances_moved": moved,
                "feed_ms": (time.perf_counter() - started) * 1000}

    def send_every_mesh(self, depsgraph) -> list:
        """Sends every object's evaluated vertices, whatever changed (bench/record_blender_feed.py's feed)."""
        sent = []
        for obj in self._mesh_objects(depsgraph):
            self.send_vertices(obj, depsgraph)
            sent.append(obj.original.name)
        self._update_transforms(depsgraph)
        return sent

    def _mesh_objects(self, depsgraph) -> list:
        """The depsgraph's evaluated objects that are snell meshes, each once (not its instances)."""
        objects, seen = [], set()
        for instance in depsgraph.object_instances:
            name = instance.object.original.name
            if not instance.is_instance and name in self.geometry and name not in seen:
                seen.add(name)
                objects.append(instance.object)
        return objects

    @staticmethod
    def _lights_of(depsgraph) -> list:
        """What snell's lights are made of, to see when one changed: names, matrices, colours and power."""
        state = []
        for instance in depsgraph.object_instances:
            obj = instance.object
            if obj.type == "LIGHT":
                data = obj.data
                state.append((obj.original.name, tuple(map(tuple, instance.matrix_world)), data.type,
                              tuple(data.color), compat.light_power(data)))
        return state

    def update(self, depsgraph) -> dict:
        """Brings the renderer up to the depsgraph's state; returns what was sent.

        Raises TopologyChanged when only a rebuild can say what changed.
        """
        started = time.perf_counter()
        sent = []
        for update in depsgraph.updates:
            data = update.id
            kind = type(data).__name__
            # A material's own tree is a ShaderNodeTree; a node group's may be any NodeTree.
            if kind in ("Material", "Light", "World", "Image", "NodeTree", "ShaderNodeTree"):
                raise TopologyChanged(f"{kind} {data.name} changed")
            moved = update.is_updated_geometry or update.is_updated_transform
            if kind == "Object" and data.type == "LIGHT" and moved:
                raise TopologyChanged(f"light {data.name} changed")  # lights are part of snell's scene
            if kind == "Object" and update.is_updated_geometry:
                obj = data
                if obj.original.name in self.geometry:
                    self.send_vertices(obj, depsgraph)
                    sent.append(obj.original.name)
        moved = self._update_transforms(depsgraph)
        return {"meshes_sent": sent, "instances_moved": moved, "feed_ms": (time.perf_counter() - started) * 1000}

    def _transforms_of(self, depsgraph) -> dict:
        """Every instance's matrix in snell's world, by key; a new instance, or one gone, rebuilds."""
        matrices = {}
        for instance in depsgraph.object_instances:
            obj = instance.object
            if obj.type == "LIGHT":
                continue  # light positions are in the scene: a moved light comes as a Light/Object update
            key = _instance_key(instance)
            if key not in self.instances:
                if obj.type in ("MESH", "CURVE", "SURFACE", "META", "FONT"):
                    raise TopologyChanged(f"{obj.name} appeared")
                continue
            matrices[key] = camera.to_snell(instance.matrix_world)
        if len(matrices) != len(self.instances):
            raise TopologyChanged("an object was hidden or deleted")
        return matrices

    def _update_transforms(self, depsgraph) -> int:
        """Sets the transforms of instances that moved; returns how many moved."""
        moved = 0
        for key, matrix in self._transforms_of(depsgraph).items():
            name, placed, old = self.instances[key]
            if not np.array_equal(matrix, old):
                for index in placed:
                    self.renderer.set_transform(index, matrix)
                self.instances[key] = (name, placed, matrix)
                moved += 1
        return moved

    def close(self) -> None:
        for geometry in self.geometry.values():
            for part in geometry.parts:
                part.positions = part.normals = None
        if self.renderer is not None:
            self.renderer.close()
        self.scene.close()
