"""UsdGeomCamera as snell.View's view and projection matrices.

USD's camera: focalLength and the apertures in tenths of a scene unit (only
their ratios matter to a perspective), aperture offsets that slide the film
window (a lens shift), a clipping range in scene units. snell takes OpenGL's
matrices and refuses a projection whose aspect is not the image's (its
pixels are square), so the window is first conformed to the image's aspect
by one of UsdRender's aspectRatioConformPolicy rules (default
expandAperture, UsdRenderSettings' fallback: the whole aperture stays in
view and the image sees more in the other direction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdGeom

CONFORM_POLICIES = ("expandAperture", "cropAperture", "adjustApertureWidth", "adjustApertureHeight")
APERTURE_UNIT = 0.1  # USD's lens and film values are in tenths of a scene unit


@dataclass
class CameraState:
    """A camera at one time code, in snell's space (metres, +Y up)."""

    path: str
    orthographic: bool
    focal_length: float
    horizontal_aperture: float
    vertical_aperture: float
    horizontal_offset: float
    vertical_offset: float
    near: float  #: metres
    far: float  #: metres
    camera_to_world: np.ndarray  #: 4x4, column vectors, rigid (scale and shear removed)
    meters_per_unit: float

    def aperture_for(self, width: int, height: int, policy: str = "expandAperture") -> tuple[float, float]:
        """(horizontal, vertical) aperture conformed to the image's aspect."""
        if policy not in CONFORM_POLICIES:
            raise ValueError(f"conform must be one of {', '.join(CONFORM_POLICIES)}, got '{policy}'")
        h, v = self.horizontal_aperture, self.vertical_aperture
        image = width / height
        if policy == "adjustApertureWidth" or (policy == "expandAperture" and h / v < image) or \
                (policy == "cropAperture" and h / v > image):
            return v * image, v
        return h, h / image

    def matrices(self, width: int, height: int, policy: str = "expandAperture") -> tuple[np.ndarray, np.ndarray]:
        """(view matrix, projection): numpy 4x4 in OpenGL's conventions, as snell.View takes them."""
        h, v = self.aperture_for(width, height, policy)
        # snell ignores the depth range; a degenerate clipping range must still give finite matrices.
        n = self.near if self.near > 0 else 1e-3
        f = self.far if self.far > n else n + 1.0
        depth = np.array([-(f + n) / (f - n), -2.0 * f * n / (f - n)])
        if self.orthographic:
            scale = APERTURE_UNIT * self.meters_per_unit  # the window in metres
            hw, hh = 0.5 * h * scale, 0.5 * v * scale
            ox, oy = self.horizontal_offset * scale, self.vertical_offset * scale
            projection = np.array([[1 / hw, 0, 0, -ox / hw], [0, 1 / hh, 0, -oy / hh],
                                   [0, 0, -2.0 / (f - n), -(f + n) / (f - n)], [0, 0, 0, 1]])
        else:
            focal = self.focal_length
            projection = np.array([[2 * focal / h, 0, 2 * self.horizontal_offset / h, 0],
                                   [0, 2 * focal / v, 2 * self.vertical_offset / v, 0],
                                   [0, 0, depth[0], depth[1]], [0, 0, -1, 0]])
        return np.linalg.inv(self.camera_to_world), projection

    def describe(self) -> str:
        kind = "orthographic" if self.orthographic else f"focal length {self.focal_length:g}"
        offsets = ""
        if self.horizontal_offset or self.vertical_offset:
            offsets = f", offset {self.horizontal_offset:g} x {self.vertical_offset:g}"
        yfov = 2 * np.degrees(np.arctan(0.5 * self.vertical_aperture / self.focal_length))
        fov = "" if self.orthographic else f" ({yfov:.1f} degrees vertically)"
        return (f"{kind}, aperture {self.horizontal_aperture:g} x {self.vertical_aperture:g}{fov}{offsets}, "
                f"clipping {self.near:g}-{self.far:g} m")


def rigid(matrix: np.ndarray) -> np.ndarray:
    """The rotation and translation of a 4x4 (column vectors): scale and shear removed, -Z kept."""
    z = matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])
    x = matrix[:3, 0] - np.dot(matrix[:3, 0], z) * z
    x /= np.linalg.norm(x)
    out = np.eye(4)
    out[:3, 0], out[:3, 1], out[:3, 2], out[:3, 3] = x, np.cross(z, x), z, matrix[:3, 3]
    return out


def camera_state(prim: Usd.Prim, time: Usd.TimeCode, to_snell: np.ndarray, meters_per_unit: float,
                 xform_cache: UsdGeom.XformCache) -> CameraState:
    """The camera prim at a time code; to_snell maps the stage's world to snell's (units and up axis)."""
    camera = UsdGeom.Camera(prim)
    world = to_snell @ np.array(xform_cache.GetLocalToWorldTransform(prim)).T
    near, far = camera.GetClippingRangeAttr().Get(time)
    return CameraState(
        path=str(prim.GetPath()),
        orthographic=camera.GetProjectionAttr().Get(time) == UsdGeom.Tokens.orthographic,
        focal_length=float(camera.GetFocalLengthAttr().Get(time)),
        horizontal_aperture=float(camera.GetHorizontalApertureAttr().Get(time)),
        vertical_aperture=float(camera.GetVerticalApertureAttr().Get(time)),
        horizontal_offset=float(camera.GetHorizontalApertureOffsetAttr().Get(time)),
        vertical_offset=float(camera.GetVerticalApertureOffsetAttr().Get(time)),
        near=float(near) * meters_per_unit, far=float(far) * meters_per_unit,
        camera_to_world=rigid(world), meters_per_unit=meters_per_unit)
