"""snell.usd: USD stages drawn by snell, read with Pixar's usd-core (`pxr`).

    import snell.usd

    with snell.usd.open("eyes.usda") as stage:          # preview-purpose materials
        for frame in range(1001, 1049):
            stage.set_time(frame)                       # only what moves is re-read and sent
            rgba = stage.render(1920, 1080)             # the stage's first camera

What is read: UsdGeomMesh (n-gons fanned, normals of every interpolation,
st, materialBind GeomSubsets, instance proxies, visibility and purpose),
UsdSkel skinning and blend shapes evaluated by USD itself, UsdPreviewSurface
materials bound for a purpose (preview first, then all-purpose) with
UsdUVTexture diffuse, emissive, normal and opacity textures (their wraps and
UsdTransform2d), cut-outs and coverage, UsdLux lights, UsdGeomCamera; metersPerUnit
and upAxis map the stage onto snell's metres and +Y up. What snell cannot
draw is a warning naming the prim (Stage.warnings). docs/usd.md has the
rules; `snell-usd` (python -m snell.usd) is the command line.
"""

from __future__ import annotations

import os
from typing import Optional, Union

try:
    import pxr  # noqa: F401  (usd-core)
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("snell.usd needs Pixar's USD Python modules: pip install usd-core") from e

from .. import Device
from ._cameras import CONFORM_POLICIES, CameraState
from ._lights import LightRecord
from ._problems import StageError, StageWarning
from ._reader import GEOMETRY_PURPOSES, ReadOptions, StageContents
from ._screen import DEFAULT_TRIANGLE_BUDGET
from ._stage import FeedStats, Stage

PathLike = Union[str, os.PathLike]


def read(path: PathLike, *, time: Optional[float] = None, purpose: str = "preview",
         geometry_purpose: str = "render", meters_per_unit: Optional[float] = None, strict: bool = False,
         load_textures: bool = True, missing_textures_fail: Optional[bool] = None,
         subdivision_level: Optional[int] = None, image_size: tuple[int, int] = (1920, 1080),
         camera: Union[None, int, str] = None, triangle_budget: int = DEFAULT_TRIANGLE_BUDGET) -> StageContents:
    """Reads a stage for snell without a GPU: its meshes, materials, lights, cameras and warnings.

    time: the time code (default: the stage's start); purpose: the material
    purpose bound first ('preview', 'full', or 'all' for the all-purpose
    binding alone); geometry_purpose: 'render' or 'proxy', drawn beside
    'default' ('guide' never is); meters_per_unit overrides the stage's;
    strict: a broken stage (a mesh with faces but no points, a missing
    texture file) raises StageError instead of warning;
    missing_textures_fail: what snell draws around is an error: a texture
    file that is missing or cannot be decoded, and a stage with nothing to
    draw when its Scene is made (default: as strict; otherwise a warning,
    and the texture's fallback or the background is drawn, as usdview
    draws them); subdivision_level: the levels every subdivision surface
    (subdivisionScheme other than none) is refined by, on the GPU (0: its
    cage is drawn as it is); None (the default) sizes each cage's level to
    the view: its edges about a pixel at image_size through `camera` (the
    stage's first, else the framed view of its bounds), 1 to 3 levels,
    lowered to keep the scene within triangle_budget refined triangles.
    """
    if subdivision_level is not None and not 0 <= subdivision_level <= 8:
        raise ValueError(f"subdivision level must be 0 to 8, got {subdivision_level}")
    options = ReadOptions(purpose=purpose, geometry_purpose=geometry_purpose, meters_per_unit=meters_per_unit,
                          load_textures=load_textures, strict=strict,
                          missing_textures_fail=strict if missing_textures_fail is None else missing_textures_fail,
                          subdivision_level=subdivision_level, image_size=image_size, camera=camera,
                          triangle_budget=triangle_budget)
    return StageContents(path, time, options)


def open(path: PathLike, *, time: Optional[float] = None, purpose: str = "preview",  # noqa: A001 (as io.open)
         geometry_purpose: str = "render", device: Optional[Device] = None, meters_per_unit: Optional[float] = None,
         strict: bool = False, frames_in_flight: int = 2, subdivision_level: Optional[int] = None,
         image_size: tuple[int, int] = (1920, 1080), camera: Union[None, int, str] = None,
         triangle_budget: int = DEFAULT_TRIANGLE_BUDGET) -> Stage:
    """Opens a stage for drawing: a snell.Scene of its meshes and a Renderer on `device`.

    Without a device the stage makes its own and closes it with itself. The
    other arguments are read()'s. Raises StageError (a snell.Error) naming
    the file or prim when the stage cannot be drawn.
    """
    contents = read(path, time=time, purpose=purpose, geometry_purpose=geometry_purpose,
                    meters_per_unit=meters_per_unit, strict=strict, subdivision_level=subdivision_level,
                    image_size=image_size, camera=camera, triangle_budget=triangle_budget)
    return Stage(contents, device=device, frames_in_flight=frames_in_flight)


__all__ = [
    "CONFORM_POLICIES",
    "CameraState",
    "FeedStats",
    "GEOMETRY_PURPOSES",
    "LightRecord",
    "Stage",
    "StageContents",
    "StageError",
    "StageWarning",
    "open",
    "read",
]
