"""Type stubs for snell's compiled module (python/snell_module.cpp), so editors complete its names."""

from types import TracebackType
from typing import Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

DEFAULT_YFOV: float  # radians (40 degrees): the field of view of framed views and of View(yfov=)

Matrix = npt.ArrayLike  # 4x4, numpy (row, column) order, as mathutils.Matrix

class Error(RuntimeError):
    """Every failure snell reports; the message names the file, array or option at fault."""

def version() -> str:
    """snell's version, 'major.minor.patch'."""

def methods() -> list[tuple[str, str]]:
    """The ways of drawing glass View(method=...) takes: (name, one-line summary) pairs."""

def read_image_file(path: str) -> np.ndarray:
    """An image file's samples as stored, (height, width, channels), row 0 at the top: uint8, uint16 (16-bit
    PNG) or float32 (Radiance HDR); decoded by stb_image (PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC, PNM)."""

def write_png(path: str, rgba: npt.ArrayLike, alpha: bool = False) -> None:
    """Writes a (height, width, 4) scene-linear picture as an 8-bit sRGB PNG, complete or not at all."""

class Device:
    """The GPU snell runs on (a Vulkan device of its own)."""

    def __init__(
        self,
        device: str = "",
        validation: bool = False,
        interop: bool = False,
        driver_ray_tracing: bool = False,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def validation_messages(self) -> int: ...
    @property
    def exports_semaphores(self) -> bool: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Device": ...
    def __exit__(
        self,
        kind: Optional[type],
        value: Optional[BaseException],
        traceback: Optional[TracebackType],
    ) -> None: ...

class TextureTransform:
    """How a material's texture reads its UVs (glTF's KHR_texture_transform)."""

    offset: Sequence[float]
    rotation: float
    scale: Sequence[float]
    def __init__(
        self,
        offset: Sequence[float] = (0, 0),
        rotation: float = 0.0,
        scale: Sequence[float] = (1, 1),
    ) -> None: ...

class Material:
    """A glTF metallic-roughness material with transmission, IOR and volume (colours linear)."""

    name: str
    base_color: Sequence[float]
    base_color_texture: int
    transmission: float
    ior: float
    roughness: float
    thickness: float
    attenuation_color: Sequence[float]
    attenuation_distance: float
    double_sided: bool
    emissive: Sequence[float]
    dispersion: float
    emissive_texture: int
    normal_texture: int
    normal_scale: float
    alpha_mode: str
    alpha_cutoff: float
    base_color_transform: TextureTransform
    emissive_transform: TextureTransform
    normal_transform: TextureTransform
    def __init__(
        self,
        name: str = "",
        base_color: Sequence[float] = (1, 1, 1, 1),
        base_color_texture: int = -1,
        transmission: float = 0.0,
        ior: float = 1.5,
        roughness: float = 1.0,
        thickness: float = 0.0,
        attenuation_color: Sequence[float] = (1, 1, 1),
        attenuation_distance: float = float("inf"),
        double_sided: bool = False,
        emissive: Sequence[float] = (0, 0, 0),
        dispersion: float = 0.0,
        emissive_texture: int = -1,
        normal_texture: int = -1,
        normal_scale: float = 1.0,
        alpha_mode: str = "opaque",
        alpha_cutoff: float = 0.5,
        base_color_transform: TextureTransform = ...,
        emissive_transform: TextureTransform = ...,
        normal_transform: TextureTransform = ...,
    ) -> None: ...

class Light:
    """A punctual light: candela for point and spot lights, lux for directional."""

    type: str
    color: Sequence[float]
    intensity: float
    position: Sequence[float]
    direction: Sequence[float]
    inner_cone_angle: float
    outer_cone_angle: float
    def __init__(
        self,
        type: str = "point",
        color: Sequence[float] = (1, 1, 1),
        intensity: float = 1.0,
        position: Sequence[float] = (0, 0, 0),
        direction: Sequence[float] = (0, 0, -1),
        inner_cone_angle: float = 0.0,
        outer_cone_angle: float = 0.7853982,
    ) -> None: ...

class Camera:
    """A camera of a scene made from arrays (View(camera=index) picks it)."""

    orthographic: bool
    yfov: float
    ymag: float
    name: str
    def __init__(
        self,
        transform: Optional[Matrix] = None,
        orthographic: bool = False,
        yfov: float = DEFAULT_YFOV,
        ymag: float = 1.0,
        name: str = "",
    ) -> None: ...
    @property
    def transform(self) -> npt.NDArray[np.float64]: ...

class Subdivision:
    """How a Mesh is a subdivision surface, with USD's UsdGeomMesh tags: its indices are a cage's faces, which
    snell refines on the GPU whenever the vertices change (set_vertices)."""

    scheme: str  #: catmullClark, loop, bilinear or none
    level: int
    face_vertex_counts: list[int]
    left_handed: bool
    hole_indices: list[int]
    crease_indices: list[int]
    crease_lengths: list[int]
    crease_sharpnesses: list[float]
    corner_indices: list[int]
    corner_sharpnesses: list[float]
    interpolate_boundary: str  #: none, edgeOnly or edgeAndCorner
    face_varying_linear_interpolation: str  #: none, cornersOnly, cornersPlus1, cornersPlus2, boundaries or all
    smooth_triangles: bool
    limit_surface: bool
    normals: str  #: mesh or limit
    uv_indices: list[int]
    def __init__(
        self,
        scheme: str = "catmullClark",
        level: int = 2,
        face_vertex_counts: Optional[npt.ArrayLike] = None,
        interpolate_boundary: str = "edgeAndCorner",
        face_varying_linear_interpolation: str = "cornersPlus1",
        limit_surface: bool = False,
        normals: str = "mesh",
    ) -> None: ...

class Mesh:
    """A triangle mesh from numpy arrays, for Scene.from_arrays (or, with a Subdivision, a subdivision cage)."""

    material: int
    name: str
    def __init__(
        self,
        positions: npt.NDArray[np.float32],
        normals: Optional[npt.NDArray[np.float32]],
        indices: npt.NDArray[np.uint32],
        uvs: Optional[npt.NDArray[np.float32]] = None,
        material: int = -1,
        name: str = "",
        subdivision: Optional[Subdivision] = None,
        face_materials: Optional[npt.ArrayLike] = None,
    ) -> None: ...
    @property
    def subdivision(self) -> Optional[Subdivision]: ...
    @property
    def face_materials(self) -> Optional[npt.ArrayLike]: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def normals(self) -> npt.NDArray[np.float32]: ...
    @property
    def indices(self) -> npt.NDArray[np.uint32]: ...
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float32]]: ...

class Instance:
    """A mesh placed in the world (transform: mesh space to world)."""

    mesh: int
    def __init__(self, mesh: int, transform: Optional[Matrix] = None) -> None: ...
    @property
    def transform(self) -> Optional[Matrix]: ...

class Texture:
    """An 8-bit RGBA texture, (height, width, 4) uint8, row 0 at the top: sRGB colour, or a normal map's data."""

    name: str
    wrap_s: str
    wrap_t: str
    nearest: bool
    def __init__(
        self,
        rgba: npt.NDArray[np.uint8],
        name: str = "",
        wrap_s: str = "repeat",
        wrap_t: str = "repeat",
        nearest: bool = False,
    ) -> None: ...
    @property
    def rgba(self) -> npt.NDArray[np.uint8]: ...

class Scene:
    """What is drawn: a glTF file, or meshes from numpy arrays."""

    @staticmethod
    def load(path: str) -> "Scene": ...
    @staticmethod
    def from_arrays(
        meshes: Sequence[Mesh],
        materials: Sequence[Material] = (),
        textures: Sequence[Texture] = (),
        instances: Optional[Sequence[Instance]] = None,
        lights: Sequence[Light] = (),
        cameras: Sequence[Camera] = (),
        name: str = "arrays",
    ) -> "Scene": ...
    @property
    def name(self) -> str: ...
    @property
    def mesh_count(self) -> int: ...
    @property
    def camera_count(self) -> int: ...
    @property
    def duration(self) -> float: ...
    @property
    def warnings(self) -> list[str]: ...
    def vertex_count(self, mesh: int) -> int: ...
    def drawn_vertex_count(self, mesh: int) -> int: ...
    def drawn_triangle_count(self, mesh: int) -> int: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Scene": ...
    def __exit__(self, *args: Any) -> None: ...

class Environment:
    """What glass reflects: an equirectangular (lat-long) map of linear RGB radiance, row 0 looking up (+Y), the
    middle column looking down -Z, +X right of it."""

    width: int
    height: int
    name: str
    def __init__(self, rgb: npt.ArrayLike, name: str = "environment") -> None: ...

class View:
    """One picture of the scene: its size, camera, method and optics."""

    width: int
    height: int
    camera: int
    viewport: bool
    method: str
    max_interfaces: int
    fresnel: bool
    dispersion: bool
    volume: bool
    background: Sequence[float]
    transparent_background: bool
    environment: Optional[Environment]
    def __init__(
        self,
        width: int = 640,
        height: int = 480,
        camera: int = -1,
        view_matrix: Optional[Matrix] = None,
        projection: Optional[Matrix] = None,
        eye: Sequence[float] = (0, 0, 3),
        target: Sequence[float] = (0, 0, 0),
        up: Sequence[float] = (0, 1, 0),
        yfov: float = DEFAULT_YFOV,
        viewport: bool = False,
        method: str = "auto",
        max_interfaces: int = 8,
        fresnel: bool = True,
        dispersion: bool = True,
        volume: bool = True,
        background: Sequence[float] = (0.02, 0.02, 0.025),
        transparent_background: bool = False,
        environment: Optional[Environment] = None,
    ) -> None: ...
    def set_matrices(self, view_matrix: Matrix, projection: Matrix) -> None: ...

class SharedImage:
    """An RGBA16F Vulkan image OpenGL imports (GL_EXT_memory_object_fd)."""

    def __init__(self, device: Device, width: int, height: int) -> None: ...
    def export_memory(self) -> int: ...
    @property
    def memory_size(self) -> int: ...
    @property
    def dedicated(self) -> bool: ...
    def close(self) -> None: ...

class Renderer:
    """Draws views of one scene, updating only what changed between frames."""

    def __init__(self, device: Device, scene: Scene, frames_in_flight: int = 2, compact_trees: bool = False) -> None: ...
    @property
    def instance_count(self) -> int: ...
    def set_time(self, seconds: float) -> None: ...
    def set_transform(self, instance: int, transform: Matrix) -> None: ...
    def mark_dirty(self, mesh: int) -> None: ...
    def positions(self, mesh: int) -> npt.NDArray[np.float32]: ...
    def normals(self, mesh: int) -> npt.NDArray[np.float32]: ...
    def set_vertices(
        self,
        mesh: int,
        positions: npt.NDArray[np.float32],
        normals: Optional[npt.NDArray[np.float32]] = None,
    ) -> None: ...
    def render(self, view: View) -> npt.NDArray[np.float32]: ...
    def render_into(self, view: View, out: npt.NDArray[np.float32]) -> None: ...
    def render_to(self, view: View, image: SharedImage) -> None: ...
    def render_aovs(self, view: View) -> dict[str, npt.NDArray[Any]]: ...
    def last_frame(self) -> dict[str, Any]: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Renderer": ...
    def __exit__(self, *args: Any) -> None: ...

class ShotFrame:
    """One frame of a shot (render_frames): a time, and what the host changes at it.

    Each device keeps the vertices the frames it drew gave: a mesh one frame rewrites
    should come in every frame, or a frame's pixels would depend on its device.
    """

    def __init__(
        self,
        number: int,
        seconds: float = 0.0,
        view_matrix: Optional[Matrix] = None,
        projection: Optional[Matrix] = None,
        transforms: Optional[dict[int, Matrix]] = None,
        vertices: Optional[dict[int, tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]]] = None,
    ) -> None: ...
    @property
    def number(self) -> int: ...
    @property
    def seconds(self) -> float: ...

def framing(lo: Sequence[float], hi: Sequence[float], yfov: float = ...) -> dict[str, Any]:
    """The look-at snell render frames a scene without a camera with, for View(width, height, **framing(lo, hi)):
    looking down -Z at the centre of the world box [lo, hi], far enough back to see its whole bounding sphere (an
    empty box, lo > hi: the origin). Returns eye, target, up and yfov."""

def render_frames(
    scene: Scene,
    view: View,
    frames: Iterable[Union[ShotFrame, float]],
    on_frame: Callable[[dict[str, Any]], None],
    devices: str = "all",
    device: str = "",
    validation: bool = False,
    driver_ray_tracing: bool = False,
) -> dict[str, Any]: ...
