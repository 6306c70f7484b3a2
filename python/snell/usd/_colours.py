"""A mesh's own colours (primvars:displayColor, or any primvar a UsdPrimvarReader feeds into diffuseColor or
opacity) as snell's base colour.

A constant primvar (or one whose values are all equal) is the base colour
factor of the mesh's own copy of its material. One that varies (vertex,
varying, uniform or faceVarying, as USD interpolates them: across each
triangle linearly, as Hydra does) becomes a texture of the mesh's own, since
snell's meshes carry positions, normals and one UV set per vertex: every
triangle gets its own three vertices (split, as faceVarying data splits
them) and its own block of n x n texels, its corners at the centres of the
block's corner texels (0, 0), (n - 1, 0) and (0, n - 1), and every texel
holding the linear function of the corners' colours at its centre. Bilinear
filtering inside the triangle is then exact in the cells the triangle holds
whole; the cells its long edge crosses read one texel past the edge, whose
value is clipped to [0, 1] where the colours change steeply. The corner put
at the right angle is the one that clips least (for one channel the median
corner never does), and each block is the smallest n of 2, 4, 8 and 16 whose
clipping is at most 0.08, which changes the colour inside the triangle by a
quarter of that at most (the far texel's bilinear weight there is at most
1/4): smooth colours take 2 x 2 texels, pure primaries at a triangle's
corners 16 x 16. Texels hold 8-bit sRGB (alpha: bytes / 255), filtered in
linear light; blocks are laid out in bands of one size, so mip levels
average each block alone until they are smaller than a texel, and only
triangles that small in the picture blend with their neighbours.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pxr import Usd, UsdGeom

from ._meshes import Topology, read_primvar
from ._problems import Problems
from ._textures import linear_to_srgb

_WIDTH = 2048  # the atlas's width at most, in texels
_SIZES = (2, 4, 8, 16)  # a triangle's block: n x n texels
_CLIP = 0.08  # what a block's colours may clip past the long edge: a quarter of it, 0.02, at most inside


@dataclass
class MeshColours:
    """What a mesh part's primvars give its base colour: a constant, or per triangle corner."""

    constant: Optional[np.ndarray] = None  #: (4,) linear RGBA, when the colour does not vary
    corners: Optional[np.ndarray] = None  #: (T, 3, 4) linear RGBA of each triangle's corners, where it varies
    varies_alpha: bool = False  #: the alpha (opacity) varies or is below 1: the part blends


def _corner_values(prim: Usd.Prim, name: str, width: int, topology: Topology, triangles: np.ndarray,
                   time: Usd.TimeCode, problems: Problems) -> Optional[np.ndarray]:
    """The primvar's values at each corner of the triangles, (T, 3, width); None where it is not there."""
    primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(name) if name else None
    if not primvar or not primvar.HasAuthoredValue():
        return None
    values = primvar.GetAttr().Get(time)
    array = np.asarray(values, np.float64) if values is not None else np.zeros((0,))
    if array.ndim == 1 and width == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[1] < width or len(array) == 0:
        problems.warn(prim.GetPath(), f"primvars:{name} holds {primvar.GetTypeName()}, not {width} number(s) a "
                                      "value: ignored")
        return None
    indices = np.asarray(primvar.GetIndices(time), np.int64) if primvar.IsIndexed() else None
    interpolation = primvar.GetInterpolation()
    if interpolation == UsdGeom.Tokens.constant and indices is None and len(array) > 1:
        array = array[:1]  # a constant holds one value; USD reads the first
    read = read_primvar(prim, primvar.GetAttr(), interpolation, indices, topology, time, problems,
                        f"primvars:{name}")
    if read is None:
        return None
    if read.varying:
        problems.warn(prim.GetPath(), f"primvars:{name} is animated; snell reads it once, at time code "
                                      f"{time.GetValue():g}")
    return array[read.corner_ids[topology.triangles[triangles]], :width]


def mesh_colours(prim: Usd.Prim, colour: Optional[tuple[str, tuple]], opacity: Optional[tuple[str, float]],
                 base_alpha: float, topology: Topology, triangles: np.ndarray, time: Usd.TimeCode,
                 problems: Problems) -> MeshColours:
    """The base colour a part's primvars give (colour: (name, fallback) of diffuseColor's primvar; opacity:
    (name, fallback) of opacity's; base_alpha: the material's own alpha where opacity reads no primvar)."""
    count = len(triangles)
    rgba = np.empty((count, 3, 4))
    rgba[..., 3] = base_alpha
    if colour is not None:
        values = _corner_values(prim, colour[0], 3, topology, triangles, time, problems)
        rgba[..., :3] = values if values is not None else np.asarray(colour[1][:3], float)
    else:
        rgba[..., :3] = 1.0
    if opacity is not None:
        values = _corner_values(prim, opacity[0], 1, topology, triangles, time, problems)
        rgba[..., 3] = values[..., 0] if values is not None else opacity[1]
    alpha_blends = bool(opacity is not None and (rgba[..., 3] < 1.0).any())
    flat = rgba.reshape(-1, 4)
    if len(flat) == 0 or (flat == flat[0]).all():
        return MeshColours(constant=flat[0] if len(flat) else np.array([*(colour or ("", (0.18,) * 3))[1], 1.0]),
                           varies_alpha=alpha_blends)
    return MeshColours(corners=rgba, varies_alpha=alpha_blends)


def _block_sizes(c_o: np.ndarray, c_a: np.ndarray, c_b: np.ndarray) -> np.ndarray:
    """Each triangle's block: the fewest texels n x n for which its colours' extension past the long edge clips
    by at most _CLIP (see the module's docstring)."""
    sizes = np.full(len(c_o), _SIZES[-1])
    for n in reversed(_SIZES):
        # The lattice points just past the edge a-b, i + j = n: their value is linear in i, so its extremes are
        # at i = 1 and i = n - 1.
        step_a, step_b = (c_a - c_o) / (n - 1), (c_b - c_o) / (n - 1)
        clip = np.zeros(len(c_o))
        for i in (1, n - 1):
            v = c_o + step_a * i + step_b * (n - i)
            clip = np.maximum(clip, np.maximum(v - 1.0, -v).max(axis=1))
        sizes[clip <= _CLIP] = n
    return sizes


def colour_atlas(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each triangle's corner colours (T, 3, 4 linear RGBA) as a texture of blocks and the UVs of its split
    vertices: (rgba (H, W, 4) uint8, row 0 at the top; uvs (T * 3, 2) float32, vertex 3t + k at corner k)."""
    count = len(corners)
    colours = np.clip(corners.astype(np.float64), 0.0, 1.0)
    # The corner at the block's right angle: where c_a + c_b - c_o stays in [0, 1] (least clipped).
    others = ((1, 2), (2, 0), (0, 1))
    clipped = np.stack([np.abs(np.clip(colours[:, a] + colours[:, b] - colours[:, o], 0, 1)
                               - (colours[:, a] + colours[:, b] - colours[:, o])).sum(axis=1)
                        for o, (a, b) in enumerate(others)], axis=1)
    right = np.argmin(clipped, axis=1)
    a = np.array([o[0] for o in others])[right]
    b = np.array([o[1] for o in others])[right]
    t = np.arange(count)
    c_o, c_a, c_b = colours[t, right], colours[t, a], colours[t, b]
    sizes = _block_sizes(c_o, c_a, c_b)
    width = int(min(_WIDTH, max(int((sizes * sizes).sum()), 1) if count else 1))
    width = max(width, int(sizes.max(initial=2)))
    bands, corner_uv, top = [], np.empty((count, 3, 2)), 0
    for n in _SIZES:
        members = np.nonzero(sizes == n)[0]
        if len(members) == 0:
            continue
        per_row = width // n
        rows = -(-len(members) // per_row)
        band = np.zeros((rows * n, width, 4))
        k = np.arange(len(members))
        bx, by = n * (k % per_row), n * (k // per_row)
        # Texel (i, j) of a block holds c_o + (c_a - c_o) i / (n - 1) + (c_b - c_o) j / (n - 1), clipped.
        steps = np.arange(n) / (n - 1)
        i, j = np.meshgrid(steps, steps, indexing="xy")  # i along x, j along y
        m = members
        values = (c_o[m, None, None] + (c_a[m] - c_o[m])[:, None, None] * i[None, :, :, None]
                  + (c_b[m] - c_o[m])[:, None, None] * j[None, :, :, None])
        rows_at = by[:, None, None] + np.arange(n)[None, :, None]
        cols_at = bx[:, None, None] + np.arange(n)[None, None, :]
        band[rows_at, cols_at] = np.clip(values, 0.0, 1.0)
        corner_uv[m, 0] = np.stack([bx + 0.5, top + by + 0.5], axis=1)
        corner_uv[m, 1] = np.stack([bx + n - 0.5, top + by + 0.5], axis=1)
        corner_uv[m, 2] = np.stack([bx + 0.5, top + by + n - 0.5], axis=1)
        bands.append(band)
        top += rows * n
    linear = np.concatenate(bands, axis=0) if bands else np.ones((1, 1, 4))
    height = len(linear)
    texels = np.empty((height, width, 4), np.uint8)
    texels[..., :3] = np.rint(linear_to_srgb(linear[..., :3]) * 255.0)
    texels[..., 3] = np.rint(linear[..., 3] * 255.0)
    uvs = np.empty((count, 3, 2))
    uvs[t, right], uvs[t, a], uvs[t, b] = corner_uv[:, 0], corner_uv[:, 1], corner_uv[:, 2]
    uvs /= (width, height)
    return texels, uvs.reshape(-1, 2).astype(np.float32)
