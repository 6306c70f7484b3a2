"""A USD stage drawn by snell: its scene and renderer on a device, fed frame by frame.

Each set_time re-reads only what moves: the deforming meshes (time-sampled
points or normals, or skinned by an animated skeleton) are evaluated by USD
and written straight into snell's mapped memory (Renderer.positions and
normals, then mark_dirty, so snell refits their trees alone), and moving
prims are sent as instance transforms (only the top-level tree is refit).
Static prims cost nothing per frame.
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass
from types import TracebackType
from typing import Any, Callable, Optional, Union

import numpy as np

from .. import Device, Environment, Mesh, Renderer, Scene, ShotFrame, View, framing
from ._cameras import CameraState
from ._problems import StageError, StageWarning
from ._reader import Frame, StageContents



@dataclass
class FeedStats:
    """What one set_time did."""

    time: float  #: the time code
    meshes: int = 0  #: snell meshes whose vertices were re-sent
    transforms: int = 0  #: instance transforms re-sent
    evaluate_seconds: float = 0.0  #: USD's evaluation: points, skinning, blend shapes, normals
    copy_seconds: float = 0.0  #: the copies into snell's mapped memory


class Stage:
    """A stage on a device: Stage.scene, Stage.renderer, and set_time to move it (see snell.usd.open)."""

    def __init__(self, contents: StageContents, device: Optional[Device] = None, frames_in_flight: int = 2) -> None:
        self.contents = contents
        self.scene, _ = scene_of(contents)
        self.environment: Optional[Environment] = contents.snell_environment()  # the dome, shared by every view
        self._owns_device = device is None
        self.device = device if device is not None else Device()
        try:
            self.renderer = Renderer(self.device, self.scene, frames_in_flight)
        except Exception:
            self._close_device()
            raise
        # The mapped views of the meshes that will be re-sent, made once: they live as long as the renderer.
        self._views = {part.mesh: (self.renderer.positions(part.mesh), self.renderer.normals(part.mesh))
                       for source in contents.dynamic_sources for part in source.parts}
        self.time = contents.time
        self.last_feed = FeedStats(self.time)
        self._outside_said = not contents.in_range(contents.time)  # read() said it for the open time code

    # ------------------------------------------------------------------ facts

    @property
    def path(self) -> str:
        return self.contents.path

    @property
    def warnings(self) -> list[StageWarning]:
        """Everything snell left out or approximated, each naming its prim (errors marked)."""
        return self.contents.problems.items

    @property
    def time_range(self) -> Optional[tuple[float, float]]:
        """The stage's authored (start, end) time codes, or None."""
        return (self.contents.start, self.contents.end) if self.contents.has_range else None

    @property
    def time_codes_per_second(self) -> float:
        return self.contents.time_codes_per_second

    @property
    def cameras(self) -> list[str]:
        """The stage's cameras, as prim paths, in traversal order."""
        return [str(c.GetPath()) for c in self.contents.cameras]

    # ------------------------------------------------------------------ frames

    def set_time(self, time_code: float) -> FeedStats:
        """Poses the stage at a time code: only the deforming meshes and moving prims are re-read and sent."""
        if not self.contents.in_range(time_code) and not self._outside_said:
            self._outside_said = True  # once: a loop past the range would repeat it every frame
            self.contents.problems.warn("", f"time code {time_code:g} is outside the stage's range "
                                            f"{self.contents.start:g}-{self.contents.end:g}: USD holds the nearest "
                                            "samples")
        frame = self.contents.evaluate(time_code)
        self.last_feed = self.send(frame)
        self.time = time_code
        return self.last_feed

    def send(self, frame: Frame) -> FeedStats:
        """Writes an evaluated frame into snell (set_time is evaluate then send)."""
        started = clock.perf_counter()
        stats = FeedStats(frame.time, evaluate_seconds=frame.seconds)
        for source, pose in frame.poses:
            for part in source.parts:
                positions, normals = self._views[part.mesh]
                source.write(part, pose, positions, normals)
                self.renderer.mark_dirty(part.mesh)
                stats.meshes += 1
        for placement, matrix in frame.transforms:
            if np.array_equal(matrix, placement.matrix):
                continue  # held between samples: nothing moved
            placement.matrix = matrix
            for instance in placement.instances:
                self.renderer.set_transform(instance, matrix)
                stats.transforms += 1
        stats.copy_seconds = clock.perf_counter() - started
        return stats

    # ------------------------------------------------------------------ views

    def camera(self, camera: Union[None, int, str] = None) -> Optional[CameraState]:
        """A camera at the current time code: a prim path, an index, or None for the stage's first."""
        return self.contents.camera(camera, self.time)

    def view(self, width: int, height: int, camera: Union[None, int, str] = None,
             conform: str = "expandAperture", **options: Any) -> View:
        """A snell.View of the stage: a USD camera's matrices (None: its first camera) or, with no camera
        in the stage, snell render's framed view of the bounds. options go to snell.View (method, ...); the
        stage's DomeLight is its environment unless options give one."""
        options.setdefault("environment", self.environment)
        state = self.camera(camera)
        if state is not None:
            view_matrix, projection = state.matrices(width, height, conform)
            return View(width, height, view_matrix=view_matrix, projection=projection, **options)
        return View(width, height, **framing(*self.bounds()), **options)

    def render(self, width: int, height: int, camera: Union[None, int, str] = None, **options: Any) -> np.ndarray:
        """The picture at the current time code: (height, width, 4) float32, scene-linear, row 0 at the top."""
        return self.renderer.render(self.view(width, height, camera, **options))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The world bounds of what is drawn now, in snell's space (metres, +Y up): (lo, hi)."""
        return world_bounds(self.contents, self.renderer.positions)

    # ------------------------------------------------------------------ lifetime

    def close(self) -> None:
        """Lets go of the renderer, the scene and (if the stage made it) the device."""
        self._views = {}
        for held in ("renderer", "scene"):
            thing = getattr(self, held, None)
            if thing is not None:
                thing.close()
        self._close_device()

    def _close_device(self) -> None:
        if self._owns_device and getattr(self, "device", None) is not None:
            self.device.close()

    def __enter__(self) -> "Stage":
        return self

    def __exit__(self, kind: Optional[type], value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"<snell.usd.Stage '{self.path}', {self.scene.mesh_count} meshes, time code {self.time:g}, "
                f"{len(self.warnings)} warnings>")


def scene_of(contents: StageContents) -> tuple[Scene, list[Mesh]]:
    """The stage's snell.Scene at the time code read (its meshes, materials, textures, instances and lights),
    and its meshes. A stage with nothing to draw draws its background, with a warning (snell render's rule for
    a glTF without meshes); strict readers raise StageError."""
    meshes = contents.snell_meshes()
    if not meshes:
        nothing = "nothing to draw: no visible UsdGeomMesh or gprim with faces" + _skipped_note(contents)
        if contents.problems.strict_missing:
            raise StageError(f"{contents.path}: {nothing}")
        contents.problems.warn("", f"{nothing}; the background is drawn")
    scene = Scene.from_arrays(meshes, materials=contents.snell_materials(),
                              textures=contents.materials.snell_textures(), instances=contents.snell_instances(),
                              lights=contents.snell_lights(), name=contents.path)
    return scene, meshes


def world_bounds(contents: StageContents, positions: Callable[[int], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The world bounds (lo, hi) of the placed meshes, each mesh's positions given by `positions(mesh)`."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for placement in contents.placements:
        for part in placement.source.parts:
            p = np.asarray(positions(part.mesh), np.float64)
            world = p @ placement.matrix[:3, :3].T + placement.matrix[:3, 3]
            world = world[np.isfinite(world).all(axis=1)]
            if len(world):
                lo, hi = np.minimum(lo, world.min(axis=0)), np.maximum(hi, world.max(axis=0))
    return lo, hi


def shot_frame(contents: StageContents, time_code: float, camera: Optional[CameraState], width: int, height: int,
               conform: str) -> ShotFrame:
    """A snell.ShotFrame of the stage at a time code, for render_frames: every deforming mesh's vertices and
    every moving instance's transform (each device keeps what its frames gave, so every frame gives them all),
    and the camera's matrices where the stage has one."""
    frame = contents.evaluate(time_code)
    vertices = {}
    for source, pose in frame.poses:
        for part in source.parts:
            positions = np.empty((len(part.vertex_point), 3), np.float32)
            normals = np.empty_like(positions)
            source.write(part, pose, positions, normals)
            vertices[part.mesh] = (positions, normals)
    transforms = {instance: matrix for placement, matrix in frame.transforms for instance in placement.instances}
    matrices: dict[str, Any] = {}
    if camera is not None:
        matrices["view_matrix"], matrices["projection"] = camera.matrices(width, height, conform)
    seconds = time_code / contents.time_codes_per_second if contents.time_codes_per_second else 0.0
    return ShotFrame(int(time_code), seconds, transforms=transforms, vertices=vertices, **matrices)


def _skipped_note(contents: StageContents) -> str:
    if not contents.skipped:
        return ""
    counts = ", ".join(f"{len(paths)} {kind}" for kind, paths in contents.skipped.items())
    return f" (skipped: {counts})"
